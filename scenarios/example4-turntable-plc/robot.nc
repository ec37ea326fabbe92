%turntable
; The table centre lies 600 mm in front of the robot base.
#TRAFO [45]
G1 X600 Y0 Z200 F6000
; M100 asks the PLC to switch the tracking on (it holds the turntable's geometry itself);
; the acknowledge comes once the transition is sent.
M100
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
; M101 asks the PLC to switch the tracking off
M101
G92 X0
M30
