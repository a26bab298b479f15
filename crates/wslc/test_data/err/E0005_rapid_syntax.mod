! E0005: a RAPID statement without its `;`
MODULE m
  PROC main()
    WaitTime 1
    WaitTime 2;
  ENDPROC
ENDMODULE
