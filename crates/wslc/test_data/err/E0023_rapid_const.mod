! E0023: a CONST cannot be assigned (names are case-insensitive)
MODULE m
  CONST num nMax := 3;
  PROC main()
    NMAX := 4;
  ENDPROC
ENDMODULE
