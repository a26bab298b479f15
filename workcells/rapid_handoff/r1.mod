MODULE Carrier
  ! r1 (T_ROB1) carries the part from the infeed to the transfer station and, after r2
  ! has inspected it, back to the infeed: three rounds.
  CONST jointtarget jHome := [[0,-30,30,0,60,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pInfeed := [[450,-200,140],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pStation := [[300,250,140],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  ! The part's mass; GripLoad part1 grips the workcell's part1.
  PERS loaddata part1 := [0.5,[0,0,20],[1,0,0,0],0,0,0];
  VAR intnum iInspected;
  VAR num nInspected := 0;
  VAR syncident sDone;
  PERS tasks tlBoth{2} := [["T_ROB1"],["T_ROB2"]];

  TRAP PartInspected
    Incr nInspected;
    TPWrite "r1: r2 has inspected part " \Num:=nInspected;
  ENDTRAP

  PROC Carry(robtarget pFrom, robtarget pTo)
    MoveL Offs(pFrom, 0, 0, 100), v500, fine, tool0;
    MoveL pFrom, v100, fine, tool0;
    GripLoad part1;
    MoveL Offs(pFrom, 0, 0, 100), v200, z10, tool0;
    MoveL Offs(pTo, 0, 0, 100), v500, z10, tool0;
    MoveL pTo, v100, fine, tool0;
    GripLoad load0;
    MoveL Offs(pTo, 0, 0, 100), v200, fine, tool0;
  ENDPROC

  PROC main()
    CONNECT iInspected WITH PartInspected;
    ISignalDI diInspected, 1, iInspected;
    MoveAbsJ jHome, v1000, fine, tool0;
    FOR i FROM 1 TO 3 DO
      Carry pInfeed, pStation;
      MoveAbsJ jHome, v1000, fine, tool0;
      SetGO goPartsReady, i;
      WaitGI giPartsBack, i;
      Carry pStation, pInfeed;
    ENDFOR
    MoveAbsJ jHome, v1000, fine, tool0;
    WaitSyncTask sDone, tlBoth;
    TPWrite "r1 done, parts inspected: " \Num:=nInspected;
  ENDPROC
ENDMODULE
