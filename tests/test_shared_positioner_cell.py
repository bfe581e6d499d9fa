"""``calibrate shared-positioner --update-cell``: the fit of both robots' touches written into the
two-robot demo's cell (the positioner's axes and root, the other robot's base), what its
provenance records, what ``calibrate cell`` does with it, and every refusal writing nothing."""

from __future__ import annotations

import re
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from scipy.spatial.transform import Rotation
from shared_positioner_helpers import demo_folder, shared_args

from robotcell.cell import Cell
from robotcell.cell.calibrate import calibrate_cell
from robotcell.cell.calibrate.common import sha256_of
from robotcell.cell.calibrate.robottorobot import RobotTouchFile
from robotcell.cell.calibrate.sharedpositioner import (
    SOURCE,
    place_shared_positioner,
    shared_positioner,
)
from robotcell.errors import InputError
from robotcell.identification.sharedpositioner import PositionerLines, chain_lines
from robotcell.kinematics.transforms import invert

TRACK_REF = 1.0  # the KUKA's track position during its touches in the demo (m)


@pytest.fixture(scope="module")
def demo(tmp_path_factory) -> Path:
    """The two-robot demo's folder: the calibrated cell, the true cell and every touch file."""
    return demo_folder(tmp_path_factory.mktemp("demo2"))


@pytest.fixture()
def cell_dir(demo, tmp_path) -> Path:
    """A fresh copy of the demo's folder (the cell records its touch files beside it)."""
    out = tmp_path / "cell"
    shutil.copytree(demo, out)
    return out


def _touches(d: Path) -> tuple[tuple[RobotTouchFile, RobotTouchFile], tuple[str, str]]:
    return ((RobotTouchFile("kuka", str(d / "robot_to_robot_kuka.csv"), "torch", TRACK_REF),
             RobotTouchFile("abb", str(d / "robot_to_robot_abb.csv"), "torch")),
            (str(d / "positioner_kuka.csv"), str(d / "positioner_abb.csv")))


def _tool_off(d: Path, mm: float) -> str:
    """A copy of the calibrated cell with the ABB's torch ``mm`` off along the flange's X."""
    text = (d / "cell.yaml").read_text(encoding="utf-8")
    start = text.index("frame: {x: ", text.index("torch:", text.index("  abb:")))
    x = re.match(r"frame: \{x: ([-\d.]+)", text[start:])
    assert x is not None
    text = text[:start] + f"frame: {{x: {float(x.group(1)) + mm}" + text[start + x.end():]
    (d / "tool_off.yaml").write_text(text, encoding="utf-8")
    return "tool_off.yaml"


def _in_kuka(cell: Cell, T_world: np.ndarray) -> np.ndarray:
    """A pose of the world in the KUKA's base at its track position of the touches."""
    return invert(cell.for_robot("kuka").frame_pose("robot", track=TRACK_REF)) @ T_world


def _within(T: np.ndarray, T_true: np.ndarray, sigma_p: np.ndarray, sigma_r: np.ndarray,
            what: str) -> None:
    dp = T[:3, 3] - T_true[:3, 3]
    dr = Rotation.from_matrix(T[:3, :3] @ T_true[:3, :3].T).as_rotvec()
    assert np.all(np.abs(dp) <= 4 * sigma_p), (what, dp, sigma_p)
    assert np.all(np.abs(dr) <= 4 * sigma_r), (what, dr, sigma_r)


def test_update_cell_writes_the_positioner_and_the_base_within_4_sigma_of_the_truth(
        cell_dir, capsys):
    common, plate = _touches(cell_dir)
    fit = shared_positioner(Cell.load(cell_dir / "cell.yaml"), common, plate, sigma=1e-4,
                            tool_sigma=1.3e-4).joint
    code, out, err = run(capsys, *shared_args(cell_dir), "--update-cell")
    assert code == 0, err
    assert "calibrations of the positioner agree" in out
    assert re.search(r"updated .*cell\.yaml: positioner 'DKP_2' \(root, axes\) and the base of "
                     r"robot 'abb' from the fit of all touches \(previous version: ", err), err
    assert re.search(r"positioner 'DKP_2' root \(T_world_0\), X,Y,Z mm / A,B,C deg: .*; 1-sigma "
                     r"relative to the base of robot 'kuka': [\d.]+, [\d.]+, [\d.]+ / ", err), err
    assert "base of robot 'abb' (T_world_R), X,Y,Z mm / A,B,C deg: " in err
    cell, truth = Cell.load(cell_dir / "cell.yaml"), Cell.load(cell_dir / "truth.yaml")
    assert cell.turntable.provenance.source == SOURCE == "shared-positioner"
    assert cell.robots["abb"].base_provenance.source == SOURCE
    s = fit.sigma
    # the positioner's axis lines in the KUKA's base, against the true ones in its true base
    got = chain_lines(cell.turntable.chain.with_base(_in_kuka(cell, cell.turntable.chain.base)),
                      like=PositionerLines(fit.values["T_ref_B"], 0.0, 0.0))
    true = chain_lines(truth.turntable.chain.with_base(
        _in_kuka(truth, truth.turntable.chain.base)), like=got)
    _within(got.T_B, true.T_B, s["T_ref_B_position"], s["T_ref_B_rotation"], "root")
    assert abs(got.offset - true.offset) <= 4 * s["axis_offset"]
    assert abs(got.angle - true.angle) <= 4 * s["axis_angle"]
    # the fitted lines are the joint fit's, written through the KUKA's base
    assert np.allclose(got.T_B, fit.values["T_ref_B"], atol=1e-9)
    assert got.offset == pytest.approx(fit.values["axis_offset"], abs=1e-9)
    assert got.angle == pytest.approx(fit.values["axis_angle"], abs=1e-9)
    # the ABB's base in the KUKA's base
    _within(_in_kuka(cell, cell.robots["abb"].T_world_R),
            _in_kuka(truth, truth.robots["abb"].T_world_R), s["T_ref_other_position"],
            s["T_ref_other_rotation"], "base")


def test_the_provenance_records_the_files_checksums_options_and_sigma_parts(cell_dir, capsys):
    code, _, err = run(capsys, *shared_args(cell_dir), "--update-cell")
    assert code == 0, err
    cell = Cell.load(cell_dir / "cell.yaml")
    pos, base = cell.turntable.provenance, cell.robots["abb"].base_provenance
    files = {"reference_plate": "positioner_kuka.csv", "other_plate": "positioner_abb.csv",
             "reference_common": "robot_to_robot_kuka.csv",
             "other_common": "robot_to_robot_abb.csv"}
    for prov in (pos, base):
        assert Path(prov.measurements) == (cell_dir / "positioner_kuka.csv").resolve()
        assert prov.sha256 == sha256_of(cell_dir / "positioner_kuka.csv")
        o = prov.options
        assert (o["robot"], o["reference"], o["other"]) == ("kuka", "kuka", "abb")
        assert (o["tool_ref"], o["tool_other"]) == ("torch", "torch")
        assert (o["track_ref_mm"], o["track_other_mm"]) == (1000.0, 0.0)
        assert o["sigma_mm"] == pytest.approx(0.1) and o["tool_sigma_mm"] == pytest.approx(0.13)
        for key, name in files.items():
            assert o[f"{key}_file"] == name
            assert o[f"{key}_sha256"] == sha256_of(cell_dir / name)
        parts = o["sigma_parts"]
        assert set(parts) == {"T_ref_B", "axis_offset", "axis_angle", "T_ref_other"}
        assert set(parts["T_ref_B"]) >= {"own", "recorded"}
        assert parts["T_ref_B"]["relative_to"] == parts["T_ref_other"]["relative_to"] == "kuka"
        assert parts["T_ref_B"]["recorded"]["sources"] == ["kuka tool", "abb tool"]
        assert "touches from positioner_kuka.csv" in prov.note
    # one fit: the same own touch noise in both, so their correlation is kept
    assert pos.id == base.id and pos.id in pos.sources and pos.id in base.sources
    assert {"kuka tool", "abb tool"} <= set(base.sources)
    assert all(f.shape[0] == 14 for f in pos.sources.values())


def test_without_tool_sigma_the_tools_part_is_recorded_as_assumed(cell_dir, capsys):
    args = [str(a) for a in shared_args(cell_dir)]
    del args[args.index("--tool-sigma"):args.index("--tool-sigma") + 2]
    code, _, err = run(capsys, *args, "--update-cell")
    assert code == 0, err
    o = Cell.load(cell_dir / "cell.yaml").turntable.provenance.options
    assert "tool_sigma_mm" not in o and "assumed" in o["sigma_parts"]["T_ref_B"]


def test_calibrate_cell_repeats_the_fit_and_a_second_run_is_stable(cell_dir, capsys):
    code, _, err = run(capsys, *shared_args(cell_dir), "--update-cell")
    assert code == 0, err
    written = Cell.load(cell_dir / "cell.yaml")
    cells = []
    for _ in range(2):
        code, out, err = run(capsys, "calibrate", "cell", "--cell", cell_dir / "cell.yaml")
        assert code == 0, err
        assert re.search(r"abb: base: RMS [\d.]+ mm over 44 touches, verdict: GOOD", out), out
        assert "kept as written" not in out + err
        cells.append(Cell.load(cell_dir / "cell.yaml"))
    first, second = cells
    truth = Cell.load(cell_dir / "truth.yaml")
    for c in cells:
        assert c.turntable.provenance.source == c.robots["abb"].base_provenance.source == SOURCE
        o, o0 = c.turntable.provenance.options, written.turntable.provenance.options
        assert {k: v for k, v in o.items() if k != "sigma_parts"} == {
            k: v for k, v in o0.items() if k != "sigma_parts"}
    # repeated at the fitted tools: moved by a fraction of its 1-sigma, still near the truth
    moved = first.turntable.chain.base[:3, 3] - written.turntable.chain.base[:3, 3]
    assert 0 < np.linalg.norm(moved) < 1e-4
    sigma_p = np.full(3, 0.2e-3)  # the fit's 1-sigma of the base is about 0.1-0.2 mm per axis
    assert np.all(np.abs(_in_kuka(first, first.robots["abb"].T_world_R)[:3, 3] - _in_kuka(
        truth, truth.robots["abb"].T_world_R)[:3, 3]) <= 4 * sigma_p)
    # the second run repeats the first
    assert np.allclose(first.turntable.chain.base, second.turntable.chain.base, atol=1e-9)
    for j1, j2 in zip(first.turntable.chain.joints, second.turntable.chain.joints, strict=True):
        assert np.allclose([j1.a, j1.alpha, j1.d, j1.theta], [j2.a, j2.alpha, j2.d, j2.theta],
                           atol=1e-9)
    assert np.allclose(first.robots["abb"].T_world_R, second.robots["abb"].T_world_R, atol=1e-9)
    for robot in ("kuka", "abb"):
        assert np.allclose(first.robots[robot].tools["torch"].T_F_TCP,
                           second.robots[robot].tools["torch"].T_F_TCP, atol=1e-8), robot


def test_calibrate_cell_refuses_a_changed_touch_file_of_the_fit(cell_dir, capsys):
    code, _, err = run(capsys, *shared_args(cell_dir), "--update-cell")
    assert code == 0, err
    with (cell_dir / "positioner_abb.csv").open("a", encoding="utf-8") as f:
        f.write("\n")
    before = (cell_dir / "cell.yaml").read_bytes()
    code, _, err = run(capsys, "calibrate", "cell", "--cell", cell_dir / "cell.yaml")
    assert code == 2 and err.count("error:") == 1, err
    assert re.search(r"positioner \(shared-positioner\): touch file .*positioner_abb\.csv has "
                     r"changed since the calibration \(checksum differs\)", err), err
    assert (cell_dir / "cell.yaml").read_bytes() == before
    with pytest.raises(InputError, match=r"positioner_abb\.csv has changed since the calibration"):
        calibrate_cell(Cell.load(cell_dir / "cell.yaml"))


def test_a_repeated_fit_that_is_poor_is_not_written_and_a_note_says_so(cell_dir):
    cell = Cell.load(cell_dir / "cell.yaml")
    common, plate = _touches(cell_dir)
    done = shared_positioner(cell, common, plate, sigma=1e-4, tool_sigma=1.3e-4)
    new = place_shared_positioner(cell, done, common, plate, tool_sigma=1.3e-4)
    prov = new.turntable.provenance  # a touch accuracy stated 10 times too small
    new.turntable = replace(new.turntable, provenance=replace(
        prov, options={**prov.options, "sigma_mm": 0.01}))
    notes: list[str] = []
    out = calibrate_cell(new, on_note=notes.append)
    assert any(n.startswith("note: the fit of all touches of the shared positioner, repeated, "
                            "is not written (poor verdict: ") and n.endswith(
        "the positioner and the base of robot 'abb' are kept as written") for n in notes), notes
    assert out.cell.turntable.chain is new.turntable.chain
    assert np.array_equal(out.cell.robots["abb"].T_world_R, new.robots["abb"].T_world_R)


def test_a_base_placed_again_since_keeps_the_positioner_with_a_note(cell_dir, capsys):
    code, _, err = run(capsys, *shared_args(cell_dir), "--update-cell")
    assert code == 0, err
    written = Cell.load(cell_dir / "cell.yaml")
    code, _, err = run(capsys, "calibrate", "robot-to-robot", cell_dir / "robot_to_robot_kuka.csv",
                       cell_dir / "robot_to_robot_abb.csv", "--cell", cell_dir / "cell.yaml",
                       "--reference", "kuka", "--robot", "abb", "--tool-ref", "torch",
                       "--tool-other", "torch", "--track-ref", "1000", "--sigma", "0.1")
    assert code == 0, err
    code, out, err = run(capsys, "calibrate", "cell", "--cell", cell_dir / "cell.yaml")
    assert code == 0, err
    assert ("note: positioner 'DKP_2' comes from the fit of all touches of calibrate "
            "shared-positioner, not repeated (the positioner or the base was calibrated "
            "otherwise since): kept as written") in err
    cell = Cell.load(cell_dir / "cell.yaml")
    assert np.array_equal(cell.turntable.chain.base, written.turntable.chain.base)
    assert cell.robots["abb"].base_provenance.source == "robot-to-robot"
    assert re.search(r"abb: base: RMS [\d.]+ mm over 20 touches", out), out


def test_calibrate_cell_of_one_robot_keeps_the_fit_with_a_note(cell_dir, capsys):
    code, _, err = run(capsys, *shared_args(cell_dir), "--update-cell")
    assert code == 0, err
    written = Cell.load(cell_dir / "cell.yaml")
    code, _, err = run(capsys, "calibrate", "cell", "--cell", cell_dir / "cell.yaml",
                       "--robot-name", "kuka")
    assert code == 0, err
    assert ("note: positioner 'DKP_2' and the base of robot 'abb' come from the fit of all "
            "touches of calibrate shared-positioner, not repeated (refitting one robot only): "
            "kept as written") in err
    cell = Cell.load(cell_dir / "cell.yaml")
    assert np.array_equal(cell.turntable.chain.base, written.turntable.chain.base)
    assert np.array_equal(cell.robots["abb"].T_world_R, written.robots["abb"].T_world_R)


def test_without_update_cell_nothing_is_written(cell_dir, capsys):
    before = (cell_dir / "cell.yaml").read_bytes()
    code, _, err = run(capsys, *shared_args(cell_dir))
    assert code == 0, err
    assert (cell_dir / "cell.yaml").read_bytes() == before and "updated" not in err


def test_a_disagreement_writes_nothing_unless_accept_poor(cell_dir, capsys):
    cell = _tool_off(cell_dir, 2.0)
    before = (cell_dir / cell).read_bytes()
    code, _, err = run(capsys, *shared_args(cell_dir, cell), "--update-cell")
    assert code == 3
    assert err.strip().splitlines()[-1].startswith(
        "error: kuka's and abb's calibrations of the positioner disagree")
    assert (cell_dir / cell).read_bytes() == before
    assert not list(cell_dir.glob("tool_off.yaml.*.bak"))
    code, out, err = run(capsys, *shared_args(cell_dir, cell), "--update-cell", "--accept-poor")
    assert code == 0 and "disagree" in out and "updated" in err, err
    assert Cell.load(cell_dir / cell).turntable.provenance.source == SOURCE


@pytest.mark.parametrize(("change", "message"), [
    (("--robot", "fanuc"), "fanuc"),
    (("--tool-other", "welder"), "robot 'abb' has no tool 'welder'; its tools: pointer, torch"),
    (("--track-ref", "500"), ("column 'track' differs from the track position 500 mm of robot "
                             "'kuka'")),
    (("--robot", "kuka"), "the reference and the other robot are both 'kuka'"),
    (("--tool-sigma", "0"), "--tool-sigma must be a positive number"),
])
def test_bad_input_exits_2_with_one_error_line_and_writes_nothing(cell_dir, capsys, change,
                                                                  message):
    args = [str(a) for a in shared_args(cell_dir)]
    args[args.index(change[0]) + 1] = change[1]
    before = (cell_dir / "cell.yaml").read_bytes()
    code, _, err = run(capsys, *args, "--update-cell")
    assert code == 2, err
    assert err.count("error:") == 1 and message in err and "Traceback" not in err
    assert (cell_dir / "cell.yaml").read_bytes() == before


def test_output_onto_the_cell_file_is_refused(cell_dir, capsys):
    before = (cell_dir / "cell.yaml").read_bytes()
    code, _, err = run(capsys, *shared_args(cell_dir), "--update-cell", "-o", cell_dir / "cell.yaml")
    assert code == 2 and err.count("error:") == 1, err
    assert (cell_dir / "cell.yaml").read_bytes() == before


# -- the library -----------------------------------------------------------------------------
def test_place_shared_positioner_returns_a_new_cell_and_leaves_the_input(cell_dir):
    cell = Cell.load(cell_dir / "cell.yaml")
    chain, base = cell.turntable.chain, cell.robots["abb"].T_world_R.copy()
    common, plate = _touches(cell_dir)
    done = shared_positioner(cell, common, plate, sigma=1e-4, tool_sigma=1.3e-4)
    new = place_shared_positioner(cell, done, common, plate, tool_sigma=1.3e-4,
                                  time="2026-01-02T03:04:05+00:00")
    assert cell.turntable.chain is chain and np.array_equal(cell.robots["abb"].T_world_R, base)
    assert cell.turntable.provenance.source == "positioner"
    assert new.turntable.provenance.time == "2026-01-02T03:04:05+00:00"
    # the plate frame keeps its place on the plate: it moves with the axes, by well under 1 mm
    moved = new.turntable.chain.fk(np.zeros(2))[:3, 3] - chain.fk(np.zeros(2))[:3, 3]
    assert np.linalg.norm(moved) < 1e-3
    assert new.turntable.chain.lower.tolist() == chain.lower.tolist()


def test_place_shared_positioner_refuses_a_disagreement(cell_dir):
    cell = Cell.load(cell_dir / _tool_off(cell_dir, 2.0))
    common, plate = _touches(cell_dir)
    done = shared_positioner(cell, common, plate, sigma=1e-4, tool_sigma=1.3e-4)
    with pytest.raises(InputError, match=r"calibrations of the positioner disagree .*; nothing "
                                         r"written \(accept_poor=True writes the fit anyway\)"):
        place_shared_positioner(cell, done, common, plate)
    new = place_shared_positioner(cell, done, common, plate, accept_poor=True)
    assert new.turntable.provenance.source == SOURCE


def test_place_shared_positioner_refuses_a_touch_file_it_cannot_read(cell_dir):
    cell = Cell.load(cell_dir / "cell.yaml")
    common, plate = _touches(cell_dir)
    done = shared_positioner(cell, common, plate, sigma=1e-4)
    (cell_dir / "positioner_abb.csv").unlink()
    with pytest.raises(InputError, match=r"cannot read .*positioner_abb\.csv"):
        place_shared_positioner(cell, done, common, plate)


def test_shared_positioner_refuses_a_tool_the_cell_lacks(cell_dir):
    cell = Cell.load(cell_dir / "cell.yaml")
    (ref, oth), plate = _touches(cell_dir)
    with pytest.raises(InputError, match="robot 'abb' has no tool 'welder'; its tools: "):
        shared_positioner(cell, (ref, RobotTouchFile("abb", oth.path, "welder")), plate)


def test_a_second_robots_positioner_calibration_says_it_replaces_the_first(cell_dir, capsys):
    """The cell file holds one calibration of the shared positioner: the ABB's replaces the
    KUKA's, and the command says so and names the joint fit; the same robot again says
    nothing of it."""
    args = ["calibrate", "positioner", cell_dir / "positioner_abb.csv", "--cell",
            cell_dir / "cell.yaml", "--robot-name", "abb", "--tool", "torch", "--sigma", "0.1"]
    code, _, err = run(capsys, *args)
    assert code == 0, err
    assert ("note: positioner 'DKP_2' was calibrated by robot 'kuka' (positioner_kuka.csv); "
            "this calibration by robot 'abb' replaces it in the cell file; to compare the two "
            "within their 1-sigma and fit both robots' touches together, use 'robotcell "
            "calibrate shared-positioner'") in err
    assert Cell.load(cell_dir / "cell.yaml").turntable.provenance.options["robot"] == "abb"
    code, _, err = run(capsys, *args)
    assert code == 0 and "replaces it" not in err


def test_a_frame_in_the_world_another_robot_calibrated_is_named_when_replaced():
    from robotcell.cell import Provenance
    from robotcell.cell.calibrate.wholerobots import replaced_notes

    before = Cell.load("examples/cell_two_robots_positioner.yaml")
    by_kuka = replace(Provenance.now("frame"), measurements="frame_kuka.csv",
                      options={"robot": "kuka"})
    before.frames["table"] = replace(before.frames["table"], provenance=by_kuka)
    after = Cell.load("examples/cell_two_robots_positioner.yaml")
    after.frames["table"] = replace(before.frames["table"], provenance=replace(
        by_kuka, measurements="frame_abb.csv", options={"robot": "abb"}))
    assert replaced_notes(before, after, "abb") == [
        "note: frame 'table' was calibrated by robot 'kuka' (frame_kuka.csv); this calibration "
        "by robot 'abb' replaces it in the cell file"]
    assert replaced_notes(before, after, "kuka") == []
    assert replaced_notes(before, before, "abb") == []
