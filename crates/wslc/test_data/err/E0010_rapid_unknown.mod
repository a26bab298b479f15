! E0010: an unknown name, with the nearest declared one
MODULE m
  PERS num nParts := 0;
  PROC main()
    nPart := 1;
  ENDPROC
ENDMODULE
