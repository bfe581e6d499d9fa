"""Robot programs: from a path through the calibrated cell to the controller, and back.

- :mod:`robotcell.programs.path`: the path file (CSV, mm and deg) in SI units;
- :mod:`robotcell.programs.write`: :func:`write_program`, a path solved through the cell and
  written as a program (:class:`ProgramOptions`: in pieces, through another cell's model);
- :mod:`robotcell.programs.check`: :func:`check_program`, every point of a program through the
  cell; :mod:`.lines`, every linear motion followed as the controller follows it; :mod:`.singular`,
  the distances to the singularities;
- :mod:`robotcell.programs.retarget`: :func:`retarget_program`, joint points recomputed after a
  recalibration;
- :mod:`robotcell.programs.config`, :mod:`.frames`: configuration flags, tools and frames as a
  controller holds them;
- :mod:`robotcell.programs.formats`: :func:`read_program`, a program file of any controller;
- :mod:`robotcell.programs.coordinated`: :func:`write_coordinated`, several robots' paths as one
  coordinated program (ABB MultiMove); :mod:`.coordcheck`: :func:`check_coordinated`, read back
  and checked, all robots together.

What a program holds (:class:`Program`, :class:`ProgramPoint`, :class:`Ref`, :class:`Config`)
and each controller's reader and writer are in :mod:`robotcell.controllers`. Formats, units and
sources: ``docs/programs.md``.
"""

from robotcell.controllers.model import Config, Program, ProgramPoint, Ref
from robotcell.programs.formats import read_program, vendor_of
from robotcell.programs.path import PathTargets, read_path
from robotcell.programs.write import (
    PathBreaks,
    ProgramOptions,
    WriteResult,
    build_programs,
    write_program,
)

__all__ = ["Config", "PathBreaks", "PathTargets", "Program", "ProgramOptions", "ProgramPoint",
           "Ref", "WriteResult", "build_programs", "read_path", "read_program", "vendor_of",
           "write_program"]
