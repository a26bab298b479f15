! E0303: an interrupt ordered before any CONNECT names its TRAP
MODULE m
  VAR intnum iPart;
  TRAP OnPart
    TPWrite "part";
  ENDTRAP
  PROC main()
    ISignalDI diPart, 1, iPart;
  ENDPROC
ENDMODULE
