%slaveleft
; works on the workpiece from the left
#TRAFO [45]
; the master's base seen from this robot: 400 mm ahead, 700 mm left, turned -90 degree
#CS ON [OFFS] [400, 700, 0, 0, 0, -90]
#TRACK CS ON [ID=1 SET_ZERO X=400 Y=700 C=-90 FILTER=0 WAIT]
; zero on the master's tool frame at switch-on (negative B: yaw-pitch-roll)
#CS ON [V.G.TRACK_CS.X, V.G.TRACK_CS.Y, V.G.TRACK_CS.Z, V.G.TRACK_CS.A, -V.G.TRACK_CS.B, V.G.TRACK_CS.C]
G1 X0 Y0 Z0 A0 B0 C0 F3000
#SIGNAL SYN [ID1 COUNT1]
#WAIT SYN [ID2]
; let go of the workpiece at once, as the manual does: the compensation the master's
; motion built up is shed on the joints' catch-up, within their limits
#TRACK CS OFF [FILTER=0]
#CS OFF
#CS OFF
M30
