MODULE Routines
  ! Functions, nested calls, records and arrays.
  CONST robtarget pBase := [[400,-150,350],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST num offsets{4} := [0, 50, 100, 150];
  VAR speeddata vRun := [200,500,5000,1000];
  PERS num nCycles := 0;

  FUNC num Clamp(num x, num lo, num hi)
    IF x < lo RETURN lo;
    IF x > hi RETURN hi;
    RETURN x;
  ENDFUNC

  FUNC robtarget Row(num k)
    RETURN Offs(pBase, 0, offsets{k}, 0);
  ENDFUNC

  PROC main()
    FOR k FROM 1 TO Dim(offsets, 1) DO
      MoveL Row(k), vRun, z5, tool0;
    ENDFOR
    vRun.v_tcp := Clamp(vRun.v_tcp * 2, 50, 300);
    FOR k FROM 4 TO 1 STEP -1 DO
      MoveL Row(k), vRun, z5, tool0;
    ENDFOR
    Incr nCycles;
  ENDPROC
ENDMODULE
