MODULE screw_plate
    ! excerpt written for robotcell's tests: targets declared one by one, then arrays of them
    ! declared by their names (one and two dimensions, the rows over several lines), moved to
    ! by constant and by run-time indices, as a RobotStudio station's modules hold them
    CONST robtarget Screw1:=[[800,-150,700],[0,0,1,0],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Screw2:=[[800,-100,700],[0,0,1,0],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Hole11:=[[900,-150,650],[0,0,1,0],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Hole12:=[[900,-100,650],[0,0,1,0],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Hole21:=[[950,-150,650],[0,0.258819,0.965926,0],[-1,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Hole22:=[[950,-100,650],[0,0,1,0],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
CONST robtarget Screws{2} := [Screw1,Screw2];
CONST robtarget Holes{2,2} := [
    [Hole11, Hole12],
    [Hole21, Hole22]];
CONST robtarget Spare{1} := [SpareScrew];
    VAR num screwNr:=1;

PROC Screw()
    MoveJ Screws{2}, v1000, z10, tool0\WObj:=wobj0;
    MoveL Holes{2, 1}, v100, fine, tool0\WObj:=wobj0;
    MoveL Screws{screwNr}, v100, fine, tool0\WObj:=wobj0;
    MoveL Spare{1}, v100, fine, tool0\WObj:=wobj0;
ENDPROC
ENDMODULE
