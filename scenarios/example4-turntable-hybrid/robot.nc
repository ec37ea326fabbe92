%turntable
; The manual's geometry: the table centre lies 1305.92 mm in front of the robot base.
#TRAFO [45]
G1 X1305.92 Y0 Z130 F6000
N200 X1305.92 Y0
; Robot base seen from the table centre: 1305.92 mm in -X. The PLC turns the frame with the
; table; OPTION=1 keeps the tool orientation while the tool point circles with the table.
N210 #TRACK CS ON [ID=0 OPTION=1 FILTER=0 WAIT KIN_BASE X=-1305.92]
; from here on X0 Y0 is the table centre
N230 G92 X1305.92
N240 Z90
; the robot goes over the table's axis so nothing jumps; the table (X1) turns by itself
N250 X0 Y0 X1[INDP_ASYN POS=-90 G01 F500 G90]
N260 Z80
N270 X-60
N280 X60
N290 X0
N300 Y-60
N310 Y60
Y0
N320 Z90
N480 #WAIT INDP ALL
; back over the table centre before switching off, so nothing jumps
N490 G01 X0 Y0
N500 #TRACK CS OFF [FILTER=0 WAIT]
G92 X0
M30
