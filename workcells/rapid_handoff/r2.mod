MODULE Inspector
  ! r2 (T_ROB2) takes the part from the transfer station, inspects it, puts it back and
  ! leaves. Its base is turned 180 deg: the station (300, 250) of the cell is (300, 350)
  ! in its base frame.
  CONST jointtarget jHome := [[0,-30,30,0,60,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pStation := [[300,350,140],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pInspect := [[0,450,370],[0,0.7071068,0.7071068,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS loaddata part1 := [0.5,[0,0,20],[1,0,0,0],0,0,0];
  VAR num nInspected := 0;
  VAR syncident sDone;
  PERS tasks tlBoth{2} := [["T_ROB1"],["T_ROB2"]];

  PROC main()
    MoveAbsJ jHome, v1000, fine, tool0;
    FOR i FROM 1 TO 3 DO
      WaitGI giPartsReady, i;
      MoveL Offs(pStation, 0, 0, 100), v500, fine, tool0;
      MoveL pStation, v100, fine, tool0;
      GripLoad part1;
      MoveL Offs(pStation, 0, 0, 100), v200, fine, tool0;
      MoveJ pInspect, v500, fine, tool0;
      WaitTime 0.5;
      Incr nInspected;
      PulseDO \PLength:=0.1, doInspected;
      MoveL Offs(pStation, 0, 0, 100), v500, z10, tool0;
      MoveL pStation, v100, fine, tool0;
      GripLoad load0;
      MoveL Offs(pStation, 0, 0, 100), v500, z10, tool0;
      SetGO goPartsBack, i;
      MoveAbsJ jHome, v1000, fine, tool0;
    ENDFOR
    WaitSyncTask sDone, tlBoth;
    TPWrite "r2 done, inspected: " \Num:=nInspected;
  ENDPROC
ENDMODULE
