/PROG  GUNMACRO	  Macro
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "Move gun";
PROG_SIZE	= 646;
CREATE		= DATE 24-03-11  TIME 15:27:12;
MODIFIED	= DATE 24-03-12  TIME 15:05:16;
FILE_NAME	= GUNMACRO;
VERSION		= 0;
LINE_COUNT	= 9;
MEMORY_SIZE	= 1074;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,1,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
  SPOT : TRUE ; 
  SPOT Welding Equipment Number : 1 ;
/MN
   1:  !AR[1]: velocity label ;
   2:  !AR[2]: position register index ;
   3:  JMP LBL[AR[1]] ;
   4:  LBL[1:Normal velocity] ;
   5:L PR[AR[2]] 2000mm/sec FINE    ;
   6:  END ;
   7:  LBL[15:P1/Tips_tch.Gun5] ;
   8:L P[...] 250mm/sec FINE    ;
   9:  END ;
/POS
/END
