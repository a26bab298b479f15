! E0301: an optional argument the instruction does not take
MODULE m
  CONST jointtarget j0 := [[0,0,0,0,30,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    MoveAbsJ j0, v100, fine, tool0 \Speed:=20;
  ENDPROC
ENDMODULE
