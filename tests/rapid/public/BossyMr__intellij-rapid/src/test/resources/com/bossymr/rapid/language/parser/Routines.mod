MODULE DUMMY

    PROC type name ENDPROC

    FUNC name( ENDPROC

    FUNC name name name) ENDPROC

ENDMODULE