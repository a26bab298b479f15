MODULE IfStatements

    PROC name()
        IF TRUE <SMT>

        IF TRUE THEN
            !
        ELSEIF FALSE THEN
            !
        ENDIF

        IF TRUE THEN
            !
        ELSEIF FALSE THEN
            !
        ELSEIF TRUE THEN
            !
        ELSE
            !
        ENDIF
    ENDPROC

ENDMODULE