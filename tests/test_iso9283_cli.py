"""``robotcell iso9283 analyse`` and ``robotcell simulate iso9283``: the JSON as documented,
bad logs refused naming the line with nothing written, and a calibrated cell that passes where
the nominal one fails."""

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.io.yamlfile import dump_yaml, parse_yaml
from robotcell.iso9283 import plan, simulate, write_log, write_plan

ROOT = Path(__file__).resolve().parent.parent
TRACK_CELL = ROOT / "examples" / "cell_kr16_track_turntable.yaml"

POSE_KEYS = {"pose", "cycles", "command_mm", "barycentre_mm", "AP_p_mm", "AP_x_mm", "AP_y_mm",
             "AP_z_mm", "l_mean_mm", "S_l_mm", "RP_l_mm", "AP_a_deg", "AP_b_deg", "AP_c_deg",
             "RP_a_deg", "RP_b_deg", "RP_c_deg", "drift"}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A plan of the example cell and a clean simulated log of it (10 cycles, both paths)."""
    d = tmp_path_factory.mktemp("iso")
    cell = Cell.load(TRACK_CELL)
    p = plan(cell, "torch", size=0.5)
    write_plan(p, d / "plan.csv")
    write_log(simulate(cell, p, cycles=10, path_cycles=10, spacing=0.005, seed=3),
              d / "meas.csv")
    return d


def test_analyse_prints_the_documented_json(made, capsys, tmp_path):
    code, out, err = run(capsys, "iso9283", "analyse", made / "meas.csv", "--plan",
                         made / "plan.csv", "--limit-ap", "0.5", "--limit-rp", "0.2", "--json",
                         "-o", tmp_path / "report.html")
    assert code == 0, err
    data = json.loads(out)
    assert [p["pose"] for p in data["poses"]] == ["P1", "P2", "P3", "P4", "P5"]
    for p in data["poses"]:
        assert set(p) == POSE_KEYS
        assert p["cycles"] == 10 and p["AP_p_mm"] < 0.05 and p["RP_l_mm"] < 0.2
        assert p["drift"] is None                    # 10 cycles: the drift needs 20
    assert [d["to"] for d in data["distances"]] == ["P2", "P3", "P4", "P5"]
    assert {d["from"] for d in data["distances"]} == {"P1"}
    assert [p["path"] for p in data["paths"]] == ["line", "circle"]
    for p in data["paths"]:
        assert set(p) == {"path", "cycles", "points", "AT_p_mm", "AT_at", "RT_p_mm", "RT_at",
                          "AT_a_deg", "AT_b_deg", "AT_c_deg"}
        assert p["AT_a_deg"] is not None and abs(p["AT_c_deg"]) < 0.01
        assert p["cycles"] == 10 and p["AT_p_mm"] < 0.05
    assert data["verdict"]["level"] == "pass" and len(data["verdict"]["reasons"]) == 2
    assert data["limits"] == {"AP_mm": 0.5, "RP_mm": 0.2, "AT_mm": None, "RT_mm": None}
    assert data["device_frame"] is None
    assert any("fewer than the 30 cycles" in n for n in data["notes"])
    page = (tmp_path / "report.html").read_text()
    assert "verdict: PASS" in page and page.count("data:image/png;base64,") == 2


def test_a_fail_exits_3_with_the_report_written(made, capsys, tmp_path):
    code, out, _ = run(capsys, "iso9283", "analyse", made / "meas.csv", "--plan",
                       made / "plan.csv", "--limit-rp", "0.001", "-o", tmp_path / "r.html")
    assert code == 3 and "verdict: FAIL: RP_l" in out
    assert "verdict: FAIL" in (tmp_path / "r.html").read_text()


def _rewrite(src: Path, dst: Path, edit) -> None:
    lines = src.read_text().splitlines()
    dst.write_text("\n".join(edit(lines)) + "\n")


def _field(line: str, column: int, value: str) -> str:
    cells = line.split(",")
    cells[column] = value
    return ",".join(cells)


BAD_LOGS = {
    # (edit of the lines, what the message says)
    "pose the plan lacks": (lambda ls: [*ls[:7], _field(ls[7], 1, "P6"), *ls[8:]],
                            "line 8: pose 'P6' is not in the plan"),
    "NaN": (lambda ls: [*ls[:4], _field(ls[4], 3, "nan"), *ls[5:]],
            "line 5: column 'y' is NaN"),
    "mixed units": (lambda ls: [*ls[:9], _field(ls[9], 2, str(float(ls[9].split(",")[2]) / 1e3)),
                                *ls[10:]],
                    "line 10: P2 lies 3448.8 mm from the median of its cycles.*mixed units"),
    "too few cycles": (lambda ls: [ls[0], *(l for l in ls[1:] if l.split(",")[0] in "1234")],
                       "P1 has 4 cycles \\(its last on line 21\\): the figures need at least 10"),
    "a cycle that is not whole": (lambda ls: [*ls[:2], _field(ls[2], 0, "1.5"), *ls[3:]],
                                  "line 3: cycle 1.5 is not a whole number"),
    "a pose twice in a cycle": (lambda ls: [*ls[:3], ls[2], *ls[4:]],
                                "line 4: P4 of cycle 1 again"),
}


@pytest.mark.parametrize("case", list(BAD_LOGS))
def test_a_bad_log_exits_2_naming_the_line_and_writes_nothing(made, capsys, tmp_path, case):
    edit, message = BAD_LOGS[case]
    _rewrite(made / "meas.csv", tmp_path / "bad.csv", edit)
    out_file = tmp_path / "report.html"
    code, out, err = run(capsys, "iso9283", "analyse", tmp_path / "bad.csv", "--plan",
                         made / "plan.csv", "--json", "-o", out_file)
    assert code == 2, err
    assert err.startswith("error: ") and "Traceback" not in err
    assert re.search(message, err), err
    assert out == "" and not out_file.exists()


def test_a_log_in_the_trackers_frame_needs_the_device_frame(made, capsys, tmp_path):
    T = np.array([[0.0, -1.0, 0.0, 1500.0], [1.0, 0.0, 0.0, -200.0], [0.0, 0.0, 1.0, 30.0]])

    def move(lines):
        out = [lines[0]]
        for line in lines[1:]:
            c = line.split(",")
            p = T[:, :3] @ np.array([float(v) for v in c[2:5]]) + T[:, 3]
            out.append(",".join([*c[:2], *(f"{v:.4f}" for v in p), *c[5:]]))
        return out

    header = (made / "meas.csv").read_text().splitlines()[0].split(",")
    assert header[:5] == ["cycle", "pose", "x", "y", "z"]
    _rewrite(made / "meas.csv", tmp_path / "device.csv",
             lambda ls: [",".join(c for c in l.split(",")[:5] + l.split(",")[8:]) for l in move(ls)])
    code, _, err = run(capsys, "iso9283", "analyse", tmp_path / "device.csv", "--plan",
                       made / "plan.csv")
    assert code == 2 and "from its command" in err and "--device-frame" in err
    code, out, err = run(capsys, "iso9283", "analyse", tmp_path / "device.csv", "--plan",
                         made / "plan.csv", "--device-frame", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["device_frame"]["rms_mm"] < 0.05
    assert data["device_frame"]["a_deg"] == pytest.approx(-90.0, abs=0.01)
    assert all(p["AP_a_deg"] is None for p in data["poses"])


def test_simulate_iso9283_writes_the_log_analyse_reads(made, capsys, tmp_path):
    shutil.copy(TRACK_CELL, tmp_path / "truth.yaml")
    code, out, err = run(capsys, "simulate", "iso9283", "--cell", tmp_path / "truth.yaml",
                         "--plan", made / "plan.csv", "--cycles", "10", "--path-cycles", "0",
                         "--no-orientation", "--seed", "2", "-o", tmp_path / "meas.csv")
    assert code == 0, err
    header = (tmp_path / "meas.csv").read_text().splitlines()[0]
    assert header == "cycle,pose,x,y,z,time"
    assert len((tmp_path / "meas.csv").read_text().splitlines()) == 1 + 10 * 5
    code, _, err = run(capsys, "simulate", "iso9283", "--cell", tmp_path / "truth.yaml",
                       "--plan", made / "plan.csv", "--noise", "50", "-o", tmp_path / "x.csv")
    assert code == 2 and "--noise must be from 0 to 10 mm" in err
    assert not (tmp_path / "x.csv").exists()
    code, out, _ = run(capsys, "simulate", "--help")
    assert code == 0 and "simulate iso9283 --help" in out
    code, out, _ = run(capsys, "simulate", "iso9283", "--help")
    assert code == 0 and "--controller" in out and "Example" in out


def _truth_with_tool_error(path: Path) -> None:
    """The example cell whose torch's TCP is 1.2 mm off its nominal values."""
    data = parse_yaml(TRACK_CELL.read_text(encoding="utf-8"), str(TRACK_CELL))
    frame = data["tools"]["torch"]["frame"]
    frame["x"], frame["y"], frame["z"] = frame["x"] + 0.8, frame["y"] - 0.6, frame["z"] + 0.7
    path.write_text(dump_yaml(data), encoding="utf-8")


def test_a_cell_calibrated_by_robotcell_passes_where_the_nominal_one_fails(capsys, tmp_path,
                                                                          monkeypatch):
    monkeypatch.chdir(tmp_path)
    _truth_with_tool_error(Path("truth.yaml"))
    shutil.copy(TRACK_CELL, "nominal.yaml")
    shutil.copy(TRACK_CELL, "calibrated.yaml")
    steps = [
        ["iso9283", "plan", "--cell", "nominal.yaml", "--tool", "torch", "--size", "500",
         "-o", "plan.csv"],
        ["simulate", "tcp", "--cell", "truth.yaml", "--tool", "torch", "--touches", "6",
         "--noise", "0.05", "--seed", "1", "-o", "tcp.csv"],
        ["calibrate", "tcp", "tcp.csv", "--cell", "calibrated.yaml", "--name", "torch"],
    ]
    for argv in steps:
        code, _, err = run(capsys, *argv)
        assert code == 0, (argv, err)
    verdicts = {}
    for controller in ("nominal", "calibrated"):
        code, _, err = run(capsys, "simulate", "iso9283", "--cell", "truth.yaml", "--plan",
                           "plan.csv", "--controller", f"{controller}.yaml", "--path-cycles", "0",
                           "--seed", "4", "-o", f"{controller}.csv")
        assert code == 0, err
        code, out, err = run(capsys, "iso9283", "analyse", f"{controller}.csv", "--plan",
                             "plan.csv", "--limit-ap", "0.5", "--limit-rp", "0.1", "--json")
        verdicts[controller] = (code, json.loads(out))
    code, data = verdicts["nominal"]
    assert code == 3 and data["verdict"]["level"] == "fail"
    assert min(p["AP_p_mm"] for p in data["poses"]) > 1.0      # the 1.2 mm of the tool
    code, data = verdicts["calibrated"]
    assert code == 0 and data["verdict"]["level"] == "pass"
    assert max(p["AP_p_mm"] for p in data["poses"]) < 0.5


def test_an_identified_arm_compensates_the_real_arm_that_the_nominal_misses():
    from accuracy_helpers import kr16_truth

    from robotcell.cell.parts import Provenance
    from robotcell.iso9283 import Limits, analyse

    nominal = Cell.load(TRACK_CELL)
    truth = Cell.load(TRACK_CELL)
    truth.set_identified(kr16_truth(np.random.default_rng(2)), "truth.yaml",
                         Provenance("manual"))
    p = plan(nominal, "torch", size=0.5)
    limits = Limits(AP=0.1e-3)
    missed = analyse(simulate(truth, p, nominal, path_cycles=0, cycles=10, seed=1), p,
                     limits=limits)
    # the controller's cell knows the real arm (a perfect identification): it compensates
    kept = analyse(simulate(truth, p, truth, path_cycles=0, cycles=10, seed=1), p,
                   limits=limits)
    assert missed.verdict.level == "fail"
    assert max(r.figures.AP_p for r in missed.poses) > 0.3e-3
    assert kept.verdict.level == "pass"
    assert max(r.figures.AP_p for r in kept.poses) < 0.03e-3


def _model_with_repeatability(folder: Path, block: str) -> Path:
    """The library's KR 16 model file with ``block`` appended, in ``folder``."""
    text = (ROOT / "src" / "robotcell" / "robots" / "kuka_kr16.yaml").read_text(encoding="utf-8")
    path = folder / "kr16_sheet.yaml"
    path.write_text(text + block, encoding="utf-8")
    return path


SHEET = "repeatability: {mm: 0.04, source: 'Datasheet KR 16, example.com/kr16.pdf'}\n"


def test_the_datasheet_repeatability_is_the_default_limit_of_rp(made, capsys, tmp_path):
    model = _model_with_repeatability(tmp_path, SHEET)
    cell = tmp_path / "cell.yaml"
    cell.write_text(TRACK_CELL.read_text(encoding="utf-8").replace(
        "  model: kuka_kr16", f"  model: {model.name}"), encoding="utf-8")
    code, out, err = run(capsys, "iso9283", "analyse", made / "meas.csv", "--plan",
                         made / "plan.csv", "--cell", cell, "--json")
    data = json.loads(out)
    assert data["limits"]["RP_mm"] == pytest.approx(0.04)
    assert any("limit of RP_l 0.04 mm: the pose repeatability of the KUKA KR 16-2 datasheet "
               "(Datasheet KR 16, example.com/kr16.pdf)" in n for n in data["notes"])
    assert code == (3 if data["verdict"]["level"] == "fail" else 0)
    # a limit given wins; without --cell there is no default
    code, out, _ = run(capsys, "iso9283", "analyse", made / "meas.csv", "--plan",
                       made / "plan.csv", "--cell", cell, "--limit-rp", "0.5", "--json")
    data = json.loads(out)
    assert code == 0 and data["limits"]["RP_mm"] == 0.5
    assert not any("datasheet" in n for n in data["notes"])
    code, out, _ = run(capsys, "iso9283", "analyse", made / "meas.csv", "--plan",
                       made / "plan.csv", "--json")
    assert code == 0 and json.loads(out)["limits"]["RP_mm"] is None


@pytest.mark.parametrize("block, message", [
    ("repeatability: 0.04\n", "key 'repeatability' must be a mapping"),
    ("repeatability: {mm: 0.04}\n", "key 'repeatability': missing key 'source'"),
    ("repeatability: {mm: -1, source: x}\n", "key 'mm' must be a repeatability from 0 to 10 mm"),
    ("repeatability: {mm: 0.04, source: ''}\n", "key 'source' must name the datasheet"),
    ("repeatability: {mm: 0.04, source: x, accuracy: 1}\n", "unknown key\\(s\\) \\['accuracy'\\]"),
])
def test_a_repeatability_without_its_datasheet_is_refused(tmp_path, block, message):
    from robotcell.errors import InputError
    from robotcell.robot.models import load_robot

    with pytest.raises(InputError, match=message):
        load_robot(_model_with_repeatability(tmp_path, block))


def test_the_datasheet_repeatability_survives_a_model_file_round_trip(tmp_path):
    from robotcell.robot.models import load_robot, save_robot

    robot = load_robot(_model_with_repeatability(tmp_path, SHEET))
    assert robot.repeatability == pytest.approx(4e-5)
    save_robot(robot, tmp_path / "again.yaml")
    again = load_robot(tmp_path / "again.yaml")
    assert again.repeatability == robot.repeatability
    assert again.repeatability_source == "Datasheet KR 16, example.com/kr16.pdf"


@pytest.mark.parametrize("name, mm, page", [
    ("ur3e", 0.03, "complianceUR3e"), ("ur5e", 0.03, "complianceUR5e"),
    ("ur10e", 0.05, "complianceUR10e")])
def test_the_library_ur_arms_carry_their_manual_repeatability(name, mm, page):
    """The UR e-Series manuals' technical specifications state the pose repeatability per ISO
    9283; the library's models carry it with the page that states it (docs/models.md)."""
    from robotcell.robot.models import load_robot

    robot = load_robot(name)
    assert robot.repeatability == pytest.approx(mm * 1e-3)
    assert f"+-{mm:.2f} mm" in robot.repeatability_source
    assert page in robot.repeatability_source and "ISO 9283" in robot.repeatability_source


def test_a_ur5e_cell_takes_its_manual_repeatability_as_the_limit_of_rp(tmp_path):
    """`analyse(..., robot=...)` of a UR5e: the limit of RP_l is the manual's 0.03 mm, named
    with its source, without a --limit-rp."""
    from robotcell.cell.model import cell_from_dict
    from robotcell.iso9283 import analyse, plan, simulate
    from robotcell.robot.models import load_robot

    cell = cell_from_dict({"name": "ur5e_test", "robot": {"model": "ur5e"}, "tools": {
        "probe": {"frame": {"x": 0, "y": 0, "z": 100, "a": 0, "b": 0, "c": 0}}}})
    p = plan(cell, tool="probe", size=0.2)
    result = analyse(simulate(cell, p, cell, path_cycles=0, cycles=10, noise=2e-6, seed=3), p,
                     robot=load_robot("ur5e"))
    assert result.limits.RP == pytest.approx(3e-5)
    assert any("limit of RP_l 0.03 mm" in n and "complianceUR5e" in n for n in result.notes)
    assert result.verdict.level == "pass"
