/PROG  UP201
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "excerpt for tests";
PROG_SIZE	= 10534;
CREATE		= DATE 23-07-09  TIME 16:00:48;
MODIFIED	= DATE 23-07-09  TIME 16:00:50;
FILE_NAME	= UP021;
VERSION		= 0;
LINE_COUNT	= 6;
MEMORY_SIZE	= 20118;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 500,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,1,1,1,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
/MN
   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=2 ;
   3:  PAYLOAD[2] ;
   4:J P[1] 100% CNT0 ACC100 TB    .10sec,P-SPS    ;
      1:  DO[23]=(OFF) ;
      2:  CALL MAKRO050    ;
      3:  WAIT (DI[23])    ;
       ------ ;
   5:  !Robot in path ;
   6:J P[2] 100% CNT100 ACC100 TB   0.00sec,P-SPS    ;
      1:  DO[16]=ON ;
       ------ ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 2,	
	J1=    25.000 deg,	J2=   -10.000 deg,	J3=    20.000 deg,
	J4=   -35.000 deg,	J5=   -45.000 deg,	J6=    50.000 deg
   GP2:
	UF : 0, UT : 2,	
	J1=     0.000  mm
   GP3:
	UF : 0, UT : 2,	
	J1=     0.000  mm
   GP4:
	UF : 0, UT : 2,	
	J1=     0.000  mm
};
P[2]{
   GP1:
	UF : 0, UT : 2,		CONFIG : 'N U T, 0, 0, 0',
	X =   950.000  mm,	Y =   100.000  mm,	Z =   700.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
   GP2:
	UF : 0, UT : 2,	
	J1=   150.000  mm
   GP3:
	UF : 0, UT : 2,	
	J1=     0.000  mm
   GP4:
	UF : 0, UT : 2,	
	J1=     0.000  mm
};
/END
