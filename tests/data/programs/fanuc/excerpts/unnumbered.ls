/PROG  UNNUM
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "excerpt for tests";
PROG_SIZE	= 1101;
CREATE		= DATE 24-03-11  TIME 09:38:16;
MODIFIED	= DATE 24-03-12  TIME 10:02:40;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 14;
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
/APPL
/MN
    :  !excerpt for tests ;
    :  UFRAME_NUM=0 ;
    :  UTOOL_NUM=0 ;
    :  PR[49]=LPOS    ;
    :  SKIP CONDITION DI[101]=ON    ;
    :J PR[49] 100% CNT100 ACC100    ;
    :J P[1] 100% CNT0 ACC100 TB    .10sec,P-SPS    ;
      1:  DO[23]=OFF ;
      2:  CALL MAKRO050    ;
    :L P[2] 250mm/sec CNT0 ACC250 Skip,LBL[1]    ;
    :  LBL[1] ;
    :L P[3:"retreat"] 1000mm/sec FINE    ;
    :  DO[101]=OFF ;
    :  END ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =  1000.000  mm,	Y =   150.000  mm,	Z =   500.000  mm,
	W =   180.000 deg,	P =      .000 deg,	R =    30.000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =  1000.000  mm,	Y =   150.000  mm,	Z =   400.000  mm,
	W =   180.000 deg,	P =      .000 deg,	R =    30.000 deg
};
P[3:"retreat"]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   900.000  mm,	Y =   150.000  mm,	Z =   700.000  mm,
	W =   180.000 deg,	P =      .000 deg,	R =    30.000 deg
};
/END
