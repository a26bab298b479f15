! E0020: RAPID types are checked: a num is not a robtarget
MODULE m
  VAR num n := 3;
  PROC main()
    MoveL n, v100, fine, tool0;
  ENDPROC
ENDMODULE
