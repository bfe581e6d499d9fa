"""The acceptance test of a cell after ISO 9283: plan, programs, simulation, evaluation.

- :func:`plan`: the largest test cube in the arm's reach, its five poses and two paths, all
  reached in one configuration (:mod:`.testplan`, :mod:`.search`, :mod:`.cube`);
- :func:`write_plan`, :func:`read_plan`: the plan file (:mod:`.planfile`);
- :func:`write_programs`: the pose and path cycles as KUKA, ABB, FANUC and YASKAWA programs
  (:mod:`.cycles`, through :func:`robotcell.programs.write_program`);
- :func:`simulate`: a tracker's log of the test in a virtual cell (:mod:`.simulation`);
- :func:`read_log`, :func:`write_log`: the measurement log (:mod:`.log`);
- :func:`analyse`: the figures (pose accuracy and repeatability, distance, path, drift) and the
  verdict against limits (:mod:`.analysis`, :mod:`.figures`, :mod:`.verdict`).

Formulas, their sources and the choices made: ``docs/iso9283.md``.
"""

from robotcell.iso9283.analysis import Iso9283Result, analyse, fit_device_frame
from robotcell.iso9283.cycles import MIN_CYCLES, PATH_CYCLES, POSE_CYCLES, write_programs
from robotcell.iso9283.log import Log, read_log, write_log
from robotcell.iso9283.planfile import read_plan, write_plan
from robotcell.iso9283.simulation import simulate
from robotcell.iso9283.testplan import TestPlan, plan
from robotcell.iso9283.verdict import Limits, Verdict

__all__ = ["MIN_CYCLES", "PATH_CYCLES", "POSE_CYCLES", "Iso9283Result", "Limits", "Log",
           "TestPlan", "Verdict", "analyse", "fit_device_frame", "plan", "read_log", "read_plan",
           "simulate", "write_log", "write_plan", "write_programs"]
