"""The placement of a cell's robots in each other, in the FANUC and YASKAWA exports.

Independent checks: the FANUC values put the leader's WORLD where the cell has it when composed
as rpiRobotics/fanuc_motion_program_exec ``tools/roboguide_base_adjust.py`` does (R2 = R1 times
the pendant's X, Y, Z, W, P, R); the YASKAWA values put R2's TCP where the cell has it when
composed as Yaskawa-Global/motoros2 ``src/PositionMonitor.c`` does (the robot calibration as
ZYX Euler angles, then the robot's own FK). Both with scipy's ``Rotation.from_euler``, not
robotcell's pose formats.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from cli_helpers import run
from scipy.spatial.transform import Rotation

from robotcell.cell import Cell, cell_from_dict
from robotcell.export import export_cell, parse_export

_NUM = r"(-?\d+\.\d+)"


def _cell(robots: dict, name: str = "pairs") -> Cell:
    return cell_from_dict({"name": name, "robots": robots})


def _fixed(model: str, frame: dict, source: str = "nominal") -> dict:
    return {"model": model, "frame": frame, "base_provenance": {"source": source, "rms_mm": 0.12},
            "tools": {"torch": {"number": 1, "frame": {"x": 300, "y": 0, "z": 90, "a": 0,
                                                       "b": 45, "c": 0}}}}


def _random_frame(rng: np.random.Generator) -> dict:
    xyz = rng.uniform(-2500, 2500, 3)
    abc = rng.uniform([-180, -30, -30], [180, 30, 30])
    return dict(zip("xyzabc", (*xyz, *abc)))


def _values(text: str, fields: tuple[str, ...], marker: str) -> list[np.ndarray]:
    pattern = re.escape(marker) + r"\s+" + r"\s+".join(f"{f} {_NUM}" for f in fields)
    return [np.array(m, float) for m in re.findall(pattern, text)]


def _homogeneous(R: Rotation, p: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R.as_matrix(), p
    return T


@pytest.mark.parametrize("seed", range(5))
def test_the_fanuc_pair_puts_the_leaders_world_where_the_cell_has_it(seed):
    rng = np.random.default_rng(seed)
    cell = _cell({"a": _fixed("fanuc_m20ia", _random_frame(rng)),
                  "b": _fixed("fanuc_m20ia", _random_frame(rng), "robot-to-robot")})
    text = export_cell(cell, "fanuc", "a")
    assert "! Coord Pair 1: Leader Group 2 = b, Follower Group 1 = a" in text
    assert "b's base: robot-to-robot, rms 0.120 mm" in text
    (x, y, z, w, p, r), = _values(text, ("X", "Y", "Z", "W", "P", "R"), "!")
    tp = _homogeneous(Rotation.from_euler("ZYX", [r, p, w], degrees=True), [x, y, z])
    r1 = cell.robots["a"].T_world_R.copy()
    r1[:3, 3] *= 1000.0
    expected = cell.robots["b"].T_world_R.copy()
    expected[:3, 3] *= 1000.0
    np.testing.assert_allclose((r1 @ tp)[:3, 3], expected[:3, 3], atol=1e-5)   # mm
    np.testing.assert_allclose((r1 @ tp)[:3, :3], expected[:3, :3], atol=1e-9)
    assert export_cell(cell, "fanuc", "b").endswith(text[text.index("! coordinated pair"):])


@pytest.mark.parametrize("seed", range(5))
def test_the_yaskawa_calibration_puts_r2s_tcp_where_the_cell_has_it(seed):
    rng = np.random.default_rng(seed)
    cell = _cell({"r1": _fixed("abb_irb120", _random_frame(rng)),
                  "r2": _fixed("abb_irb120", _random_frame(rng))})
    text = export_cell(cell, "yaskawa", "r2")
    assert "' R1+R2 (R2 = r2): R2's robot coordinates in R1's" in text
    (x, y, z, rx, ry, rz), = _values(text, ("X", "Y", "Z", "Rx", "Ry", "Rz"), "'")
    srang = _homogeneous(Rotation.from_euler("ZYX", [rz, ry, rx], degrees=True),
                         np.array([x, y, z]) / 1000.0)
    q = rng.uniform(-1, 1, 6)
    tcp_in_r2 = cell.for_robot("r2").robot.fk(q)
    tcp_in_world = cell.fk(q, robot="r2")
    np.testing.assert_allclose(cell.robots["r1"].T_world_R @ srang @ tcp_in_r2, tcp_in_world,
                               atol=1e-8)


def test_a_robot_on_a_track_is_named_and_no_values_are_written():
    cell = Cell.load("examples/cell_two_robots_positioner.yaml")
    for fmt, marker in (("fanuc", "!"), ("yaskawa", "'")):
        text = export_cell(cell, fmt, "abb")
        assert "not written (kuka on a track" in text
        assert not _values(text, ("X",), marker + "  ")


def test_three_robots_fanuc_pairs_groups_1_and_2_yaskawa_every_robot_to_r1():
    rng = np.random.default_rng(7)
    cell = _cell({n: _fixed("abb_irb2400", _random_frame(rng)) for n in ("p", "q", "s")})
    fanuc = export_cell(cell, "fanuc", "s")
    assert "Coord Pair 2: Leader Group 3 = s, Follower Group 1 = p: not written (group 3" in fanuc
    assert len(_values(fanuc, ("X", "Y", "Z", "W", "P", "R"), "!")) == 1
    yaskawa = export_cell(cell, "yaskawa", "q")
    assert len(_values(yaskawa, ("X", "Y", "Z", "Rx", "Ry", "Rz"), "'")) == 2
    assert "' R1+R3 (R3 = s)" in yaskawa


@pytest.mark.parametrize("fmt", ["fanuc", "yaskawa"])
def test_the_pair_lines_leave_the_listing_readable_and_a_one_robot_cell_without_them(fmt):
    rng = np.random.default_rng(3)
    cell = _cell({"a": _fixed("abb_irb2400", _random_frame(rng)),
                  "b": _fixed("abb_irb2400", _random_frame(rng))})
    with_pairs = export_cell(cell, fmt, "a")
    alone = export_cell(cell.for_robot("a"), fmt)
    assert with_pairs.startswith(alone) and len(with_pairs) > len(alone)
    back, ref = parse_export(with_pairs, fmt), parse_export(alone, fmt)
    assert [s.name for s in back.tools] == [s.name for s in ref.tools]
    assert "R1+" not in alone and "Coord Pair" not in alone


def test_the_command_line_writes_the_pairs_and_refuses_without_a_robot_name(capsys, tmp_path):
    code, out, _ = run(capsys, "export", "--cell", "examples/cell_two_robots_positioner.yaml",
                       "--format", "yaskawa", "--robot-name", "abb")
    assert code == 0
    assert "' R1+R2 (R2 = abb): not written" in out
    written = tmp_path / "frames.txt"
    code, _, err = run(capsys, "export", "--cell", "examples/cell_two_robots_positioner.yaml",
                       "--format", "fanuc", "-o", written)
    assert code == 2
    assert "say which one with --robot-name NAME" in err
    assert not written.exists()


@pytest.mark.parametrize("fmt", ["fanuc", "yaskawa"])
def test_the_export_written_again_to_a_path_with_spaces_is_the_same_and_reads_back(
        fmt, capsys, tmp_path):
    out = tmp_path / "my exports" / "frames abb.txt"
    out.parent.mkdir()
    texts = []
    for _ in range(2):
        code, _, err = run(capsys, "export", "--cell", "examples/cell_two_robots_positioner.yaml",
                           "--format", fmt, "--robot-name", "abb", "-o", out)
        assert code == 0, err
        texts.append(out.read_text(encoding="utf-8"))
    assert texts[0] == texts[1]
    assert ("Coord Pair 1" if fmt == "fanuc" else "R1+R2") in texts[0]
    assert [s.name for s in parse_export(texts[0], fmt).tools] == ["torch", "pointer"]
