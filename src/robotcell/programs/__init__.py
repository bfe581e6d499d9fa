"""Robot programs: from a path through the calibrated cell to the controller, and back.

- :mod:`robotcell.programs.model`: :class:`Program`, :class:`ProgramPoint`, :class:`Ref`,
  :class:`Config`: what every reader returns and every writer takes;
- :mod:`robotcell.programs.path`: the path file (CSV, mm and deg) in SI units;
- :mod:`robotcell.programs.write`: :func:`write_program`, a path solved through the cell and
  written as a program;
- :mod:`robotcell.programs.check`: :func:`check_program`, every point of a program through the
  cell;
- :mod:`robotcell.programs.retarget`: :func:`retarget_program`, joint points recomputed after a
  recalibration;
- :mod:`robotcell.programs.config`, :mod:`.frames`, :mod:`.axes`: configuration flags, tools and
  frames, external axes as each format holds them;
- one module per format: :mod:`.kuka`, :mod:`.abb`, :mod:`.fanuc`, :mod:`.yaskawa`.

Formats, units and sources: ``docs/programs.md``.
"""

from robotcell.programs.formats import read_program, vendor_of
from robotcell.programs.model import VENDORS, Config, Program, ProgramPoint, Ref
from robotcell.programs.path import PathTargets, read_path
from robotcell.programs.write import PathBreaks, WriteResult, build_programs, write_program

__all__ = ["VENDORS", "Config", "PathBreaks", "PathTargets", "Program", "ProgramPoint", "Ref",
           "WriteResult", "build_programs", "read_path", "read_program", "vendor_of",
           "write_program"]
