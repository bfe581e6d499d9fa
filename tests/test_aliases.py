"""The old module paths (before the layout by concept) import for one release: the same module
object as the new path, with a DeprecationWarning naming the new path."""

import importlib
import importlib.util
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
          for m in ("procedures", "touches")}}


def test_the_table_holds_every_moved_module():
    assert set(ALIASES) == {f"robotcell.{m}" for m in (
        "transforms", "dh", "robot", "coupling", "modelfile", "poseformats", "tables", "fileio",
        "axischain", "coupled", "cellik", "cellcal", "simulate", "plan", "demo",
        "reach", "sweep")}
    assert new_name("robotcell.cellcal.touches") == "robotcell.cell.calibrate.touches"
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
        from robotcell.modelfile import load_robot
    import robotcell.cell.ik
    import robotcell.kinematics.models
    from robotcell.cell import Cell

    assert CellIKSolutions is robotcell.cell.ik.CellIKSolutions
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


ROOT = Path(__file__).resolve().parents[1]
_SPEC = importlib.util.spec_from_file_location("relayout_imports",
                                               ROOT / "tools" / "relayout_imports.py")
_TOOL = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(_TOOL)
rewrite = _TOOL.rewrite

#: the only files that may name an old path: the alias table, its test, and the notes on it
MAY_NAME_OLD = {"src/robotcell/_aliases.py", "tests/test_aliases.py", "docs/conventions.md",
                "src/robotcell/__init__.py", "tools/relayout_imports.py"}


def test_rewrite_maps_old_paths_only():
    text = ("from robotcell import cellcal\nfrom robotcell.robot import Robot\n"
            "import robotcell.cellik  # src/robotcell/cellik.py, robotcell/export/urdf.py\n"
            "robotcell.robots robotcell.dhprocedure robotcell.cli.export robotcell.cell.ik\n")
    assert rewrite(text) == (
        "from robotcell.cell import calibrate as cellcal\n"
        "from robotcell.kinematics.robot import Robot\n"
        "import robotcell.cell.ik  # src/robotcell/cell/ik.py, robotcell/export/urdf.py\n"
        "robotcell.robots robotcell.dhprocedure robotcell.cli.export robotcell.cell.ik\n")


def test_no_file_of_the_repository_uses_an_old_path():
    files = [p for d in ("src", "tests", "benchmarks", "docs", "examples", "tools")
             for p in (ROOT / d).rglob("*") if p.suffix in (".py", ".md", ".yaml")]
    files.append(ROOT / "README.md")
    old = sorted(str(p.relative_to(ROOT)) for p in files
                 if str(p.relative_to(ROOT)) not in MAY_NAME_OLD
                 and rewrite(p.read_text(encoding="utf-8")) != p.read_text(encoding="utf-8"))
    assert not old, f"old module paths in {old}: run python tools/relayout_imports.py FILE..."
