MODULE multimove_t_rob1
! excerpt written for robotcell's tests: a MultiMove task as an offline tool (COMPAS RRC)
! saves it on the controller: synchronised motions, each with its \ID
VAR confdata conf := [0,0,0,0];
VAR syncident sync1;
VAR syncident sync2;
TASK PERS tasks all_tasks{2} := [["T_ROB1"], ["T_ROB2"]];
PERS tooldata GripTool:=[TRUE,[[0.000,0.000,120.000],[1.0000,0.0000,0.0000,0.0000]],[0.5,[0.000,0.000,50.000],[1,0,0,0],0,0,0]];
TASK PERS wobjdata TrackFrame:=[FALSE,TRUE,"",[[0.000,0.000,0.000],[1.0000,0.0000,0.0000,0.0000]],[[0,0,0],[1,0,0,0]]];
TASK PERS speeddata Speed000:=[100.00,180.00,5000.00,1080.00];
PROC Main()
ConfL \Off;
SyncMoveOn sync1, all_tasks;
MoveAbsJ [[10.000,-20.000,30.000,0.000,40.000,0.000],[1500.00,9E9,9E9,9E9,9E9,9E9]]\ID:=0,Speed000,fine,GripTool;
MoveJ [[900.00,100.00,800.00],[0.0000,0.0000,1.0000,0.0000],[0,0,0,0],[1500.00,9E9,9E9,9E9,9E9,9E9]]\ID:=1,Speed000,fine,GripTool \WObj:=TrackFrame;
MoveL [[900.00,200.00,800.00],[0.0000,0.0000,1.0000,0.0000],[0,0,0,0],[1400.00,9E9,9E9,9E9,9E9,9E9]]\ID:=2,Speed000,z10,GripTool \WObj:=TrackFrame;
SyncMoveOff sync2;
ENDPROC
ENDMODULE
