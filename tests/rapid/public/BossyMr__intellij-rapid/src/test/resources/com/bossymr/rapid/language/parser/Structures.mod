MODULE DUMMY

    ALIAS type name;

    ALIAS type1 typ2 name;

    ALIAS type

    ALIAS type name

    ALIAS

    type;

    RECORD name
        type name;
        type name;
    ENDRECORD

    RECORD name
        type;
        type type name;
        type

    RECORD
        type name;

    RECORD
        type;
        type name;

ENDMODULE