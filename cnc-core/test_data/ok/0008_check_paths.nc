; blocks the check's run does not reach are checked on their own: an arc's start is unknown
N10 G1 X10 Y0 F100
N20 P1 = 0
N30 $IF P1 == 1
N40   G3 X0 Y10 I-10 J0
N50   G91 G2 X10 Y-10 R10
N60 $ENDIF
; $CONTINUE inside a $SWITCH inside a loop continues the loop; $DEFAULT may come first
N70 P2 = 0
N80 $WHILE P2 < 3
N90   P2 = P2 + 1
N100  $SWITCH P2
N110  $DEFAULT
N120    Y=P2
N125    $BREAK
N130  $CASE 2
N140    $CONTINUE
N150  $ENDSWITCH
N160  Z=P2
N170 $ENDWHILE
; where an $ELSEIF reads a machine value, the check does not decide
N180 $IF P1 == 1
N190   P3 = 1
N200 $ELSEIF V.G.TRACK_CS.X > 1
N210   P3 = 5
N220 $ENDIF
N230 G1 X=P3
M30
