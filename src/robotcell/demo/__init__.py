"""The demo walk-through (``robotcell demo``), in the presentation tier beside the reports and
views: it runs the library's commands on a virtual cell and writes their reports, exports,
program and 3D views, as a technician would with the command line.

- :mod:`robotcell.demo.walkthrough`: commission the demo cell (:func:`run_demo`);
- :mod:`robotcell.demo.accuracy`: its last step, identify the arm and filter a path.

The demo cell itself, true and nominal, is :func:`robotcell.studies.demo.demo_cells`.
"""
