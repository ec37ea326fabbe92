%offsets
; G90/G91, G92 as additive offset, #PSET/#PRESET
N10 G01 G90 X10 Y20 Z30 F1000
N20 G91 X5 Y-5
N30 G90 G92 X100          ; offset, moves nothing
N40 X10                   ; 10 + 100
N50 G92 X0                ; offset removed ...
N60 X10                   ; ... from the next absolute position
N70 #PSET Y=0             ; the current Y (15) is now called 0
N80 Y10                   ; 25 in channel coordinates
N90 #PRESET
N100 Y10
N110 G0 Z0
M30
