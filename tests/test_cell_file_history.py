"""The cell file as the user wrote it: updates keep comments, key order and layout; every
version an update replaces is kept as a numbered backup; YAML files with duplicate keys or
absurd nesting are refused, naming the line."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import InputError, pose_from_vendor
from robotcell.cell import Cell, Provenance
from robotcell.cell.history import cell_history
from robotcell.io.yamlfile import MAX_DEPTH, dump_yaml, parse_yaml, update_document

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"
LAYOUTS = ROOT / "examples" / "layouts_kr16.yaml"
SEAM = ROOT / "examples" / "seam_part.csv"

#: A cell file as a person writes one: comments above, beside and between the entries, numbers
#: spelt their way (1.0, 95.0, 0.05), block and flow mappings mixed.
COMMENTED = """\
# Cell 7, welding line 2 -- maintained by hand, do not reformat.
# Values from the commissioning protocol P-7-2025.

name: kr16_track_turntable   # the cell's name in the plant's PLC
robot:
  model: kuka_kr16           # KR 16-2, serial 123456
track:
  name: KL1500
  # the track frame is the world frame of this cell
  frame: {x: 0, y: 0, z: 0, a: 0, b: 0, c: 0}
  robot_at_zero: {x: 0, y: 0, z: 450, a: 0.05, b: -0.03, c: 0.02}   # from the last service
  axis: x
  scale: 1.0                 # gear ratio checked 2025-01
  min: 0
  max: 6000
turntable:
  name: DKP_400_01
  parent: world
  frame: {x: 3000, y: 1600, z: 700, a: 90, b: 0.12, c: -0.08}
  min: -360
  max: 360

tools:
  # the welding torch: TCP at the wire tip, 15 mm stick-out
  torch:
    number: 1
    frame:
      x: 312.5               # mm
      y: -1.2
      z: 95.0
      a: 0
      b: 45
      c: 0
    mass: 3.2                # kg, with the cable package
    cog: [120, 0, 40]
  pointer:                   # calibration pointer, 250 mm
    number: 2
    frame: {x: 250, y: 0, z: 0, a: 0, b: 0, c: 0}

frames:
  fixture:
    number: 1
    parent: world
    frame: {x: 1800, y: -1200, z: 600, a: 30, b: 0, c: 0}   # clamping fixture
# end of file: nothing below this line
"""


def _comments(text: str) -> list[str]:
    """Every comment of a YAML text (what follows '#' outside quotes), in order."""
    return [m[1].strip() for line in text.splitlines() if (m := re.search(r"(#.*)$", line))]


def _leaves(data, path=()):
    """(key path, value) of every scalar of a parsed YAML document."""
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _leaves(v, (*path, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _leaves(v, (*path, i))
    else:
        yield path, data


def test_a_commented_cell_file_survives_three_updates(tmp_path):
    path = tmp_path / "cell.yaml"
    path.write_text(COMMENTED, encoding="utf-8")
    versions = [COMMENTED]
    rng = np.random.default_rng(3)
    updates = [
        lambda c: c.set_tool("torch", pose_from_vendor(
            [312.5, -1.2, 95.0, 0, 45, 0] + rng.normal(0, 0.1, 6), "kuka"),
            Provenance.now("tcp", rms_mm=0.05, note="6 touches from tcp.csv")),
        lambda c: c.update_turntable(Provenance.now("turntable", rms_mm=0.07),
                                     T_parent_B=pose_from_vendor([3001, 1599, 700.2, 90.01, 0.1,
                                                                  -0.07], "kuka")),
        lambda c: c.update_frame("part", pose_from_vendor([150, -80, 220, 15, 0, 0], "kuka"),
                                 Provenance.now("workpiece", rms_mm=0.1), parent="turntable"),
    ]
    for i, update in enumerate(updates, start=1):
        cell = Cell.load(path)
        update(cell)
        assert cell.save(path) == tmp_path / f"cell.yaml.{i}.bak"
        versions.append(path.read_text(encoding="utf-8"))
    final = versions[-1]
    # Every comment is still in the file, in its order.
    assert _comments(final) == _comments(COMMENTED)
    # Every version is kept, none overwritten: backup i holds the file before update i.
    for i in range(1, 4):
        assert (tmp_path / f"cell.yaml.{i}.bak").read_text(encoding="utf-8") == versions[i - 1]
    # Every original value is in the file, or (where an update changed it) in a backup.
    original = dict(_leaves(parse_yaml(COMMENTED, "original")))
    now = dict(_leaves(parse_yaml(final, "final")))
    changed = {k for k in original if now.get(k) != original[k]}
    assert changed and all(k[0] in ("tools", "turntable") for k in changed)
    assert "  scale: 1.0                 # gear ratio checked 2025-01\n" in final  # as spelt
    # Key order and layout: the untouched sections are the same lines as written.
    for block in ("name: kr16_track_turntable   # the cell's name in the plant's PLC\n",
                  "  robot_at_zero: {x: 0, y: 0, z: 450, a: 0.05, b: -0.03, c: 0.02}   # from",
                  "    cog: [120, 0, 40]\n", "  pointer:                   # calibration pointer"):
        assert block in final
    assert list(parse_yaml(final, "final")) == ["name", "robot", "track", "turntable", "tools",
                                                "frames"]
    assert list(parse_yaml(final, "final")["tools"]["torch"]) == [
        "number", "frame", "mass", "cog", "provenance"]
    np.testing.assert_allclose(Cell.load(path).frames["part"].pose[:3, 3], [0.15, -0.08, 0.22])


def test_the_history_lists_every_version_with_its_provenance(tmp_path, capsys):
    path = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, path)
    for rms in (0.05, 0.04):
        cell = Cell.load(path)
        cell.set_tool("torch", cell.tools["torch"].T_F_TCP,
                      Provenance("tcp", f"2026-01-0{round(rms * 100)}T08:00:00+01:00", rms,
                                 "touches.csv"))
        cell.save(path)
    versions = cell_history(path)
    assert [v.number for v in versions] == [1, 2, None]
    assert "tool torch" in versions[0].changed and len(versions[0].changed) == 6
    assert versions[1].changed == ["tool torch"] and versions[2].changed == ["tool torch"]
    assert versions[2].provenance["tool torch"]["rms_mm"] == 0.04
    code, out, err = run(capsys, "cell", "history", str(path))
    assert code == 0, err
    assert out.startswith(f"3 version(s) of {path}, oldest first")
    lines = out.splitlines()[1:]
    assert lines[0].startswith(f"{path}.1.bak") and "first kept version, 6 item(s)" in lines[0]
    assert lines[2].startswith(f"{path} (current)")
    assert lines[2].endswith("tool torch (tcp, RMS 0.040 mm)")
    code, _, err = run(capsys, "cell", "history", str(tmp_path / "none.yaml"))
    assert code == 2 and "does not exist, and no backup of it" in err


def test_update_adds_new_keys_in_order_and_keeps_unknown_ones():
    doc = parse_yaml("# head\na: 1   # one\nkeep: x   # not the program's\nc: {x: 1.0, y: 2}\n", "t")
    old = {"a": 1, "c": {"x": 1, "y": 2}}
    # A key the serialiser starts to write (another quantity of a calibration) flows through.
    new = {"a": 1, "b": {"covariance": [[1, 0], [0, 1]]}, "c": {"x": 1, "y": 3}}
    update_document(doc, old, new)
    text = dump_yaml(doc)
    assert text == ("# head\na: 1   # one\nb:\n  covariance:\n    - [1, 0]\n    - [0, 1]\n"
                    "keep: x   # not the program's\nc: {x: 1.0, y: 3}\n")
    update_document(doc, new, {"a": 2, "c": {"x": 1, "y": 3}})  # b dropped by the program
    assert dump_yaml(doc) == "# head\na: 2   # one\nkeep: x   # not the program's\nc: {x: 1.0, y: 3}\n"


def test_a_file_that_is_not_a_cell_is_replaced_whole_and_kept(tmp_path):
    path = tmp_path / "cell.yaml"
    path.write_text("just: text\n")
    Cell.load(EXAMPLE).save(path)
    assert path.read_text().startswith("# robotcell cell file")
    assert (tmp_path / "cell.yaml.1.bak").read_text() == "just: text\n"


# -- duplicate keys and nesting (every YAML file read) -----------------------------------------
DUPLICATE_TOOLS = EXAMPLE.read_text().replace("frames:\n", "tools:\n  other:\n    frame: {}\n"
                                                           "frames:\n")


def _line_of(text: str, needle: str, nth: int = 1) -> int:
    lines = [i for i, line in enumerate(text.splitlines(), 1) if line.startswith(needle)]
    return lines[nth - 1]


@pytest.mark.parametrize("argv", [
    ["cell", "show", "{cell}"],
    ["fk", "--cell", "{cell}", "--joints", "0,-90,90,0,0,0"],
    ["export", "--cell", "{cell}", "--format", "kuka"],
])
def test_duplicate_keys_in_a_cell_file_are_refused_naming_key_and_line(tmp_path, capsys, argv):
    path = tmp_path / "cell.yaml"
    path.write_text(DUPLICATE_TOOLS)
    code, out, err = run(capsys, *(a.format(cell=path) for a in argv))
    line = _line_of(DUPLICATE_TOOLS, "tools:", 2)
    assert code == 2 and out == ""
    assert f"line {line}, column 1: key 'tools' is given twice in the same mapping" in err


@pytest.mark.parametrize("text,key", [
    ("name: a\nname: b\nrobot: {model: kuka_kr16}\n", "name"),
    ("name: a\nrobot: {model: kuka_kr16}\nrobot: {model: ur5e}\n", "robot"),
    ("robot: {model: kuka_kr16}\ntools:\n  t: {frame: {x: 1, x: 2}}\n", "x"),
])
def test_duplicate_keys_anywhere_in_a_cell_file(tmp_path, text, key):
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match=rf"c.yaml: line \d+, column \d+: key '{key}' is given "
                                         "twice"):
        Cell.load(path)


def test_duplicate_keys_in_model_and_layouts_files(tmp_path, capsys):
    model = (ROOT / "src" / "robotcell" / "robots" / "kuka_kr16.yaml").read_text()
    (tmp_path / "m.yaml").write_text(model + "name: other\n")
    code, _, err = run(capsys, "fk", str(tmp_path / "m.yaml"), "--joints", "0,-90,90,0,0,0")
    assert code == 2 and "m.yaml: line" in err and "key 'name' is given twice" in err
    layouts = LAYOUTS.read_text()
    first = next(line for line in layouts.splitlines() if line and not line.startswith("#"))
    (tmp_path / "l.yaml").write_text(layouts + first + "\n")
    code, _, err = run(capsys, "sweep", "--cell", str(EXAMPLE), "--targets", str(SEAM),
                       "--layouts", str(tmp_path / "l.yaml"), "--frame", "part", "--tool",
                       "torch")
    assert code == 2 and f"key '{first.split(':')[0]}' is given twice" in err


@pytest.mark.parametrize("depth", [1000, 20000])
@pytest.mark.parametrize("argv", [
    ["fk", "--cell", "{cell}", "--joints", "0,-90,90,0,0,0"],
    ["ik", "--cell", "{cell}", "--pose", "1200,0,1200,0,90,0"],
    ["reach", "--cell", "{cell}", str(SEAM), "-o", "{tmp}/r.csv"],
    ["export", "--cell", "{cell}", "--format", "kuka"],
    ["cell", "show", "{cell}"],
    ["calibrate", "tcp", "{tmp}/t.csv", "--cell", "{cell}", "--name", "torch"],
])
def test_deeply_nested_cell_file_is_refused_naming_the_line(tmp_path, capsys, argv, depth):
    path = tmp_path / "cell.yaml"
    path.write_text("name: deep\nrobot: {model: kuka_kr16}\ntools:\n  t: {frame: "
                    + "[" * depth + "]" * depth + "}\n")
    (tmp_path / "t.csv").write_text("a1,a2,a3,a4,a5,a6\n0,-90,90,0,0,0\n")
    code, out, err = run(capsys, *(a.format(cell=path, tmp=tmp_path) for a in argv))
    assert code == 2 and "Traceback" not in out + err
    assert f"cell.yaml: line 4: nested more than {MAX_DEPTH} levels deep" in err


def test_the_depth_bound_fits_every_shipped_file():
    files = [*(ROOT / "src" / "robotcell" / "robots").glob("*.yaml"),
             *(ROOT / "examples").rglob("*.yaml")]
    for f in files:
        parse_yaml(f.read_text(encoding="utf-8"), str(f))  # none refused
    assert len(files) > 16


def test_a_save_without_changes_leaves_the_text_as_written(tmp_path):
    path = tmp_path / "cell.yaml"
    path.write_text(COMMENTED)
    Cell.load(path).save(path)
    assert path.read_text() == COMMENTED
