%gripper
$WHILE 1
  #FLUSH WAIT
  ; both at their positions?
  #SIGNAL SYN [ID1 COUNT1]
  #WAIT SYN [ID3]
  ; take over the carriage's position and follow it
  #TRACK CS ON [ID=2 SET_ZERO]
  #TRACK CS ABS
  ; to the transfer grip, 25.44 mm above the carriage's zero
  G1 X0 Y0 Z25.44 F6000
  #PSET Z0
  #FLUSH CONTINUE
  ; wait for the tube in its working position, then bend on our own
  #WAIT SYN [ID2]
  #TRACK CS OFF
  G1 C60 F30000
  C-60
  C60
  C0
  #PRESET
  G92 X0 Y0 Z0
$ENDWHILE
