; A rectangle of 100 x 50 mm at 200 mm/s, back to where it began.
N10 G1 X100 F12000
N20 Y50
N30 X0
N40 Y0
N50 M30
