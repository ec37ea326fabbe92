%carriage
; AB: the carriage's travel (our first pose coordinate)
#TRAFO ON
G1 G90 AB=90 F2000 ; to the magazine
AB=30
N20 #CHANNEL INTERFACE ON [TRACK_CS]
$WHILE 1
  #SIGNAL SYN [ID3 COUNT1]
  #WAIT SYN [ID1]
  N20 #CHANNEL INTERFACE ON [TRACK_CS]
  M0 ; wait until the gripper holds the tube
  AB=127.7213 F2000 ; working position
  #SIGNAL SYN [ID2 COUNT1] ; the tube is in its working position
  N20 #CHANNEL INTERFACE OFF [TRACK_CS]
  AB=30 ; magazine
$ENDWHILE
