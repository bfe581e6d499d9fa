/PROG layer_2
/ATTR
OWNER       = MNEDITOR;
CREATE      = DATE 100-11-20  TIME 09:43:21;
MODIFIED    = DATE 100-12-05  TIME 05:26:29;
LINE_COUNT = 5;
PROTECT     = READ_WRITE;
TCD:  STACK_SIZE    = 0,
      TASK_PRIORITY = 50,
      TIME_SLICE    = 0,
      BUSY_LAMP_OFF = 0,
      ABORT_REQUEST = 0,
      PAUSE_REQUEST = 0;
DEFAULT_GROUP   = 1,1,*,*,*;
CONTROL_CODE    = 00000000 00000000;
/MN
:SR[30]=52.5;
:R[34]=0;
1: L P[1] 240cm/min CNT100 COORD ;
: Arc Start[1];
2: L P[2] WELD_SPEED CNT100 COORD PTH ;
: Arc End[1];
/POS
P[1]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =    10.000  mm,	Y =     0.000  mm,	Z =    20.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
   GP2:
	UF : 1, UT : 1,
	J1=    0.000 deg,	J2=    0.000 deg
};
P[2]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =    20.000  mm,	Y =     0.000  mm,	Z =    20.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
   GP2:
	UF : 1, UT : 1,
	J1=    0.000 deg,	J2=   10.000 deg
};
/END
