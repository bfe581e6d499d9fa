"""calibrate robot-to-robot --cell: the robots and tools of a cell of several robots, the other
robot's base written into the cell (at track 0 for a robot on a track), refusals that write
nothing."""

import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.io.poseformats import pose_to_vendor
from robotcell.kinematics.transforms import invert

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cell_two_robots_positioner.yaml"
TOOLS = {"kuka": "312.5,-1.2,95,0,45,0", "abb": "300,0,90,0,45,0"}
MODELS = {"kuka": "kuka_kr16", "abb": "abb_irb2400"}


def _truth(cell: Cell, ref: str, other: str, track: dict[str, float]) -> np.ndarray:
    """T_Rref_Rother of the cell at the robots' track positions (m)."""
    return (invert(cell.for_robot(ref).frame_pose("robot", track=track.get(ref, 0.0)))
            @ cell.for_robot(other).frame_pose("robot", track=track.get(other, 0.0)))


def _touches(capsys, folder, cell, ref, other, track, seed):
    pose = ",".join(f"{v:.6f}" for v in pose_to_vendor(_truth(cell, ref, other, track), "kuka"))
    code, _, err = run(capsys, "simulate", "robot-to-robot", "--seed", seed, "--robot-ref",
                       MODELS[ref], "--robot-other", MODELS[other], "--pose", pose,
                       "--tool-ref", TOOLS[ref], "--tool-other", TOOLS[other], "--noise", "0.1",
                       "--ref-output", folder / "ref.csv", "--other-output", folder / "other.csv")
    assert code == 0, err
    return folder / "ref.csv", folder / "other.csv"


@pytest.mark.parametrize("ref, other, track", [
    ("kuka", "abb", {"kuka": 0.5}),     # the reference on its track at 500 mm
    ("abb", "kuka", {"kuka": 0.5}),     # the robot placed on its track at 500 mm
])
def test_the_base_written_into_the_cell_is_the_true_one_within_its_sigma(capsys, tmp_path, ref,
                                                                           other, track):
    cell_file = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, cell_file)
    truth = Cell.load(cell_file)
    # the cell starts with the other robot 5 mm and 0.5 deg off
    off = Cell.load(cell_file)
    T = truth.for_robot(other).frame_pose("robot", track=0.0)
    T[:3, 3] += [0.005, -0.003, 0.002]
    c, s = np.cos(np.radians(0.5)), np.sin(np.radians(0.5))
    T[:3, :3] = T[:3, :3] @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    off.set_robot_base(other, T, truth.robots[other].base_provenance or
                       truth.robots[ref].base_provenance or _nominal())
    off.save(cell_file)
    r_csv, o_csv = _touches(capsys, tmp_path, truth, ref, other, track, 11)
    code, out, err = run(capsys, "calibrate", "robot-to-robot", r_csv, o_csv, "--cell", cell_file,
                         "--robot", other, "--reference", ref, "--tool-ref", "torch",
                         "--tool-other", "torch", "--track-ref", track.get(ref, 0) * 1e3,
                         "--track-other", track.get(other, 0) * 1e3, "--sigma", "0.1",
                         "--tool-sigma", "0.2")
    assert code == 0, err
    assert f"updated {cell_file}: base of robot {other!r} from robot {ref!r}" in err
    placed = Cell.load(cell_file)
    got = placed.for_robot(other).frame_pose("robot", track=0.0)
    want = truth.for_robot(other).frame_pose("robot", track=0.0)
    assert np.linalg.norm(got[:3, 3] - want[:3, 3]) < 1e-3  # 5 mm off before
    angle = np.arccos(np.clip((np.trace(got[:3, :3].T @ want[:3, :3]) - 1) / 2, -1, 1))
    assert np.degrees(angle) < 0.05
    unit = placed.robots[other]
    provenance = unit.base_provenance if unit.track is None else unit.track.provenance
    assert provenance.source == "robot-to-robot" and provenance.inputs == (f"robots.{ref}",)
    assert provenance.sources  # the pose's 1-sigma recorded with it
    assert (tmp_path / "cell.yaml.1.bak").exists() or any(tmp_path.glob("cell.yaml.*.bak"))


def _nominal():
    from robotcell.cell import Provenance
    return Provenance("nominal")


@pytest.mark.parametrize("args, message", [
    (["--robot", "ur", "--reference", "kuka"], "the cell has no robot 'ur'; its robots: kuka, abb"),
    (["--robot", "abb", "--reference", "abb"], "both 'abb'; name two robots"),
    (["--robot", "abb", "--reference", "kuka", "--tool-other", "nope"],
     "robot 'abb' has no tool 'nope'; its tools: "),
    (["--robot", "abb"], "--cell needs --reference"),
    (["--robot", "abb", "--reference", "kuka", "--robot-ref", "kuka_kr16"],
     "--robot-ref and --cell both give a robot model"),
    (["--robot", "abb", "--reference", "kuka", "--track-other", "100"],
     "robot 'abb' has no track; its track position must be 0"),
])
def test_a_refused_run_names_the_cause_and_leaves_the_cell_as_it_was(capsys, tmp_path, args,
                                                                      message):
    cell_file = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, cell_file)
    before = cell_file.read_bytes()
    r_csv, o_csv = _touches(capsys, tmp_path, Cell.load(cell_file), "kuka", "abb", {}, 2)
    tools = [] if "--tool-other" in args else ["--tool-other", "torch"]
    code, out, err = run(capsys, "calibrate", "robot-to-robot", r_csv, o_csv, "--cell", cell_file,
                         "--tool-ref", "torch", *tools, *args)
    assert code == 2 and message in err and "Traceback" not in err, err
    assert cell_file.read_bytes() == before
    assert not list(tmp_path.glob("cell.yaml.*.bak"))


def test_output_onto_the_cell_is_refused(capsys, tmp_path):
    cell_file = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, cell_file)
    before = cell_file.read_bytes()
    r_csv, o_csv = _touches(capsys, tmp_path, Cell.load(cell_file), "kuka", "abb", {}, 3)
    code, _, err = run(capsys, "calibrate", "robot-to-robot", r_csv, o_csv, "--cell", cell_file,
                       "--robot", "abb", "--reference", "kuka", "--tool-ref", "torch",
                       "--tool-other", "torch", "-o", cell_file)
    assert code == 2 and "error:" in err
    assert cell_file.read_bytes() == before


def test_robot_names_without_a_cell_are_refused(capsys, tmp_path):
    r_csv, o_csv = _touches(capsys, tmp_path, Cell.load(EXAMPLE), "kuka", "abb", {}, 4)
    code, _, err = run(capsys, "calibrate", "robot-to-robot", r_csv, o_csv, "--reference", "kuka")
    assert code == 2 and "--reference names a robot of a cell; it needs --cell" in err


def test_the_report_of_a_robot_to_robot_result_shows_both_bases_and_the_1_sigma(capsys, tmp_path):
    r_csv, o_csv = _touches(capsys, tmp_path, Cell.load(EXAMPLE), "kuka", "abb", {}, 5)
    result = tmp_path / "r2r.json"
    code, _, err = run(capsys, "calibrate", "robot-to-robot", r_csv, o_csv, "--robot-ref",
                       "kuka_kr16", "--tool-ref", TOOLS["kuka"], "--robot-other", "abb_irb2400",
                       "--tool-other", TOOLS["abb"], "--sigma", "0.1", "--json", "-o", result)
    assert code == 0, err
    code, _, err = run(capsys, "report", result, "-o", tmp_path / "r2r.html")
    assert code == 0, err
    page = (tmp_path / "r2r.html").read_text()
    assert "position of the other robot&#x27;s base in the reference robot&#x27;s base" in page \
        or "position of the other robot's base in the reference robot's base" in page
    assert "<td>not available</td>" not in page and "Plotly.newPlot" in page
    assert "the other robot&#x27;s base" in page or "the other robot's base" in page
