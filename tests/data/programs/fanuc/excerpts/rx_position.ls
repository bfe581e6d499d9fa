/PROG  RXPOS
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "excerpt for tests";
PROG_SIZE	= 1101;
CREATE		= DATE 24-03-11  TIME 09:38:16;
MODIFIED	= DATE 24-03-12  TIME 10:02:40;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 6;
MEMORY_SIZE	= 1549;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,1,*,*,*;
CONTROL_CODE	= 00000001 00000000;
/APPL
/MN
   1:  UFRAME_NUM=1 ;
   2:  UTOOL_NUM=4 ;
   3:J P[1] 100% CNT0 ACC100 TB    .10sec,P-SPS    ;
      1:  DO[23]=OFF ;
   4:L P[2] 300mm/sec CNT100 ACC100 TB    .10sec,P-SPS RTCP    ;
   5:J P[3] 100% CNT0 ACC100    ;
   6:  END ;
/POS
P[1]{
   GP1:
	UF : 1, UT : 4,		CONFIG : 'N U T, 0, 0, 0',
	RX =   420.000  mm,	RY =  -150.000  mm,	RZ =  -600.000  mm,
	RW =    30.000 deg,	RP =   -15.000 deg,	RR =    70.000 deg
   GP2:
	UF : 1, UT : 4,	
	J1=   200.000  mm
};
P[2]{
   GP1:
	UF : 1, UT : 4,		CONFIG : 'N U T, 0, 0, 0',
	RX =   650.000  mm,	RY =  -260.000  mm,	RZ =    10.000  mm,
	RW =    95.000 deg,	RP =    -5.000 deg,	RR =   -20.000 deg
   GP2:
	UF : 1, UT : 4,	
	J1=   200.000  mm
};
P[3]{
   GP1:
	UF : 1, UT : 4,		CONFIG : 'N U T, 0, 0, 0',
	J1=   -10.000 deg,	J2=     5.000 deg,	J3=   -20.000 deg,
	J4=      .000 deg,	J5=   -60.000 deg,	J6=    15.000 deg
   GP2:
	UF : 1, UT : 4,	
	J1=   200.000  mm
};
/END
