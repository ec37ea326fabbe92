; A 3-axis mill (X Y Z): tool D1 (50 mm) on, down 2 mm into the part, the outline of a
; 60 x 40 mm pocket in continuous path with its corners rounded within 0.5 mm; then a
; finishing pass 1 mm deeper whose corners are radius-5 arcs within 0.02 mm (each meets its
; lines tangentially and runs through with transitions, never stopping); up again, down at
; the first corner, a quarter circle out of it, up and back over the origin.
N10 D1
N20 G0 X10 Y10 Z5
N30 G1 Z-2 F600
#CONTOUR MODE [DEV PATH_DEV=0.5]
G261
N40 G1 X70 F6000
N50 Y50
N60 X10
N70 Y10
G260
N71 G1 Z-3 F600
#CONTOUR MODE [DEV PATH_DEV=0.02]
G261
N72 G1 X65 F6000
N73 G3 X70 Y15 I0 J5
N74 G1 Y45
N75 G3 X65 Y50 I-5 J0
N76 G1 X15
N77 G3 X10 Y45 I0 J-5
N78 G1 Y15
N79 G3 X15 Y10 I5 J0
N80 G1 X40
G260
N81 G0 Z5
N82 X10 Y10
N83 G1 Z-2 F600
N84 G2 X0 Y20 I-10 J0 F3000
N90 G0 Z5
N100 X0 Y0
N110 M30
