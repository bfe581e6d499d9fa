"""An output file that is one of the command's inputs is refused before anything is written.

Every command that writes a file is run with valid inputs and its output named like one of them
(the same name, ``./name``, a symbolic link, a hard link): it exits with status 2, names both
options, and leaves every file as it was. Without the check each of these runs succeeds and
replaces its input.
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
from robotcell.kinematics.models import save_robot
from robotcell.studies.simulate import simulate

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
EXAMPLE = EXAMPLES / "cell_kr16_track_turntable.yaml"
URDF = Path(__file__).resolve().parents[1] / "src" / "robotcell" / "robots" / "urdf" / "ur5e.urdf"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """Valid inputs of every command, written once; each test works on a copy."""
    d = tmp_path_factory.mktemp("inputs")
    shutil.copy(EXAMPLE, d / "cell.yaml")
    shutil.copy(EXAMPLES / "seam_part.csv", d / "seam.csv")
    shutil.copy(EXAMPLES / "layouts_kr16.yaml", d / "layouts.yaml")
    shutil.copy(URDF, d / "arm.urdf")
    cell = Cell.load(EXAMPLE)
    for procedure in ("tcp", "turntable", "workpiece"):
        simulate(cell, procedure, seed=1, tool="pointer").write_csv(d / f"{procedure}.csv")
    table = cellcal.turntable(cell, d / "turntable.csv", tool="pointer").result
    (d / "table.json").write_text(json.dumps(table.to_json()))
    robot = load_robot("kuka_kr16")
    save_robot(robot, d / "model.yaml")
    q = np.random.default_rng(0).uniform([-60, -100, 40, -90, -60, -90],
                                         [60, -50, 110, 90, 60, 90], (40, 6))
    xyz = robot.fk(np.radians(q))[:, :3, 3] * 1e3
    write_csv(d / "joints.csv", [f"a{i}" for i in range(1, 7)], q[:4])
    write_csv(d / "poses.csv", list("xyzabc"), pose_to_vendor(robot.fk(np.radians(q[:4])), "kuka"))
    write_csv(d / "tracker.csv", [f"a{i}" for i in range(1, 7)] + list("xyz"), np.hstack([q, xyz]))
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
    ("export --cell cell.yaml --format kuka -o cell.yaml", "--cell cell.yaml"),
    ("export --cell cell.yaml --format urdf -o ./cell.yaml", "--cell cell.yaml"),
    ("calibrate turntable turntable.csv --cell cell.yaml --tool pointer --json -o turntable.csv",
     "MEASUREMENTS turntable.csv"),
    ("calibrate tcp tcp.csv --cell cell.yaml --name pointer -o cell.yaml", "--cell cell.yaml"),
    (("calibrate workpiece workpiece.csv --cell cell.yaml --name part --tool pointer "
     "--turntable table.json -o table.json"), "--turntable table.json"),
    ("fk kuka_kr16 --input joints.csv -o joints.csv", "--input joints.csv"),
    ("fk --cell cell.yaml --joints 0,-90,90,0,0,0 -o cell.yaml", "--cell cell.yaml"),
    ("fk model.yaml --joints 0,-90,90,0,0,0 -o model.yaml", "ROBOT model.yaml"),
    ("ik kuka_kr16 --input poses.csv -o poses.csv", "--input poses.csv"),
    ("report table.json -o table.json", "RESULT table.json"),
    ("reach --cell cell.yaml seam.csv --frame part --tool torch -o seam.csv", "TARGETS seam.csv"),
    ("reach --cell cell.yaml seam.csv --frame part --tool torch --html cell.yaml",
     "--cell cell.yaml"),
    (("sweep --cell cell.yaml --targets seam.csv --layouts layouts.yaml --frame part "
     "--tool torch --workers 1 -o layouts.yaml"), "--layouts layouts.yaml"),
    ("simulate tcp --cell cell.yaml --tool pointer -o cell.yaml", "--cell cell.yaml"),
    ("plan turntable --cell cell.yaml --tool pointer --runs 0 -o cell.yaml", "--cell cell.yaml"),
    ("identify tracker.csv --robot kuka_kr16 -o tracker.csv", "MEASUREMENTS tracker.csv"),
    ("identify tracker.csv --robot model.yaml --report model.yaml", "--robot model.yaml"),
    ("dh from-urdf arm.urdf -o arm.urdf", "FILE arm.urdf"),
    ("dh convert model.yaml --to modified -o model.yaml", "MODEL model.yaml"),
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
        os.symlink("cell.yaml", work / "alias.yaml")
        out = "alias.yaml"
    elif spelling == "hardlink":
        os.link(work / "cell.yaml", work / "alias.yaml")
        out = "alias.yaml"
    else:
        (work / "sub").mkdir()
        out = f"sub/../../{work.name}/cell.yaml"
    before = _snapshot(work)
    code, _, err = run(capsys, "export", "--cell", "cell.yaml", "--format", "kuka", "-o", out)
    assert code == 2 and f"-o/--output {out} names the same file as --cell cell.yaml" in err
    assert _snapshot(work) == before


def test_reach_map_next_to_the_csv_may_not_be_the_csv(work, capsys):
    before = _snapshot(work)
    code, _, err = run(capsys, "reach", "--cell", "cell.yaml", "seam.csv", "--frame", "part",
                       "--tool", "torch", "-o", "map.html")
    assert code == 2 and "names the same file as -o/--output map.html" in err
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
