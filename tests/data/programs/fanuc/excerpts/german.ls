/PROG  DEUTSCH
/ATTR
EIGN.		= MNEDITOR;
KOMMENTAR	= "Auszug fuer Tests";
PROG_GRÖßE	= 10510;
ERSTELL		= TAG 24-03-11  ZEIT 19:31:52;
GEÄNDERT	= TAG 24-03-12  ZEIT 13:02:46;
DATEI_NAME	= DEUTSCH;
VERSION		= 0;
ZEILEN		= 9;
SPEICHERGR.	= 20086;
SCHUTZ		= LESEN_SCHREIB;
TCD:  STACK_GRÖßE	= 500,
      TASK_PRIORITY	= 50,
      ZEITSCHEIBE	= 0,
      BUSY_LAMP_AUS	= 0,
      ABORT_ANFRAGE	= 0,
      HALT_ANFRAGE	= 0;
DEFAULT_GRUP	= 1,*,*,*,*;
KONTROLLCODE	= 00000000 00000000;
/APPL
/MN
   1:  BENUTZER_NUM=0 ;
   2:  WKZ_NUM=0 ;
   3:J P[1] 100% CNT0 ACC100 ZEIT VOR    .10sek,P-SPS    ;
      1:  A[23]=(AUS) ;
      2:  AUFRUF MAKRO050    ;
   4:L P[2] 1500mm/sek CNT0 ACC100 ZEIT VOR    .10sek,P-SPS    ;
   5:J P[3] 100% CNT0 ACC100 ZEIT VOR    .10sek,P-SPS WKZ_Offset ,PR[11]    ;
   6:L P[2] max_Geschw. CNT0 ACC100    ;
   7:L P[1] 200mm/sek CNT0 ACC250 Interrupt,LABEL[1]    ;
   8:  LABEL[1] ;
   9:  A[23]=AN ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 0,		KONFIG : 'N U T, 0, 0, 0',
	X =  1050.000  mm,	Y =  -100.000  mm,	Z =   550.000  mm,
	W =  -175.000 deg,	P =    -5.000 deg,	R =    10.000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 0,		KONFIG : 'N U T, 0, 0, 0',
	X =  1050.000  mm,	Y =   100.000  mm,	Z =   450.000  mm,
	W =  -175.000 deg,	P =    -5.000 deg,	R =    10.000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 0,		KONFIG : 'N U T, 0, 0, 0',
	X =   950.000  mm,	Y =      .000  mm,	Z =   700.000  mm,
	W =   180.000 deg,	P =      .000 deg,	R =      .000 deg
};
/END
