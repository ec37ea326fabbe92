N10 G71 G0 X10
N20 G70 G1 X1 Y2 F10                   ; inch: 25.4 mm, 50.8 mm at 254 mm/min
N30 G91 X0.5                           ; incremental inch
N40 G71 G90 X0
M30
