%arcs
; G17 is the default plane; I, J are relative to the start point (G162)
N10 G90 G0 X10 Y0 Z0
N20 G3 X0 Y10 I-10 J0 F600          ; quarter turn counter-clockwise about (0, 0)
N30 G2 X10 Y0 R10                     ; back clockwise by radius: centre (10, 10)
N40 G3 I-10                           ; full circle, end = start
N50 G3 X-10 Y0 Z5 R-10                ; half turn with a helix in Z
N60 G2 X10 Y0 R-10                    ; R<0: more than half a turn
N70 G18 G0 X0 Y0 Z0
N80 G2 Z10 X10 K10 I0                 ; Z-X plane
N90 G19 G0 Y0 Z0
N100 G3 Y0 Z20 J0 K10                 ; Y-Z plane, half turn
N110 G17 G161 G0 X10 Y0
N120 G2 X-10 Y0 I0 J0                 ; G161: absolute centre
N130 G162 G91 G3 X10 Y10 I10          ; incremental end point, centre relative to start
N140 G90 G1 X[SQRT[2] * 10] Y=COS[90] * 5
M30
