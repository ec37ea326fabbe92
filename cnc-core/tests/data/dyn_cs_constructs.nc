%constructs
; Our own program (a syntax exercise, not a machine setup): every NC construct the
; dynamic coordinate system programs rely on, in the forms the parser must accept.
; Channel axes: X Y Z A B C and the independent rotary axis X1.
#TRAFO[45]
N01010 G01 G90 X250 Y-30 Z120 A0 B0 C0 F2400
; publish this channel's tool frame, move, withdraw it
N01020 #CHANNEL INTERFACE ON [DYN_CS]
N01030 X310 Y15 Z140 C20
N01040 #CHANNEL INTERFACE OFF [DYN_CS]
; follow master channel 3, zeroed at switch-on
N01050 #TRACK_CS ON[ ID=3 SET_ZERO FILTER=250 ]
N01060 G92 X=V.G.TRACK_CS.X Y=V.G.TRACK_CS.Y Z=V.G.TRACK_CS.Z
N01070 #CS ON[TRCK_CS] [V.G.TRACK_CS.X, V.G.TRACK_CS.Y, V.G.TRACK_CS.Z, 0, -V.G.TRACK_CS.B, 0]
N01080 X0 Y0 Z60 F1800
; turn X1 by itself while the path goes on
N01090 X25 Y-25 X1[INDP_ASYN POS=135 G01 F900 G90]
N01100 X-25
N01110 #WAIT INDP ALL
N01120 #PSET X1=0
; three passes, each announced to the other channels
P1 = 0
$WHILE P1 < 3
N01210 #SIGNAL SYN [ID5 COUNT2]
N01220 Z=50 - 10 * P1
P1 = P1 + 1
$ENDWHILE
N01300 #TRACK_CS OFF [ID=3 FILTER=0]
N01310 #CS OFF
N01320 G92 X0 Y0 Z0
N01330 #TRAFO OFF
M30
