! COMMENT
MODULE name

    ! COMMENT
    ALIAS type1 name1;

    ! COMMENT
    RECORD name2
        ! COMMENT
        type1 name1;
    ENDRECORD

    ! COMMENT
    VAR type1 name2;

    ! COMMENT
    PROC name2()
        ! COMMENT
    ENDPROC

ENDMODULE