MODULE loader_tray
	! excerpt written for robotcell's tests: joint targets with one decimal, tab indents,
	! a path procedure called from main, as a RobotStudio station saves them
	CONST jointtarget JT_1:=[[90.5,50.0,45.0,-1.0,-100.0,40.0],[9E9,9E9,9E9,9E9,9E9,9E9]];
	CONST jointtarget JT_2:=[[90.2,52.0,25.0,-1.5,-80.0,42.0],[9E9,9E9,9E9,9E9,9E9,9E9]];

	CONST jointtarget JT_3:=[[-80.0,-50.0,60.0,20.0,-12.0,22.0],[9E9,9E9,9E9,9E9,9E9,9E9]];
PROC Path_10()
	SetDO DO10_4,1;
	Reset DO10_5;
	MoveAbsJ JT_1,v200,fine,tool0;
	MoveAbsJ JT_2,v200,fine,tool0;
	WaitTime 0.5;
    WaitTime 0.5;
	MoveAbsJ JT_3,v200,z10,tool0;
ENDPROC
PROC main()
	Path_10;
ENDPROC

ENDMODULE
