%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%

MODULE LEGACY
  CONST robtarget P10:=[[600,0,500],[0.707107,0,0.707107,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget P20:=[[600,200,500],[0.707107,0,0.707107,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  VAR num reg1:=0;
  PROC main()
    ConfJ\Off;
    ConfL\Off;
    reg1:=0;
    WHILE reg1<5 DO
      MoveJ P10,v500,z10,tool0;
      MoveL P20,v200,fine,tool0;
      reg1:=reg1+1;
    ENDWHILE
    TEST reg1
    CASE 5:
      TPWrite "done";
    DEFAULT:
      TPWrite "unexpected";
    ENDTEST
  ENDPROC
ENDMODULE
