MODULE ros_motion_excerpt

! excerpt written for robotcell's tests: a zone and a speed declared as predefined zonedata
! and speeddata by their names, a time argument between the speed and the zone, as a ROS
! driver's motion module writes them

LOCAL CONST zonedata DEFAULT_CORNER_DIST := z10;
LOCAL CONST jointtarget jReady := [[0,0,0,0,30,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];

PROC main()
    VAR speeddata move_speed := v10;  ! default speed

    MoveAbsJ jReady, move_speed, \T:=2.5, DEFAULT_CORNER_DIST, tool0;
ENDPROC

ENDMODULE
