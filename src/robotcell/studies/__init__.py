"""Studies built on the cell: simulated measurements, planning, the demo cell, reach and sweeps.

- :mod:`robotcell.studies.simulate`: synthetic measurement tables with known truth;
- :mod:`robotcell.studies.plan`: planning a calibration (which touches, checked by Monte Carlo);
- :mod:`robotcell.studies.demo`: the demo cell, true and nominal (the walk-through is
  :mod:`robotcell.demo`);
- :mod:`robotcell.studies.reach`: reach maps of a cell;
- :mod:`robotcell.studies.identify`: the identification of an arm from a measurement file, with
  its cross-validation, what its report needs, controller offsets and cell update, as one call;
- :mod:`robotcell.studies.sweep`: layout sweeps (robot, track, turntable or part placed over a
  grid).
"""
