"""The command line's words for the inputs library messages name (:func:`robotcell.errors.term`).

The library's errors, notes and advice name a Python parameter (``sigma``, ``references``); the
command line runs every command inside :func:`robotcell.errors.terms` with :data:`CLI_TERMS`,
so that the same message names the option a user of the command line types instead.
"""

from __future__ import annotations

__all__ = ["CLI_TERMS"]

#: Key of a message's input (see the calls of :func:`robotcell.errors.term`) to the options.
CLI_TERMS = {
    "the calibration": "this command",
    "sigma": "--sigma",
    "nominal": "--nominal-accuracy",
    "tool": "--tool",
    "tool=NAME": "--tool NAME",
    "tool=flange": "--tool 0,0,0,0,0,0",
    "tool=X,Y,Z,A,B,C": "--tool X,Y,Z,A,B,C",
    "robot=NAME_OR_FILE": "--robot NAME_OR_FILE",
    "cell": "--cell",
    "cell=FILE": "--cell CELL.yaml",
    "cell=FILE (Cell)": "--cell CELL.yaml (in Python: a Cell)",
    "cell (Cell)": "--cell (in Python: a Cell)",
    "with cell": "with --cell",
    "calibrate workpiece": "'robotcell calibrate workpiece'",
    "calibrate external-tcp": "'calibrate external-tcp'",
    "calibrate track": "'calibrate track'",
    "calibrate turntable --cell": "calibrate turntable --cell",
    "parent=world": "--parent world",
    "parent=robot": "--parent robot",
    "axis": "--axis",
    "reference": "--reference",
    "reference options": "--reference options",
    "reference=X,Y,Z": "--reference X,Y,Z (a touched point with known coordinates in L, mm)",
    "roll=zero": "--roll zero",
    "turntable": "--turntable",
    "turntable=JSON": ("--turntable TURNTABLE.json (the --json output of 'robotcell calibrate "
                       "turntable')"),
    "result=output": "output of 'robotcell calibrate ... --json'",
}
