"""Studies built on the cell: simulated measurements, planning, the demo, reach and sweeps.

- :mod:`robotcell.studies.simulate`: synthetic measurement tables with known truth;
- :mod:`robotcell.studies.plan`: planning a calibration (which touches, checked by Monte Carlo);
- :mod:`robotcell.studies.demo`: the end-to-end demo;
- :mod:`robotcell.studies.reach`: reach maps of a cell;
- :mod:`robotcell.studies.identify`: the identification of an arm from a measurement file, with
  its cross-validation, report, controller offsets and cell update, as one call;
- :mod:`robotcell.studies.sweep`: layout sweeps (robot, track, turntable or part placed over a
  grid).
"""
