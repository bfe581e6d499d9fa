MODULE ServiceModule
    !*****************************************************
    ! excerpt written for robotcell's tests: a torch service routine that moves with MoveJ and
    ! MoveL and calls an add-in's instruction with the same targets, as a RobotWare add-in's
    ! service module writes it
    !*****************************************************

    TASK PERS robtarget rtSprayApp:=[[800,200,900],[0,0,1,0],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    TASK PERS robtarget rtSpray:=[[800,200,820],[0,0,1,0],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];

    PROC rCleanTorch()
        MoveJ rtSprayApp, v500, z10, tool0;
        MoveL rtSpray, v200, fine, tool0;
        MoveL rtSprayApp, v200, z10, tool0;
        MoveSprayJ rtSprayApp,rtSpray,v200,fine,tool0;
    ENDPROC
ENDMODULE
