MODULE Unsupported
  ! Constructs vworks does not run: each is an error naming it and its line.
  VAR socketdev sock;
  CONST robtarget pStart := [[500,0,300],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pEnd := [[500,200,300],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  VAR robtarget pFound;
  VAR string sName := "part";
  PROC main()
    SearchL \Stop, diSensor, pFound, pEnd, v100, tool0;
    %"Routine" + "1"%;
    AccSet 50, 50;
    IF TRUE GOTO done;
  done:
    MoveL pEnd, v100 \T:=2, fine, tool0;
  ERROR
    IF ERRNO = ERR_WHLSEARCH RETRY;
  ENDPROC
ENDMODULE
