"""Interactive 3D views of a cell, of calibration data and of paths: one HTML file, no server.

- :mod:`robotcell.view.scene`: what a view shows (items in SI units), independent of the
  plotting library; :mod:`robotcell.view.shapes` and :mod:`robotcell.view.arm` build items
  (touches, residual vectors, fitted circles and lines, plates; a DH chain's links and axes).
- :mod:`robotcell.view.plot`: a scene as a plotly figure (mm), as one self-contained page, and
  as a fragment of a report's page.
- :mod:`robotcell.view.calibration`: the scene of a calibration result (its touches, the fitted
  geometry, the residuals magnified); :mod:`robotcell.view.identification`: the scene of a
  kinematic identification (the measured targets, the identified arm beside the nominal one).
- :mod:`robotcell.view.cellscene`: the view of a cell (:func:`cell_figure`, written as a page by
  :func:`write_cell_view`);
  :mod:`robotcell.view.path`: a path with the arm at each point, on a slider;
  :mod:`robotcell.view.program`: a robot program in it, its bad points marked;
  :mod:`robotcell.view.coordinated`: a coordinated program of several robots, all moving
  together, with the closest pair of shapes at each point;
  :mod:`robotcell.view.reach`: a reachability map in the cell.
- :mod:`robotcell.view.pyplot`: matplotlib's pyplot, off screen, for the PNG figures of the
  reports and of the reachability map.

The views stand over the cell and the programs and under the reports (:mod:`robotcell.report`),
which draw the scenes of results. The names below are imported on first use (PEP 562), so that
importing a scene or plotting module (for a report) does not load the cell; plotly itself is
imported only to draw.
See docs/view.md.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from robotcell._lazy import module_getattr

if TYPE_CHECKING:
    from robotcell.view.calibration import calibration_scene
    from robotcell.view.cellscene import cell_figure, cell_scene, write_cell_view
    from robotcell.view.coordinated import coordinated_scene, write_coordinated_view
    from robotcell.view.identification import identification_scene
    from robotcell.view.path import PathMarks, path_scene
    from robotcell.view.plot import page, scene_figure, write_html
    from robotcell.view.program import program_scene, write_program_view
    from robotcell.view.reach import read_reach
    from robotcell.view.scene import Arrows, Lines, Mesh, Points, Scene, Step, Triads

#: public name -> module that defines it
_LAZY = {
    "calibration_scene": "robotcell.view.calibration",
    **dict.fromkeys(["cell_figure", "cell_scene", "write_cell_view"], "robotcell.view.cellscene"),
    **dict.fromkeys(["coordinated_scene", "write_coordinated_view"],
                    "robotcell.view.coordinated"),
    "identification_scene": "robotcell.view.identification",
    **dict.fromkeys(["PathMarks", "path_scene"], "robotcell.view.path"),
    **dict.fromkeys(["page", "scene_figure", "write_html"], "robotcell.view.plot"),
    **dict.fromkeys(["program_scene", "write_program_view"], "robotcell.view.program"),
    "read_reach": "robotcell.view.reach",
    **dict.fromkeys(["Arrows", "Lines", "Mesh", "Points", "Scene", "Step", "Triads"],
                    "robotcell.view.scene"),
}

__all__ = ["Arrows", "Lines", "Mesh", "PathMarks", "Points", "Scene", "Step", "Triads",
           "calibration_scene", "cell_figure", "cell_scene", "coordinated_scene",
           "identification_scene", "page", "path_scene", "program_scene", "read_reach",
           "scene_figure", "write_cell_view", "write_coordinated_view", "write_html",
           "write_program_view"]


#: Import a public name from its module on first access (PEP 562).
__getattr__ = module_getattr(_LAZY, __name__, globals())


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY])
