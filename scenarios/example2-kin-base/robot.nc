%kinbase
#TRAFO [45]
; safe height, no compensation yet
G1 X600 Y0 Z450 F6000
; the PLC measures the base error; compensate it, coupling in over 1000 ticks
#TRACK CS ON [ID=0 KIN_BASE OPTION=0 FILTER=1000]
G1 Z350
; machining with compensation
G1 X650 F3000
Y50
X550
Y0
; safe height before the compensation goes
G1 Z450 F6000
#TRACK CS OFF [WAIT]
; the same points without compensation
G1 Z350
G1 X650 F3000
G1 Z450 F6000
M30
