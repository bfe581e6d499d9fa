"""The old module paths (before the layout by concept) import for one release: the same module
object as the new path, with a DeprecationWarning naming the new path."""

import importlib
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import robotcell
from robotcell._aliases import ALIASES, new_name

SRC = str(Path(robotcell.__file__).resolve().parents[1])

#: every old path a user may import today, with its new path (submodules of old packages too)
OLD = {**ALIASES,
       **{f"robotcell.cellcal.{m}": f"robotcell.cell.calibrate.{m}"
          for m in ("procedures", "touches")},
       **{f"robotcell.export.{m}": f"robotcell.io.export.{m}"
          for m in ("abb", "common", "fanuc", "kuka", "urdf", "yaskawa")}}


def test_the_table_holds_every_moved_module():
    assert set(ALIASES) == {f"robotcell.{m}" for m in (
        "transforms", "dh", "robot", "coupling", "modelfile", "poseformats", "tables", "fileio",
        "export", "axischain", "coupled", "cellik", "cellcal", "simulate", "plan", "demo",
        "reach", "sweep")}
    assert new_name("robotcell.export.kuka") == "robotcell.io.export.kuka"
    assert new_name("robotcell.cell") is None and new_name("robotcell.kinematics.dh") is None


@pytest.mark.parametrize("old", sorted(OLD))
def test_old_path_is_the_new_module_and_warns(old):
    new = importlib.import_module(OLD[old])
    sys.modules.pop(old, None)  # a previous test may have imported it
    with pytest.warns(DeprecationWarning, match=rf"{old} is deprecated .*import {OLD[old]}$"):
        module = importlib.import_module(old)
    assert module is new
    assert module.__name__ == OLD[old] and module.__spec__.name == OLD[old]


def test_from_imports_and_monkeypatching_see_one_module(monkeypatch):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        from robotcell.cellik import CellIKSolutions
        from robotcell.export import kuka
        from robotcell.modelfile import load_robot
    import robotcell.cell.ik
    import robotcell.io.export.kuka
    import robotcell.kinematics.models
    from robotcell.cell import Cell

    assert CellIKSolutions is robotcell.cell.ik.CellIKSolutions
    assert kuka is robotcell.io.export.kuka
    assert load_robot is robotcell.kinematics.models.load_robot
    monkeypatch.setattr(sys.modules["robotcell.cellik"], "MAX_STEP", 1.25)
    assert robotcell.cell.ik.MAX_STEP == 1.25
    assert isinstance(Cell.load(Path(__file__).resolve().parents[1] / "examples"
                                / "cell_kr16_track_turntable.yaml"), robotcell.cell.Cell)


def test_old_submodule_attributes_in_a_fresh_process():
    # `import robotcell` loaded these before; they are still attributes, loaded on first access,
    # and neither `import robotcell` nor the finder imports numpy.
    code = ("import sys, warnings; warnings.simplefilter('error')\n"
            "import robotcell\n"
            "assert 'numpy' not in sys.modules\n"
            "try:\n"
            "    robotcell.dh\n"
            "except DeprecationWarning as w:\n"
            "    assert 'robotcell.kinematics.dh' in str(w)\n"
            "else:\n"
            "    raise AssertionError('no warning')\n"
            "warnings.simplefilter('ignore')\n"
            "robotcell.dh.Chain; robotcell.transforms.make_pose; robotcell.modelfile.load_robot\n"
            "import robotcell.kinematics.dh\n"
            "assert robotcell.dh is robotcell.kinematics.dh\n")
    subprocess.run([sys.executable, "-c", code], env={"PYTHONPATH": SRC}, check=True, timeout=120)
