/PROG  CALIB_A
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "";
PROG_SIZE	= 1822;
CREATE		= DATE 24-12-22  TIME 18:35:46;
MODIFIED	= DATE 24-12-22  TIME 18:35:46;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 9;
MEMORY_SIZE	= 2070;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,1,*,*,*;
CONTROL_CODE	= 00000000 00000000;
LOCAL_REGISTERS	= 0,0,0;
/APPL
/MN
   1:  !excerpt written for robotcell tests ;
   2:  OVERRIDE=20% ;
   3:  UTOOL_NUM=0 ;
   4:  UFRAME_NUM=0 ;
   5:   ;
   6:L P[1] 100mm/sec CNT100    ;
   7:L P[2] 100mm/sec CNT100    ;
   8:J P[3] 30% FINE    ;
   9:   ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   900.000  mm,	Y =  -200.000  mm,	Z =   600.000  mm,
	W =  -175.400 deg,	P =   -39.300 deg,	R =     -.384 deg
   GP2:
	UF : 0, UT : 0,	
	J1=     6.378 deg
};
P[2]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   920.000  mm,	Y =  -200.000  mm,	Z =   600.000  mm,
	W =  -175.400 deg,	P =   -39.300 deg,	R =     -.379 deg
   GP2:
	UF : 0, UT : 0,	
	J1=     6.378 deg
};
P[3]{
   GP1:
	UF : 0, UT : 0,	
	J1=    10.000 deg,	J2=     5.000 deg,	J3=   -10.000 deg,
	J4=     0.000 deg,	J5=   -60.000 deg,	J6=     0.000 deg
   GP2:
	UF : 0, UT : 0,	
	J1=     0.000 deg
};
/END
