%turntable
; The manual's geometry: the table centre lies 1305.92 mm in front of the robot base.
#TRAFO [45]
G1 X1305.92 Y0 Z130 F6000
N200 X1305.92 Y0
; M100 asks the PLC to switch the tracking on (it holds the turntable's geometry itself);
; the acknowledge comes once the transition is sent.
M100
; from here on X0 Y0 is the table centre
N230 G92 X1305.92
N240 Z90
; the robot goes over the table's axis so nothing jumps; the table (X1) turns by itself
N250 X0 Y0 X1[INDP_ASYN POS=-90 G01 F500 G90]
; continuous path (the demo's addition to the manual's program): corners rounded within 1 mm
#CONTOUR MODE [DEV PATH_DEV=1]
G261
N260 Z80
N270 X-60
N280 X60
N290 X0
N300 Y-60
N310 Y60
Y0
N320 Z90
G260
N480 #WAIT INDP ALL
; back over the table centre before switching off, so nothing jumps
N490 G01 X0 Y0
; M101 asks the PLC to switch the tracking off
M101
G92 X0
M30
