/PROG surface
/ATTR
OWNER			= MNEDITOR;
COMMENT			= "";
PROG_SIZE		= 4757;
FILE_NAME		= surface;
VERSION			= 0;
LINE_COUNT		= 8;
MEMORY_SIZE		= 5089;
PROTECT			= READ_WRITE;
TCD:  STACK_SIZE		= 0,
      TASK_PRIORITY		= 50,
      TIME_SLICE		= 0,
      BUSY_LAMP_OFF		= 0,
      ABORT_REQUEST		= 0,
      PAUSE_REQUEST		= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
	1:  UFRAME_NUM=0 ;
	2:  UTOOL_NUM=1 ;
	3:	;
	4:J P[1] 100% CNT60 Tool_Offset,PR[15] 	;
	5:L P[2] 200mm/sec CNT60 Tool_Offset,PR[15] 	;
	6:J P[1] 100% CNT60 	;
	7:L P[2] 200mm/sec CNT60 	;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =	1200.081761	mm,	Y =	-315.778136	mm,	Z =	423.048370	mm,
	W =	180.000000	deg,	P =	-0.000000	deg,	R =	0.000000	deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =	1150.160145	mm,	Y =	-237.127066	mm,	Z =	442.624681	mm,
	W =	180.000000	deg,	P =	-0.000000	deg,	R =	0.000000	deg
};
/END
