! A RAPID module with every kind of data and motion vworks runs.
MODULE Motions
  PERS num parts := 0;
  PERS bool ready := FALSE;
  CONST robtarget pHome := [[400,0,500],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pPick := [[450,-200,300],[0,0.7071068,0.7071068,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST jointtarget jHome := [[0,-30,30,0,60,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST speeddata vSlow := [50,200,5000,1000];
  CONST zonedata zSmall := [FALSE,3,5,5,0.5,5,0.5];
  PERS tooldata tGripper := [TRUE,[[0,0,0],[1,0,0,0]],[1,[0,0,50],[1,0,0,0],0,0,0]];
  CONST num heights{3} := [10, 20, 30];
  VAR robtarget pNext;

  PROC main()
    MoveAbsJ jHome, v1000, fine, tool0;
    pNext := pPick;
    pNext.trans.z := pNext.trans.z + 50;
    FOR i FROM 1 TO 3 DO
      MoveJ Offs(pNext, 0, 0, heights{i}), v1000, z50, tool0;
      MoveL pPick, vSlow \V:=80, zSmall, tool0;
      MoveC Offs(pPick, 30, 30, 0), Offs(pPick, 60, 0, 0), v100, fine, tool0 \WObj:=wobj0;
      Incr parts;
    ENDFOR
    WaitUntil ready \MaxTime:=2 \TimeFlag:=ready;
    TPWrite "parts: " \Num:=parts;
  ENDPROC
ENDMODULE
