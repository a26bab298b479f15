! E0300: a FUNC of a zonedata (three values in WSL: pzone_tcp, pzone_ori, zone_ori) is not supported where it is declared, and reading a component of its call does not crash
MODULE M
  FUNC zonedata MyZone()
    RETURN z10;
  ENDFUNC
  PROC main()
    TPWrite "o " \Num:=MyZone().pzone_ori;
  ENDPROC
ENDMODULE
