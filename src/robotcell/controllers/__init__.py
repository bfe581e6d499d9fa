"""Robot controllers: one room per vendor, each an object that holds everything robotcell knows
of that controller.

- :mod:`robotcell.controllers.base`: :class:`~robotcell.controllers.base.Controller`, the
  interface every controller implements (pose format, export, program reader and writer,
  configuration flags, slot numbers and name limits, external axes, sources);
- :mod:`robotcell.controllers.registry`: the registered controllers by name and by program file
  ending (``get``, ``names``, ``register``);
- one package per controller: :mod:`.kuka`, :mod:`.abb`, :mod:`.fanuc`, :mod:`.yaskawa`,
  :mod:`.ur` (Universal Robots, URScript), each with its export (``export``) and its programs
  (``program``);
- what they share: :mod:`.model` (the :class:`~robotcell.controllers.model.Program` every
  reader returns and every writer takes), :mod:`.data` (the cell as a controller sees it),
  :mod:`.pendant` (pendant listings), :mod:`.text` (program text), :mod:`.axes` (external axes).

Pose formats that no controller here writes programs for (Staubli) are pose formats only:
:mod:`robotcell.io.poseformats`. How to add a controller:
``docs/conventions.md``.
"""
