"""The controllers (robotcell.controllers): one object per vendor in one registry; a further
controller added in this file alone drives the export and the programs; the numbers and names
each controller holds."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.controllers.axes import ExternalAxes, numbered_axes
from robotcell.controllers.base import Controller, SlotRange
from robotcell.controllers.data import ControllerData, Slot
from robotcell.controllers.model import Config, Program, ProgramPoint, Ref
from robotcell.controllers.registry import CONTROLLERS, get, names, register, unregister
from robotcell.controllers.text import Lines, fmt_num
from robotcell.errors import InputError
from robotcell.export import export_cell, parse_export
from robotcell.ik.config import kuka_status_turn
from robotcell.io.poseformats import PoseFormat, pose_from_vendor, pose_to_vendor

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"
SEAM = ROOT / "examples" / "seam_part.csv"


# -- a further controller, written here and nowhere else -------------------------------------------
#: Its pose format: X, Y, Z (mm), then Rx, Ry, Rz (deg) with R = Rx Ry Rz.
TOY_POSE = PoseFormat("toy", ("X", "Y", "Z", "RX", "RY", "RZ"), "mm, deg", "XYZ")


def _pose_text(T: np.ndarray) -> str:
    return " ".join(fmt_num(v, 9) for v in pose_to_vendor(T, TOY_POSE))


class Toy(Controller):
    """A made-up controller: one line per tool, frame and point, ``#`` comments."""

    name = "toy"
    label = "TOY"
    pose_format = TOY_POSE
    reference = "world"
    table_frames = True
    world_ref = Ref(number=0, kind="world")
    world_name = "WORLD"
    program_suffixes = (".toy",)
    program_files = "TOY .toy"
    comment = "#"
    export_name = "cell.txt"
    name_limit = 12
    tool_slots = SlotRange("TOOL", 1, 4)
    frame_slots = SlotRange("FRAME", 1, 4)
    config_fields = ("S", "T")
    sources = ("this test file",)

    def format_export(self, data: ControllerData, cell_name: str) -> str:
        lines = [f"# toy export of {cell_name}"]
        lines += [f"TOOL {s.number} {_pose_text(s.pose)} {s.name}" for s in data.tools]
        lines += [f"FRAME {s.number} {_pose_text(s.pose)} {s.name} {int(s.on_table)}"
                  for s in data.frames]
        return "\n".join(lines) + "\n"

    def parse_export(self, text: str) -> ControllerData:
        data = ControllerData()
        for line in text.splitlines():
            key, *rest = line.split()
            if key in ("TOOL", "FRAME"):
                T = pose_from_vendor([float(v) for v in rest[1:7]], TOY_POSE)
                slot = Slot(rest[7], int(rest[0]), T, on_table=rest[8:] == ["1"])
                (data.tools if key == "TOOL" else data.frames).append(slot)
        return data

    def write_program(self, program: Program, header: list[str]) -> dict[str, str]:
        first = program.points[0]
        lines = [*(f"# {h}" for h in header), f"PROGRAM {program.name}",
                 f"TOOL {first.tool.number}", f"FRAME {first.frame.number or 0}"]
        for p in program.points:
            ext = " ".join(f"{k}={fmt_num(v, 9)}" for k, v in p.external.items())
            lines.append(f"{p.motion.upper()} {p.name} {_pose_text(p.pose)} "
                         f"{self.config_text(p.config.values)} {ext}".rstrip())
        lines.append("END")
        return {f"{program.name}.toy": "\n".join(lines) + "\n"}

    def read_program(self, path: str | Path) -> tuple[Program, list[str]]:
        lines = Lines(path, "toy program")
        program = Program(Path(path).stem, self.name, files=(str(path),))
        tool = frame = Ref(number=0)
        for lineno, line in enumerate(lines.lines, start=1):
            key, *rest = line.split() or [""]
            if key in ("TOOL", "FRAME"):
                ref = Ref(number=int(rest[0]), on_table=None if key == "FRAME" else False)
                tool, frame = (ref, frame) if key == "TOOL" else (tool, ref)
            elif key in ("PTP", "LIN"):
                values = [lines.number(v, lineno) for v in rest[1:7]]
                external = {k: lines.number(v, lineno)
                            for k, v in (e.split("=") for e in rest[9:])}
                program.points.append(ProgramPoint(
                    rest[0], lineno, key.lower(), tool, frame,
                    pose=pose_from_vendor(values, TOY_POSE),
                    config=Config(self.name, (int(rest[7]), int(rest[8]))), external=external,
                    where=lines.where(lineno)))
        return program, []

    def point_names(self, n: int) -> list[str]:
        return [f"P{i + 1}" for i in range(n)]

    def config_values(self, robot, q):
        return np.stack(kuka_status_turn(robot, q), axis=-1)

    def config_text(self, values: tuple[int, ...]) -> str:
        return f"{values[0]} {values[1]}"

    def external_axes(self, cell: Cell, pulses_per_degree=None) -> ExternalAxes:
        return numbered_axes(cell, self.name, ("T1", "T2", "T3"))

    def set_pose(self, lines, idx, T, config=None) -> bool:
        return False


@pytest.fixture
def toy():
    controller = register(Toy())
    yield controller
    unregister("toy")


def test_a_further_controller_registered_here_drives_export_program_write_and_check(
        toy, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    shutil.copy(EXAMPLE, "cell.yaml")
    code, _, err = run(capsys, "export", "--cell", "cell.yaml", "--format", "toy", "-o",
                       "toy.txt")
    assert code == 0, err
    cell = Cell.load("cell.yaml")
    got = parse_export(Path("toy.txt").read_text(encoding="utf-8"), "toy")
    assert [(s.name, s.number) for s in got.tools] == [("torch", 1), ("pointer", 2)]
    np.testing.assert_allclose(got.tools[0].pose, cell.tools["torch"].T_F_TCP, atol=1e-9)
    assert [(s.name, s.on_table) for s in got.frames] == [("fixture", False), ("part", True)]

    code, out, err = run(capsys, "program", "write", SEAM, "--cell", "cell.yaml", "--tool",
                         "torch", "--frame", "part", "--format", "toy", "-o", "prog")
    assert code == 0, err
    assert out.strip() == f"wrote {Path('prog') / 'seam_part.toy'}"
    text = Path("prog/seam_part.toy").read_text(encoding="utf-8")
    assert text.startswith("# robotcell program of path seam_part.csv") and "T1=" in text

    code, out, err = run(capsys, "program", "check", "prog/seam_part.toy", "--cell", "cell.yaml")
    assert code == 0, err
    assert re.fullmatch(r"prog/seam_part\.toy: \d+ points, all good", out.strip())
    # its limits hold as a built-in controller's do
    five = _cell_with(tmp_path, "  pointer:\n    number: 2", "  pointer:\n    number: 5",
                      "five.yaml")
    code, _, err = run(capsys, "export", "--cell", five, "--format", "toy")
    assert code == 2 and "its tools are TOOL[1..4]" in err


def test_the_further_controller_is_forgotten_when_unregistered(toy):
    assert names()[-1] == "toy" and CONTROLLERS["toy"] is toy
    unregister("toy")
    assert "toy" not in names()
    with pytest.raises(InputError, match=r"unknown export format 'toy'; choose one of: kuka, "
                                         r"abb, fanuc, yaskawa, ur, urdf"):
        export_cell(Cell.load(EXAMPLE), "toy")
    register(toy)  # for the fixture's teardown


def test_the_registry_holds_the_five_controllers_and_refuses_unknown_names():
    assert names() == ("kuka", "abb", "fanuc", "yaskawa", "ur")
    assert get("KUKA") is CONTROLLERS["kuka"]
    with pytest.raises(InputError, match=r"unknown controller 'staubli'; choose one of: kuka, "
                                         r"abb, fanuc, yaskawa, ur"):
        get("staubli")


def test_a_controller_is_registered_once_with_its_own_name_and_file_endings(toy):
    with pytest.raises(ValueError, match="a controller named 'toy' is registered already"):
        register(Toy())

    class Clash(Toy):
        name = "clash"
        program_suffixes = (".src",)

    with pytest.raises(ValueError, match="program file ending '.src' is read by kuka"):
        register(Clash())

    class Bad(Toy):
        name = "Bad Name"

    with pytest.raises(ValueError, match="controller name 'Bad Name'"):
        register(Bad())
    with pytest.raises(TypeError, match="is not a robotcell.controllers.base.Controller"):
        register("kuka")
    assert "clash" not in names()


def test_every_built_in_controller_names_its_sources_and_limits():
    for c in CONTROLLERS.values():
        assert c.sources and c.name_limit > 0 and c.program_suffixes, c
        assert (c.tool_slots is None) == (c.frame_slots is None), c


# -- numbers and names a controller holds ------------------------------------------------------------
def _cell_with(tmp_path: Path, old: str, new: str, name: str = "cell.yaml") -> Path:
    """The example cell with ``old`` replaced by ``new``, as ``tmp_path/name``."""
    text = EXAMPLE.read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


TOOL_99 = ("  torch:\n    number: 1", "  torch:\n    number: 99")


@pytest.mark.parametrize(("fmt", "slots"), [("kuka", r"TOOL_DATA\[1\.\.16\]"),
                                             ("fanuc", r"UTOOL\[1\.\.9\]"),
                                             ("yaskawa", r"TOOL\[0\.\.23\]")])
def test_a_tool_number_the_controller_does_not_have_is_refused_naming_the_range(
        fmt, slots, tmp_path, capsys):
    cell = _cell_with(tmp_path, *TOOL_99)
    out = tmp_path / "export.txt"
    code, _, err = run(capsys, "export", "--cell", cell, "--format", fmt, "-o", out)
    assert code == 2
    assert re.search(rf"error: tool 'torch' is number 99, which {fmt.upper()} does not have: "
                     rf"its tools are {slots}; give the tool a number from", err), err
    assert not out.exists()


def test_abb_numbers_no_tool_so_its_export_takes_any_number(tmp_path):
    text = export_cell(Cell.load(_cell_with(tmp_path, *TOOL_99)), "abb")
    assert "PERS tooldata torch:=" in text


def test_a_frame_number_the_controller_does_not_have_is_refused(tmp_path):
    cell = Cell.load(_cell_with(tmp_path, "  fixture:\n    number: 1", "  fixture:\n    number: 33"))
    with pytest.raises(InputError, match=r"frame 'fixture' is number 33, which KUKA does not "
                                         r"have: its frames are BASE_DATA\[1\.\.32\]"):
        export_cell(cell, "kuka")
    with pytest.raises(InputError, match=r"its frames are UFRAME\[1\.\.9\]"):
        export_cell(cell, "fanuc")


def test_the_turntable_root_a_pendant_listing_adds_as_a_frame_is_checked_too(tmp_path):
    # frames 1 and 9: FANUC writes the turntable's root as the next free number, 2; with 1..9
    # taken it would be 10
    cell = Cell.load(_cell_with(tmp_path, "  part:\n    number: 2", "  part:\n    number: 9"))
    assert "UFRAME[2]" in export_cell(cell, "fanuc")
    frames = "".join(f"  f{k}:\n    number: {k}\n    parent: world\n    frame: {{x: {k}, y: 0, "
                     "z: 0, a: 0, b: 0, c: 0}\n" for k in range(2, 9))
    path = tmp_path / "full.yaml"
    path.write_text(_cell_with(tmp_path, "  part:\n    number: 2", "  part:\n    number: 9")
                    .read_text(encoding="utf-8") + frames, encoding="utf-8")
    with pytest.raises(InputError, match=r"frame 'DKP_400_01' is number 10, which FANUC does "
                                         r"not have: its frames are UFRAME\[1\.\.9\]"):
        export_cell(Cell.load(path), "fanuc")


def test_program_write_refuses_a_tool_number_the_controller_does_not_have(tmp_path, capsys):
    cell = _cell_with(tmp_path, *TOOL_99)
    code, _, err = run(capsys, "program", "write", SEAM, "--cell", cell, "--tool", "torch",
                       "--frame", "part", "--format", "kuka", "-o", tmp_path / "prog")
    assert code == 2 and "its tools are TOOL_DATA[1..16]" in err
    assert not (tmp_path / "prog").exists()


# -- two programs, one controller name ---------------------------------------------------------------
def _yaskawa(capsys, path: Path, folder: Path, *extra: str) -> tuple[int, str, str]:
    return run(capsys, "program", "write", path, "--cell", EXAMPLE, "--tool", "torch", "--frame",
               "part", "--format", "yaskawa", "--pulses-per-degree", "100", "-o", folder, *extra)


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir()}


def test_two_yaskawa_programs_whose_names_collide_are_refused(tmp_path, capsys):
    a, b = tmp_path / "seam_part_a.csv", tmp_path / "seam_part_b.csv"
    shutil.copy(SEAM, a)
    shutil.copy(SEAM, b)
    folder = tmp_path / "prog"
    code, out, err = _yaskawa(capsys, a, folder)
    assert code == 0, err
    assert out.strip() == f"wrote {folder / 'SEAM_PAR.jbi'}"
    before = _snapshot(folder)
    code, out, err = _yaskawa(capsys, b, folder)
    assert code == 2 and out == ""
    assert (f"error: cannot write {folder / 'SEAM_PAR.jbi'}: it is a program written from "
            "seam_part_a.csv, and this program of seam_part_b.csv would replace it (YASKAWA "
            "program names hold 8 characters, so seam_part_b.csv is written as SEAM_PAR); give "
            "this program another name or folder") in err
    assert _snapshot(folder) == before
    code, out, err = _yaskawa(capsys, b, folder, "--name", "SEAM_B")
    assert code == 0, err
    assert sorted(_snapshot(folder)) == ["SEAM_B.jbi", "SEAM_PAR.jbi"]


def test_a_program_of_the_same_path_is_written_again_and_said_so(tmp_path, capsys):
    folder = tmp_path / "prog"
    assert _yaskawa(capsys, SEAM, folder)[0] == 0
    (folder / "SEAM_PAR.jbi").write_text((folder / "SEAM_PAR.jbi").read_text() + "' edited\n")
    code, _, err = _yaskawa(capsys, SEAM, folder)
    assert code == 0
    assert f"note: replaced {folder / 'SEAM_PAR.jbi'}, an earlier program of the same path" in err
    assert "edited" not in (folder / "SEAM_PAR.jbi").read_text()


@pytest.mark.parametrize("fmt", ["kuka", "abb", "fanuc"])
def test_every_format_knows_a_program_it_wrote_from_the_same_path(fmt, tmp_path, capsys):
    args = ["program", "write", SEAM, "--cell", EXAMPLE, "--tool", "torch", "--frame", "part",
            "--format", fmt, "-o", tmp_path]
    assert run(capsys, *args)[0] == 0
    code, _, err = run(capsys, *args)
    assert code == 0 and err.count("note: replaced") == (2 if fmt == "kuka" else 1), err


def test_a_file_of_the_programs_name_robotcell_did_not_write_is_not_replaced(tmp_path, capsys):
    taught = "/JOB\n//NAME SEAM_PAR\n//POS\n///NPOS 0,0,0,0,0,0\n//INST\nNOP\nEND\n"
    (tmp_path / "SEAM_PAR.jbi").write_text(taught)
    code, _, err = _yaskawa(capsys, SEAM, tmp_path)
    assert code == 2
    assert "it is a file robotcell did not write from seam_part.csv" in err
    assert (tmp_path / "SEAM_PAR.jbi").read_text() == taught


def test_a_program_name_in_other_capitals_in_the_folder_is_refused(tmp_path, capsys):
    (tmp_path / "SEAM_PART.SRC").write_text("DEF SEAM_PART()\nEND\n")
    code, _, err = run(capsys, "program", "write", SEAM, "--cell", EXAMPLE, "--tool", "torch",
                       "--frame", "part", "--format", "kuka", "-o", tmp_path)
    assert code == 2
    assert f"{tmp_path / 'SEAM_PART.SRC'} is there, and a controller takes the two names" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["SEAM_PART.SRC"]


# -- outputs and messages ---------------------------------------------------------------------------
@pytest.mark.parametrize(("fmt", "name", "says", "ending"), [
    ("kuka", "x.src", "a KUKA program", ".dat"), ("kuka", "x.mod", "an ABB program", ".dat"),
    ("fanuc", "x.ls", "a FANUC program", ".txt"), ("abb", "x.jbi", "a YASKAWA program", ".mod"),
    ("yaskawa", "x.dat", "a KUKA program", ".txt")])
def test_an_export_named_as_a_program_is_refused(fmt, name, says, ending, tmp_path, capsys):
    code, _, err = run(capsys, "export", "--cell", EXAMPLE, "--format", fmt, "-o",
                       tmp_path / name)
    assert code == 2
    assert (f"the name says {says}, but this writes the {fmt} export as text; name it "
            f"x{ending}") in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("fmt", "name"), [("kuka", "kuka_config.dat"), ("abb", "cell.mod"),
                                           ("fanuc", "frames.txt"), ("kuka", "frames")])
def test_an_export_named_as_what_it_is_is_written(fmt, name, tmp_path, capsys):
    code, _, err = run(capsys, "export", "--cell", EXAMPLE, "--format", fmt, "-o",
                       tmp_path / name)
    assert code == 0, err
    assert (tmp_path / name).is_file()


def test_a_src_without_its_dat_names_the_dat_to_copy_for_every_motion(tmp_path, capsys):
    # a KRL program may have no .dat (its points global ones of other modules): not refused
    run(capsys, "program", "write", SEAM, "--cell", EXAMPLE, "--tool", "torch", "--frame",
        "part", "--format", "kuka", "-o", tmp_path)
    (tmp_path / "seam_part.dat").unlink()
    code, out, err = run(capsys, "program", "check", tmp_path / "seam_part.src", "--cell", EXAMPLE)
    assert code == 0 and "no point checked" in out
    assert re.search(r"note: not checked: line \d+: PTP XP1 \(XP1 is declared neither in the "
                     r"\.src nor in a \.dat beside it: there is no seam_part\.dat, copy the "
                     r"program's \.dat beside the \.src", err), err
