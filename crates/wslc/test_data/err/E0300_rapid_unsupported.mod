! E0300: RAPID constructs vworks does not run are errors that name them
MODULE m
  PROC main()
    SearchL \Stop, diSensor, pFound, pEnd, v100, tool0;
    %"Routine" + "1"%;
    MoveL pEnd, v100 \Inpos:=inpos50, fine, tool0;
  BACKWARD
    MoveL pEnd, v100, fine, tool0;
  ENDPROC
ENDMODULE
