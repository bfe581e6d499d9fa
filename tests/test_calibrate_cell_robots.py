"""`calibrate cell` on a cell of several robots: the two-robot demo's calibrated cell refitted
from every touch file it recorded (both torches, the KUKA's track, the positioner the KUKA
touched, the ABB's base placed robot to robot), each item labelled by its robot."""

import json
import shutil

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.cell.calibrate import calibrate_cell
from robotcell.demo.tworobots import run_two_robot_demo
from robotcell.errors import InputError
from robotcell.kinematics.transforms import invert

ITEMS = ["kuka: tools.torch", "kuka: track", "abb: tools.torch", "abb: base"]
K = 4.0  # allowed error, in reported 1-sigma


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """The two-robot demo's folder: the calibrated cell, the truth and every touch file."""
    folder = tmp_path_factory.mktemp("demo2")
    run_two_robot_demo(folder, seed=3, echo=lambda line: None)
    return folder


@pytest.fixture
def cell_file(demo, tmp_path):
    folder = tmp_path / "d"
    shutil.copytree(demo, folder)
    return folder / "cell.yaml"


def refit(capsys, cell_file, *extra):
    code, out, err = run(capsys, "calibrate", "cell", "--cell", cell_file, "--json", *extra)
    assert code == 0, err
    return json.loads(out), err


def pose_errors(cell, truth):
    """Position error (m) of both torches, the KUKA's track (T_L_R0) and the ABB's base seen
    from the KUKA at the track positions of the robot-to-robot touches."""
    def base(c):
        return (invert(c.for_robot("kuka").frame_pose("robot", track=1.0))
                @ c.for_robot("abb").frame_pose("robot", track=0.0))

    poses = {f"{r}: tools.torch": lambda c, r=r: c.robots[r].tools["torch"].T_F_TCP
             for r in ("kuka", "abb")}
    poses["kuka: track"] = lambda c: c.robots["kuka"].track.T_L_R0
    poses["abb: base"] = base
    return {k: float(np.linalg.norm(f(cell)[:3, 3] - f(truth)[:3, 3])) for k, f in poses.items()}


def test_every_robots_items_are_refitted_within_their_sigma_of_the_truth(capsys, cell_file):
    data, err = refit(capsys, cell_file)
    assert [i["item"] for i in data["items"]] == ITEMS
    assert [i["robot"] for i in data["items"]] == ["kuka", "kuka", "abb", "abb"]
    assert [s["item"] for s in data["steps"]] == [
        "kuka: tools.torch", "kuka: track", "kuka: positioner", "abb: tools.torch", "abb: base"]
    assert data["verdict"]["level"] in ("good", "check")
    assert any("Not adjusted jointly" in n for n in data["notes"])
    assert "updated" in err and "4 item(s) fitted with the whole cell" in err
    cell, truth = Cell.load(cell_file), Cell.load(cell_file.with_name("truth.yaml"))
    sigma = {i["item"]: np.linalg.norm(i["sigma_mm_deg"][:3]) * 1e-3 for i in data["items"]}
    for key, error in pose_errors(cell, truth).items():
        assert error <= K * sigma[key], (key, error, sigma[key])
    relative = {i["item"]: i["sigma_relative_to"] for i in data["items"]}
    assert relative == {"kuka: tools.torch": "F", "kuka: track": "L", "abb: tools.torch": "F",
                        "abb: base": "kuka"}


def test_the_refitted_cell_reloads_with_each_provenance_kept(capsys, cell_file):
    refit(capsys, cell_file)
    cell = Cell.load(cell_file)
    for prov in (cell.robots["kuka"].tools["torch"].provenance,
                 cell.robots["abb"].tools["torch"].provenance,
                 cell.robots["kuka"].track.provenance, cell.robots["abb"].base_provenance):
        assert prov.note.endswith("; fitted with the whole cell")
        assert prov.note.count("fitted with the whole cell") == 1
        assert prov.measurements is not None and prov.sources
    assert cell.robots["abb"].base_provenance.options["reference"] == "kuka"
    assert cell.turntable.provenance.source == "positioner"
    assert cell.turntable.provenance.options["robot"] == "kuka"


def test_refitting_twice_is_stable_and_the_file_does_not_grow(capsys, cell_file):
    refit(capsys, cell_file)
    first = cell_file.read_text()
    data, _ = refit(capsys, cell_file)
    for item in data["items"]:
        assert max(abs(v) for v in item["change_sigmas"]) < 1e-3, item["item"]
    assert len(cell_file.read_text().splitlines()) == len(first.splitlines())
    a, b = Cell.load(cell_file), Cell.load(cell_file.with_name("cell.yaml.7.bak"))
    for r in ("kuka", "abb"):
        assert np.allclose(a.robots[r].tools["torch"].T_F_TCP, b.robots[r].tools["torch"].T_F_TCP,
                           atol=1e-8)
    assert np.allclose(a.robots["abb"].T_world_R, b.robots["abb"].T_world_R, atol=1e-8)


def test_robot_name_refits_that_robots_items_and_its_placement_only(capsys, cell_file):
    before = Cell.load(cell_file)
    data, _ = refit(capsys, cell_file, "--robot-name", "abb")
    assert [i["item"] for i in data["items"]] == ["abb: tools.torch", "abb: base"]
    after = Cell.load(cell_file)
    assert np.array_equal(after.robots["kuka"].tools["torch"].T_F_TCP,
                          before.robots["kuka"].tools["torch"].T_F_TCP)
    assert after.robots["kuka"].track.provenance.time == before.robots["kuka"].track.provenance.time
    assert after.robots["abb"].base_provenance.note.endswith("fitted with the whole cell")


def test_the_library_call_labels_each_item_by_its_robot(cell_file):
    out = calibrate_cell(Cell.load(cell_file), time="2026-01-01T00:00:00+00:00")
    assert out.items == tuple(ITEMS)
    assert [c.robot for c in out.changes] == ["kuka", "kuka", "abb", "abb"]
    assert out.covariance.shape == (6 + 7 + 6 + 6, 6 + 7 + 6 + 6)
    assert "of 2 robot(s) (kuka, abb), fitted robot by robot" in out.summary()
    with pytest.raises(InputError, match="no robot 'fanuc'; its robots: kuka, abb"):
        calibrate_cell(Cell.load(cell_file), robot="fanuc")


def unchanged(cell_file, text):
    assert cell_file.read_text() == text
    assert not cell_file.with_name("cell.yaml.6.bak").exists()


@pytest.mark.parametrize("name", ["tcp_abb.csv", "robot_to_robot_kuka.csv"])
def test_a_missing_touch_file_is_refused_and_nothing_written(capsys, cell_file, name):
    text = cell_file.read_text()
    cell_file.with_name(name).unlink()
    code, out, err = run(capsys, "calibrate", "cell", "--cell", cell_file)
    assert code == 2 and out == ""
    assert err.count("error:") == 1 and len(err.strip().splitlines()) == 1, err
    assert name in err and "is missing" in err
    unchanged(cell_file, text)


@pytest.mark.parametrize(("old", "new", "what"), [
    ("robot: kuka}", "robot: fanuc}", "turntable was calibrated by robot 'fanuc'"),
    ("reference: kuka,", "reference: fanuc,", "placed in the base of robot 'fanuc'")])
def test_a_robot_named_in_a_provenance_the_cell_lacks_is_refused(capsys, cell_file, old, new,
                                                                  what):
    text = cell_file.read_text()
    assert text.count(old) == 1
    cell_file.write_text(text.replace(old, new))
    text = cell_file.read_text()
    code, _, err = run(capsys, "calibrate", "cell", "--cell", cell_file)
    assert code == 2 and err.count("error:") == 1 and len(err.strip().splitlines()) == 1, err
    assert what in err and "which the cell lacks (its robots: kuka, abb)" in err
    unchanged(cell_file, text)


def test_an_unknown_robot_name_is_refused_listing_the_robots(capsys, cell_file):
    text = cell_file.read_text()
    code, _, err = run(capsys, "calibrate", "cell", "--cell", cell_file, "--robot-name", "r9")
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "no robot 'r9'; its robots: kuka, abb" in err
    unchanged(cell_file, text)


def test_a_shared_item_with_no_robot_recorded_is_taken_from_the_items_it_used(capsys, cell_file):
    """A positioner calibrated before its robot was recorded: the only robot with a track."""
    text = cell_file.read_text()
    cell_file.write_text(text.replace(", robot: kuka}", "}"))
    data, _ = refit(capsys, cell_file)
    assert "kuka: positioner" in [s["item"] for s in data["steps"]]
