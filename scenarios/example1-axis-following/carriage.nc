%carriage
; X: carriage travel, Z: lift
G1 X0 Z0 F6000
#CHANNEL INTERFACE ON [TRACK_CS]
$WHILE 1
  ; tell the gripper the carriage is at the magazine and wait for it
  #SIGNAL SYN [ID3 COUNT1]
  #WAIT SYN [ID1]
  ; M0: wait until the PLC confirms the gripper holds the tube
  M0
  ; to the working position, the gripper follows
  G1 X120 Z15 F3000
  #SIGNAL SYN [ID2 COUNT1]
  ; back to the magazine
  G1 X0 Z0 F6000
$ENDWHILE
