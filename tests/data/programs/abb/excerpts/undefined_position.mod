%%%
  VERSION: 1
  LANGUAGE: ENGLISH
%%%

MODULE TOOL_STAND(SYSMODULE)
    !---------------------------------------------------------------------------
    ! excerpt written for robotcell's tests: a position declared as not yet defined, its
    ! quaternion [0,0,0,0], over several lines; compared, never moved to
    !---------------------------------------------------------------------------

    ! Declaration of undefined position
    LOCAL CONST robtarget UndefPos:=[[1500,0,1800],
                                     [0,0,0,0],
                                     [0,0,0,0],
                                     [9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    PERS robtarget StandPos{2}:=[[[900,-300,600],[0,0,1,0],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]],
                                 [[1500,0,1800],[0,0,0,0],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]];

    PROC GoToStand(num ToolNr)
        IF StandPos{ToolNr}<>UndefPos THEN
            MoveJ StandPos{ToolNr}, v500, fine, tool0;
        ENDIF
        MoveL StandPos{1}, v100, fine, tool0;
    ENDPROC
ENDMODULE
