"""Input and output at the vendor boundary: measurement tables, vendor pose formats, YAML and
safe file writing (millimetres and degrees live here, SI inside the library). Every other package
stands on it; controller exports are the package :mod:`robotcell.export`, over the cell.

- :mod:`robotcell.io.tables`: CSV measurement tables with named columns;
- :mod:`robotcell.io.poseformats`: vendor pose conventions (KUKA, ABB, FANUC, YASKAWA);
- :mod:`robotcell.io.targets`: targets files, TCP poses with the external axes of each
  (the one reader of every command that takes targets);
- :mod:`robotcell.io.fileio`: reading text and writing files atomically;
- :mod:`robotcell.io.yamlfile`: YAML read strictly, updated keeping comments, read back when
  written;
- :mod:`robotcell.io.locking`: the lock of a file that several processes update.
"""
