"""Old module paths of robotcell, kept importable for one release.

Before 0.2 the modules stood at the top level (``robotcell.transforms``, ``robotcell.cellik``,
...). They now live in concept packages (``docs/conventions.md``, "Layout"). Importing an old path
gives the SAME module object as the new path (so monkeypatching and ``isinstance`` see one
module) and emits a :class:`DeprecationWarning` naming the new path. A submodule of an old
package (``robotcell.cellcal.touches``) maps the same way.

:func:`install` puts the finder first on :data:`sys.meta_path`; ``robotcell/__init__.py`` calls
it. The finder imports nothing until an old path is imported.
"""

from __future__ import annotations

import importlib
import importlib.machinery
import sys
import warnings
from types import ModuleType

#: old module path -> new module path (submodules of an old package follow their package)
ALIASES = {
    "robotcell.transforms": "robotcell.kinematics.transforms",
    "robotcell.dh": "robotcell.kinematics.dh",
    "robotcell.robot": "robotcell.kinematics.robot",
    "robotcell.coupling": "robotcell.kinematics.coupling",
    "robotcell.modelfile": "robotcell.kinematics.models",
    "robotcell.poseformats": "robotcell.io.poseformats",
    "robotcell.tables": "robotcell.io.tables",
    "robotcell.fileio": "robotcell.io.fileio",
    "robotcell.axischain": "robotcell.cell.axischain",
    "robotcell.coupled": "robotcell.cell.kinematics",
    "robotcell.cellik": "robotcell.cell.ik",
    "robotcell.cellcal": "robotcell.cell.calibrate",
    "robotcell.simulate": "robotcell.studies.simulate",
    "robotcell.plan": "robotcell.studies.plan",
    "robotcell.demo": "robotcell.studies.demo",
    "robotcell.reach": "robotcell.studies.reach",
    "robotcell.sweep": "robotcell.studies.sweep",
}


def new_name(old: str) -> str | None:
    """The new module path of the old path ``old``, or None when ``old`` is not an old path."""
    if old in ALIASES:
        return ALIASES[old]
    package = old.rpartition(".")[0]
    while package:
        if package in ALIASES:
            return f"{ALIASES[package]}.{old[len(package) + 1:]}"
        package = package.rpartition(".")[0]
    return None


class _AliasLoader:
    """Gives the module of the new path for an old path (an import loader, PEP 451)."""

    def __init__(self, new: str) -> None:
        self.new = new

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        warnings.warn(f"{spec.name} is deprecated and will be removed in the next release; "
                      f"import {self.new}", DeprecationWarning, stacklevel=2)
        module = importlib.import_module(self.new)
        self._spec = module.__spec__  # the import system writes the alias spec over it
        return module

    def exec_module(self, module: ModuleType) -> None:
        module.__spec__ = self._spec


class AliasFinder:
    """Finds the old module paths of :data:`ALIASES` (and their submodules).

    A meta path finder (PEP 451); it does not subclass :mod:`importlib.abc`, whose import costs
    ``import robotcell`` as much again.
    """

    def find_spec(self, fullname: str, path: object = None,
                  target: object = None) -> importlib.machinery.ModuleSpec | None:
        if not fullname.startswith("robotcell."):
            return None
        new = new_name(fullname)
        if new is None:
            return None
        return importlib.machinery.ModuleSpec(fullname, _AliasLoader(new))


def install() -> None:
    """Put the alias finder first on :data:`sys.meta_path` (once)."""
    if not any(isinstance(f, AliasFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, AliasFinder())
