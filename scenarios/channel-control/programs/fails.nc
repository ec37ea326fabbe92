; Moves, then asks to track its own channel: refused while it runs (the channel goes to ERROR).
N10 G1 X20 F12000
N20 #TRACK CS ON [ID=1]
N30 X40
N40 M30
