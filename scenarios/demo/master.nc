%master
; carries the workpiece
#TRAFO [45]
; publish the tool frame for the slaves
#CHANNEL INTERFACE ON [DYN_CS]
; wait until both slaves hold their workpiece points
#WAIT SYN [ID1 ID3]
G1 X680 Y40 Z560 F3000
G1 X600 Y-40 Z520 C170 F3000
G1 B10 F1200
G1 X640 Y0 Z540 B0 C180 F3000
; release both slaves
#SIGNAL SYN [ID2 COUNT2]
#CHANNEL INTERFACE OFF [DYN_CS]
#TRAFO OFF
M30
