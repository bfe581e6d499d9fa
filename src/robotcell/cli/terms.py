"""The command line's words for the inputs library messages name (:func:`robotcell.errors.term`).

The library's errors, notes and advice name a Python parameter (``sigma``, ``references``); the
command line runs every command inside :func:`robotcell.errors.terms` with :data:`CLI_TERMS`,
so that the same message names the option a user of the command line types instead.
"""

from __future__ import annotations

__all__ = ["CLI_TERMS"]

#: Key of a message's input (see the calls of :func:`robotcell.errors.term`) to the command
#: line's words. A key is a parameter (``sigma``), a parameter with the form of its value
#: (``tool=NAME``) or a procedure (``procedure:NAME``; ``procedure``: the one running), never a
#: command line: only this table spells commands (``tests/test_message_terms.py``).
CLI_TERMS = {
    "procedure": "this command",
    "sigma": "--sigma",
    "nominal": "--nominal-accuracy",
    "tool": "--tool",
    "tool=NAME": "--tool NAME",
    "tool=flange": "--tool 0,0,0,0,0,0",
    "tool=X,Y,Z,A,B,C": "--tool X,Y,Z,A,B,C",
    "robot=NAME_OR_FILE": "--robot NAME_OR_FILE",
    "robot=NAME": "with --robot-name NAME",
    "cell": "--cell",
    "cell=FILE": "--cell CELL.yaml",
    "cell=FILE (Cell)": "--cell CELL.yaml (in Python: a Cell)",
    "cell (Cell)": "--cell (in Python: a Cell)",
    "cell:into": "with --cell",
    "procedure:workpiece": "'robotcell calibrate workpiece'",
    "procedure:external-tcp": "'calibrate external-tcp'",
    "procedure:track": "'calibrate track'",
    "procedure:turntable(cell)": "calibrate turntable --cell",
    "procedure:shared-positioner": "'robotcell calibrate shared-positioner'",
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
    "result=json": "output of 'robotcell calibrate ... --json'",
}
