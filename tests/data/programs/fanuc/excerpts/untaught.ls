/PROG  NOTAUGHT
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "excerpt for tests";
PROG_SIZE	= 1101;
CREATE		= DATE 24-03-11  TIME 09:38:16;
MODIFIED	= DATE 24-03-12  TIME 10:02:40;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 5;
MEMORY_SIZE	= 1549;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
   1:  !excerpt for tests ;
   2:  SKIP CONDITION DI[718]=ON    ;
   3:L P[1] 10mm/sec CNT0 ACC250 Skip,LBL[1]    ;
   4:  LBL[1] ;
   5:J P[2] 50% FINE    ;
/POS
P[1]{
   GP1:
	UF : F, UT : F,		CONFIG : 'N D B, 0, 0, 0',
	X = ********  mm,	Y = ********  mm,	Z = ********  mm,
	W = ******** deg,	P = ******** deg,	R = ******** deg
};
P[2]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =  1100.000  mm,	Y =  -250.000  mm,	Z =   650.000  mm,
	W =   180.000 deg,	P =   -10.000 deg,	R =      .000 deg
};
/END
