%turntable
; The table centre lies 600 mm in front of the robot base.
#TRAFO [45]
G1 X600 Y0 Z200 F6000
; Robot base seen from the table centre: 600 mm in -X. The PLC turns the frame with the
; table; OPTION=1 keeps the tool orientation while the tool point circles with the table.
#TRACK CS ON [ID=0 OPTION=1 FILTER=0 WAIT KIN_BASE X=-600]
; from here on X0 Y0 is the table centre
G92 X600
G1 Z160
; the table turns by itself while the robot works
G1 X0 Y0 X1[INDP_ASYN POS=-90 G01 F500 G90]
G1 Z150
X-60
X60
X0
Y-60
Y60
Y0
Z160
#WAIT INDP ALL
; back over the centre before switching off, so nothing jumps
G1 X0 Y0
#TRACK CS OFF [FILTER=0 WAIT]
G92 X0
M30
