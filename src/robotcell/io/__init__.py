"""Input and output at the vendor boundary: measurement tables, vendor pose formats, safe file
writing and controller exports (millimetres and degrees live here, SI inside the library).

- :mod:`robotcell.io.tables`: CSV measurement tables with named columns;
- :mod:`robotcell.io.poseformats`: vendor pose conventions (KUKA, ABB, FANUC, YASKAWA);
- :mod:`robotcell.io.fileio`: reading text and writing files atomically;
- :mod:`robotcell.io.export`: controller exports and URDF.
"""
