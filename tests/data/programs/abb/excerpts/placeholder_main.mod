MODULE MainModule
	! excerpt written for robotcell's tests: a routine whose last statement is still RAPID's
	! placeholder <SMT>, as a module saved before it was finished holds it
	CONST robtarget pStart:=[[900,0,800],[0,0,1,0],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
	PROC main()
		MoveJ pStart, v500, fine, tool0;
		<SMT>
	ENDPROC
ENDMODULE
