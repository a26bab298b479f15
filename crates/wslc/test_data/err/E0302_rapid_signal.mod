! E0302: a signal the workcell does not give this robot (or of the wrong kind)
MODULE m
  PROC main()
    SetDO doGripper, 1;
    WaitDI diPartReady, 1;
    SetDO diPartReady, 0;
  ENDPROC
ENDMODULE
