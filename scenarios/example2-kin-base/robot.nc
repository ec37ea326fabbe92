%dynCS-agilus
#TRAFO [45]
; Our KR 6 R900 reaches the manual's points through a work frame 550 mm ahead of and 250 mm
; above its base (the manual's robot and frame are not given).
#CS ON [550, 0, 250, 0, 0, 0]
G1 X0 Y0 Z200 F6000
; to the safe position before the compensation is switched
N1000 Z200
; compensate the base error the PLC measures; couple in over 1000 ticks
N1010 #TRACK CS ON [ID=0 KIN_BASE OPTION=0 FILTER=1000]
N2000 Z100
; machining with compensation
N2010 G01 X100 F100
; to the safe position before the compensation is switched off
N9000 Z200
N9010 #TRACK CS OFF [WAIT]
; machining without compensation (back to the line's start first: ours)
G01 X0 Z100 F6000
N2000 G01 X100 F100
M30
