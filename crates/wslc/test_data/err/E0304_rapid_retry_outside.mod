! E0304: RETRY outside an error handler: it goes in the routine's ERROR clause
MODULE m
  PROC main()
    WaitTime 1;
    RETRY;
  ENDPROC
ENDMODULE
