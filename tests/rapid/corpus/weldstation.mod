MODULE WeldStation
  ! An arc-welding station: wait for the fixture, weld two seams, report.
  PERS tooldata tTorch := [TRUE,[[12.5,0,380],[0.9659258,0,0.258819,0]],[3.2,[0,0,120],[1,0,0,0],0,0,0]];
  CONST robtarget pSeam1Start := [[420,-100,250],[0,0.7071068,0.7071068,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pSeam1End := [[420,100,250],[0,0.7071068,0.7071068,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pArcVia := [[470,150,250],[0,0.7071068,0.7071068,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pArcEnd := [[520,100,250],[0,0.7071068,0.7071068,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST speeddata vWeld := [8,30,200,15];
  VAR intnum iStop;
  PERS bool bStopRequest := FALSE;
  PERS num nWelds := 0;

  TRAP StopRequested
    bStopRequest := TRUE;
    TPWrite "stop requested";
  ENDTRAP

  PROC main()
    CONNECT iStop WITH StopRequested;
    ISignalDI \Single, diStop, 1, iStop;
    WHILE NOT bStopRequest DO
      WaitDI diFixtureClosed, 1 \MaxTime:=30;
      Weld pSeam1Start, pSeam1End;
      MoveC pArcVia, pArcEnd, vWeld, fine, tTorch;
      SetDO doArcOn, 0;
      Incr nWelds;
      PulseDO \PLength:=0.5, doCycleDone;
      IF nWelds >= 3 bStopRequest := TRUE;
    ENDWHILE
    IDelete iStop;
  ENDPROC

  PROC Weld(robtarget pFrom, robtarget pTo)
    MoveJ RelTool(pFrom, 0, 0, -50), v1000, z10, tTorch;
    MoveL pFrom, v200, fine, tTorch;
    SetDO doArcOn, 1;
    WaitTime 0.3;
    MoveL pTo, vWeld, z1, tTorch;
  ENDPROC
ENDMODULE
