"""HTML reports of results: one self-contained page each, its figures and 3D scene embedded.

- :mod:`robotcell.report.calibration`: the report of a calibration result, made from the JSON a
  calibration writes (``robotcell report``);
- :mod:`robotcell.report.identification`: the report of a kinematic identification;
- :mod:`robotcell.report.accuracy`: the report of a filtering through an identified arm;
- :mod:`robotcell.report.reach`: the page of a reachability map;
- :mod:`robotcell.report.iso9283`: the report of an ISO 9283 acceptance test;
- :mod:`robotcell.report.page`: the parts every page shares.

The reports stand on the 3D views (:mod:`robotcell.view`) whose scenes they embed.
"""

from robotcell.report.accuracy import write_accuracy_report
from robotcell.report.calibration import (
    CONDITION_GOOD,
    CONDITION_POOR,
    load_result,
    verdict,
    write_report,
)
from robotcell.report.identification import write_identification_report

__all__ = ["CONDITION_GOOD", "CONDITION_POOR", "load_result", "verdict", "write_accuracy_report",
           "write_identification_report", "write_report"]
