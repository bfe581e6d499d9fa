"""An output file that is one of the command's inputs is refused before anything is written.

Every command that writes a file is run with valid inputs and its output named like one of them
(the same name, ``./name``, a symbolic link, a hard link): it exits with status 2, names both
options, and leaves every file as it was. Without the check each of these runs succeeds and
replaces its input. The inputs have names whose ending says no kind of file (``.dat``), so that
nothing but the file's identity can refuse the output.
"""

from __future__ import annotations

import importlib
import json
import os
import shutil
from pathlib import Path

import click
import numpy as np
import pytest
from cli_helpers import run

from robotcell import load_robot, pose_to_vendor
from robotcell.cell import Cell
from robotcell.cell import calibrate as cellcal
from robotcell.cli import COMMANDS
from robotcell.cli.files import Command
from robotcell.io.tables import write_csv
from robotcell.robot.models import save_robot
from robotcell.studies.simulate import simulate

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
EXAMPLE = EXAMPLES / "cell_kr16_track_turntable.yaml"
URDF = Path(__file__).resolve().parents[1] / "src" / "robotcell" / "robots" / "urdf" / "ur5e.urdf"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """Valid inputs of every command, written once; each test works on a copy."""
    d = tmp_path_factory.mktemp("inputs")
    shutil.copy(EXAMPLE, d / "cell.dat")
    shutil.copy(EXAMPLES / "seam_part.csv", d / "seam.dat")
    shutil.copy(EXAMPLES / "layouts_kr16.yaml", d / "layouts.dat")
    shutil.copy(URDF, d / "arm.dat")
    cell = Cell.load(EXAMPLE)
    for procedure in ("tcp", "turntable", "workpiece"):
        simulate(cell, procedure, seed=1, tool="pointer").write_csv(d / f"{procedure}.dat")
    table = cellcal.turntable(cell, d / "turntable.dat", tool="pointer").result
    (d / "table.dat").write_text(json.dumps(table.to_json()))
    robot = load_robot("kuka_kr16")
    save_robot(robot, d / "model.dat")
    q = np.random.default_rng(0).uniform([-60, -100, 40, -90, -60, -90],
                                         [60, -50, 110, 90, 60, 90], (40, 6))
    xyz = robot.fk(np.radians(q))[:, :3, 3] * 1e3
    write_csv(d / "joints.dat", [f"a{i}" for i in range(1, 7)], q[:4])
    write_csv(d / "poses.dat", list("xyzabc"), pose_to_vendor(robot.fk(np.radians(q[:4])), "kuka"))
    write_csv(d / "tracker.dat", [f"a{i}" for i in range(1, 7)] + list("xyz"), np.hstack([q, xyz]))
    return d


@pytest.fixture
def work(inputs, tmp_path, monkeypatch) -> Path:
    for f in inputs.iterdir():
        shutil.copy(f, tmp_path / f.name)
    monkeypatch.chdir(tmp_path)
    return tmp_path


#: (command line, the input it names as output): every command that writes a file. Each line
#: runs (exit 0 or 3) and replaces its input when the check is missing.
CASES = [
    ("export --cell cell.dat --format kuka -o cell.dat", "--cell cell.dat"),
    ("export --cell cell.dat --format urdf -o ./cell.dat", "--cell cell.dat"),
    ("calibrate turntable turntable.dat --cell cell.dat --tool pointer --json -o turntable.dat",
     "MEASUREMENTS turntable.dat"),
    ("calibrate tcp tcp.dat --cell cell.dat --name pointer -o cell.dat", "--cell cell.dat"),
    (("calibrate workpiece workpiece.dat --cell cell.dat --name part --tool pointer "
     "--turntable table.dat -o table.dat"), "--turntable table.dat"),
    ("fk kuka_kr16 --input joints.dat -o joints.dat", "--input joints.dat"),
    ("fk --cell cell.dat --joints 0,-90,90,0,0,0 -o cell.dat", "--cell cell.dat"),
    ("fk model.dat --joints 0,-90,90,0,0,0 -o model.dat", "ROBOT model.dat"),
    ("ik kuka_kr16 --input poses.dat -o poses.dat", "--input poses.dat"),
    ("report table.dat -o table.dat", "RESULT table.dat"),
    ("reach --cell cell.dat seam.dat --frame part --tool torch -o seam.dat", "TARGETS seam.dat"),
    ("reach --cell cell.dat seam.dat --frame part --tool torch --html cell.dat",
     "--cell cell.dat"),
    (("sweep --cell cell.dat --targets seam.dat --layouts layouts.dat --frame part "
     "--tool torch --workers 1 -o layouts.dat"), "--layouts layouts.dat"),
    ("simulate tcp --cell cell.dat --tool pointer -o cell.dat", "--cell cell.dat"),
    ("plan turntable --cell cell.dat --tool pointer --runs 0 -o cell.dat", "--cell cell.dat"),
    ("identify tracker.dat --robot kuka_kr16 -o tracker.dat", "MEASUREMENTS tracker.dat"),
    ("identify tracker.dat --robot model.dat --report model.dat", "--robot model.dat"),
    ("dh from-urdf arm.dat -o arm.dat", "FILE arm.dat"),
    ("dh convert model.dat --to modified -o model.dat", "MODEL model.dat"),
]


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


@pytest.mark.parametrize("line, given", CASES)
def test_output_onto_an_input_is_refused_and_changes_nothing(work, capsys, line, given):
    before = _snapshot(work)
    code, _, err = run(capsys, *line.split())
    assert code == 2, err
    assert f"names the same file as {given}, which this command reads" in err
    assert _snapshot(work) == before


@pytest.mark.parametrize("spelling", ["link", "hardlink", "dotdot"])
def test_links_and_relative_paths_are_the_same_file(work, capsys, spelling):
    if spelling == "link":
        os.symlink("cell.dat", work / "alias.dat")
        out = "alias.dat"
    elif spelling == "hardlink":
        os.link(work / "cell.dat", work / "alias.dat")
        out = "alias.dat"
    else:
        (work / "sub").mkdir()
        out = f"sub/../../{work.name}/cell.dat"
    before = _snapshot(work)
    code, _, err = run(capsys, "export", "--cell", "cell.dat", "--format", "kuka", "-o", out)
    assert code == 2 and f"-o/--output {out} names the same file as --cell cell.dat" in err
    assert _snapshot(work) == before


def test_reach_map_next_to_the_csv_may_not_be_an_input(work, capsys):
    shutil.copy(work / "seam.dat", work / "seam.html")
    before = _snapshot(work)
    code, _, err = run(capsys, "reach", "--cell", "cell.dat", "seam.html", "--frame", "part",
                       "--tool", "torch", "-o", "seam.dat")
    assert code == 2
    assert "the map written next to -o seam.html names the same file as TARGETS seam.html" in err
    assert _snapshot(work) == before


def _leaves(cmd: click.Command, path: str):
    if isinstance(cmd, click.Group):
        ctx = click.Context(cmd)
        for name in cmd.list_commands(ctx):
            yield from _leaves(cmd.get_command(ctx, name), f"{path} {name}")
    else:
        yield path, cmd


def test_every_command_checks_its_outputs():
    """A new command that writes files gets the check: every command is a files.Command."""
    for name, target in COMMANDS.items():
        module, attr = target.split(":")
        for path, cmd in _leaves(getattr(importlib.import_module(module), attr), name):
            assert isinstance(cmd, Command), path
