MODULE Palletize
  ! Stack 3 x 2 x 2 boxes from a fixed pick point onto a pallet.
  PERS tooldata tVacuum := [TRUE,[[0,0,150],[1,0,0,0]],[2.5,[0,0,60],[1,0,0,0],0,0,0]];
  PERS wobjdata wPallet := [FALSE,TRUE,"",[[500,-300,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  CONST robtarget pPick := [[450,250,200],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pPlace0 := [[0,0,100],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST jointtarget jHome := [[0,-20,20,0,60,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST num nCols := 3;
  CONST num nRows := 2;
  CONST num nLayers := 2;
  CONST num boxX := 120;
  CONST num boxY := 160;
  CONST num boxZ := 90;
  PERS num nPlaced := 0;
  VAR robtarget pPlace;

  PROC main()
    MoveAbsJ jHome, v1000, fine, tool0;
    FOR layer FROM 0 TO nLayers - 1 DO
      FOR row FROM 0 TO nRows - 1 DO
        FOR col FROM 0 TO nCols - 1 DO
          PickBox;
          pPlace := Offs(pPlace0, col * boxX, row * boxY, layer * boxZ);
          PlaceBox pPlace;
        ENDFOR
      ENDFOR
    ENDFOR
    MoveAbsJ jHome, v1000, fine, tool0;
    TPWrite "boxes placed: " \Num:=nPlaced;
  ENDPROC

  PROC PickBox()
    MoveJ Offs(pPick, 0, 0, 100), v2000, z50, tVacuum;
    MoveL pPick, v500, fine, tVacuum;
    WaitTime 0.2;
    MoveL Offs(pPick, 0, 0, 100), v1000, z20, tVacuum;
  ENDPROC

  PROC PlaceBox(robtarget pTo)
    MoveJ Offs(pTo, 0, 0, 150), v2000, z50, tVacuum \WObj:=wPallet;
    MoveL pTo, v300, fine, tVacuum \WObj:=wPallet;
    WaitTime 0.15;
    Incr nPlaced;
    MoveL Offs(pTo, 0, 0, 150), v1000, z50, tVacuum \WObj:=wPallet;
  ENDPROC
ENDMODULE
