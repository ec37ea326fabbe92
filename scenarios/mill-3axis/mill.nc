; A 3-axis mill (X Y Z): tool D1 (50 mm) on, down 2 mm into the part, the outline of a
; 60 x 40 mm pocket in continuous path with its corners rounded within 0.5 mm, a quarter
; circle out of the last corner, up again and back over the origin.
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
N80 G2 X0 Y20 I-10 J0 F3000
N90 G0 Z5
N100 X0 Y0
N110 M30
