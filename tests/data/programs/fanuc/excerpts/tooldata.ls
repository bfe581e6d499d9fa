/PROG  TOOLDATA
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "excerpt for tests";
PROG_SIZE	= 724;
CREATE		= DATE 24-03-11  TIME 05:04:50;
MODIFIED	= DATE 24-03-11  TIME 05:04:50;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 20;
MEMORY_SIZE	= 980;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
/MN
   1:  PR[16]=LPOS    ;
   2:  PR[16,1]=(-.5)    ;
   3:  PR[16,2]=12.5    ;
   4:  PR[16,3]=210.25    ;
   5:  PR[16,4]=180    ;
   6:  PR[16,5]=0    ;
   7:  PR[16,6]=(-90)    ;
   8:  UTOOL[1:GUN]=PR[16] ;
   9:  PR[16,1]=800    ;
  10:  PR[16,2]=(-300.5)    ;
  11:  PR[16,3]=(-20)    ;
  12:  PR[16,4]=0    ;
  13:  PR[16,5]=0    ;
  14:  PR[16,6]=(-90)    ;
  15:  UFRAME[2:FIXTURE]=PR[16] ;
  16:  UFRAME_NUM=2 ;
  17:  UTOOL_NUM=1 ;
  18:J P[1] 30% FINE    ;
  19:L P[2] 200mm/sec FINE    ;
  20:  END ;
/POS
P[1]{
   GP1:
	UF : 2, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   100.000  mm,	Y =   200.000  mm,	Z =   300.000  mm,
	W =      .000 deg,	P =      .000 deg,	R =      .000 deg
};
P[2]{
   GP1:
	UF : 2, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   100.000  mm,	Y =   200.000  mm,	Z =   200.000  mm,
	W =      .000 deg,	P =      .000 deg,	R =      .000 deg
};
/END
