"""Messages that name the real cause: a comment or title line above a CSV header, a folder
output given an existing file, too few touches once some are left out as outliers; and ``cell
history`` saying in one line per version what changed, when, and with what RMS."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import InputError, pose_from_vendor
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.cell import Cell, Provenance
from robotcell.cell.history import cell_history
from robotcell.io.tables import read_csv
from robotcell.kinematics.transforms import rot_z
from robotcell.programs import write_program

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"
SEAM = ROOT / "examples" / "seam_part.csv"
T_R_B = pose_from_vendor([2000, 900, 200, 90, 0.2, -0.1], "kuka")


# -- comment and title lines -----------------------------------------------------------------------
@pytest.mark.parametrize("content, match", [
    ("# touches of cell 3\nx,y,z,e1\n1,2,3,4\n",
     r"t.csv: line 1 '# touches of cell 3' is a comment above the header: robotcell reads the "
     r"first line as the header \(the column names\) and skips no comment lines; delete the "
     r"comment line\(s\), or keep remarks in a column 'note'"),
    ("# cell 3, KR 16\n# 2026-01-12\nx,y,z,e1\n1,2,3,4\n",
     r"line 1 '# cell 3, KR 16' is a comment"),
    ("\n# cell 3\nx;y;z\n1,5;2;3\n", r"line 2 '# cell 3' is a comment above the header"),
    ("Touches of cell 3\nx,y,z,e1\n1,2,3,4\n",
     r"line 1 'Touches of cell 3' has 1 value\(s\), and the line after it 4 names and no "
     r"number: a title above the header\?"),
    ("x,y,z\n1,2,3\n# re-touched\n4,5,6\n",
     r"line 3 starts with '#': robotcell skips no comment lines; delete it, or keep the remark "
     r"in a column 'note'"),
    ("x,y,z\n1,2,3\n# a, b, c\n4,5,6\n", r"line 3 starts with '#'"),
])
def test_a_comment_or_title_line_is_named_as_such(tmp_path, content, match):
    p = tmp_path / "t.csv"
    p.write_text(content)
    with pytest.raises(InputError, match=match) as exc:
        read_csv(p)
    assert "decimal commas" not in str(exc.value)


def test_a_column_named_hash_and_a_hash_in_a_note_column_are_data(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("#,x\n1,2\n2,3\n")
    np.testing.assert_array_equal(read_csv(p)["#"], [1.0, 2.0])
    p.write_text("note,x\n# first,2\n,3\n")
    assert read_csv(p)["note"] == ["# first", ""]


def test_calibrate_names_the_comment_line_and_writes_nothing(tmp_path, capsys):
    p = tmp_path / "table.csv"
    p.write_text("# turntable touches, cell 3\nx,y,z,e1\n" + "".join(
        f"{1000 + 300 * np.cos(t):.3f},{300 * np.sin(t):.3f},0,{np.degrees(t):.1f}\n"
        for t in np.radians([0, 60, 120, 180, 240, 300])))
    code, out, err = run(capsys, "calibrate", "turntable", p, "-o", tmp_path / "r.txt")
    assert code == 2 and err.count("error:") == 1
    assert "line 1 '# turntable touches, cell 3' is a comment above the header" in err
    assert sorted(f.name for f in tmp_path.iterdir()) == ["table.csv"]


# -- a folder output given a file -----------------------------------------------------------------
def test_program_write_onto_an_existing_file_says_o_is_a_folder(tmp_path, capsys):
    f = tmp_path / "prog"
    f.write_text("my notes\n")
    args = ["program", "write", SEAM, "--cell", EXAMPLE, "--tool", "torch", "--frame", "part",
            "--format", "kuka"]
    code, out, err = run(capsys, *args, "-o", f)
    assert code == 2
    assert (f"'{f}' exists and is a file, but this option names a folder: the one the files "
            "are written into (created when missing); give a folder") in err
    assert "Directory" not in err and f.read_text() == "my notes\n"
    code, out, err = run(capsys, *args, "-o", f / "sub")
    assert code == 2 and f"cannot write '{f / 'sub'}': '{f}' is a file, not a folder" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["prog"]
    with pytest.raises(InputError, match=r"/prog' is a file, not a folder"):  # the library
        write_program(SEAM, Cell.load(EXAMPLE), "torch", "part", "kuka", f / "sub")


# -- too few touches, some left out ---------------------------------------------------------------
def _table_csv(path: Path, theta_deg: list[float], wrong: int | None) -> Path:
    rng = np.random.default_rng(7)
    theta = np.radians(theta_deg)
    p = (rot_z(theta) @ [0.35, 0.0, 0.05]) @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    p = p * 1e3 + rng.normal(0.0, 0.05, p.shape)
    if wrong is not None:
        p[wrong] += [10.0, 0.0, 0.0]
    path.write_text("x,y,z,e1\n" + "".join(f"{a:.4f},{b:.4f},{c:.4f},{t:g}\n"
                                         for (a, b, c), t in zip(p, theta_deg)))
    return path


def test_too_few_touches_once_one_is_left_out_counts_given_left_out_and_more(tmp_path, capsys):
    f = _table_csv(tmp_path / "t.csv", [0, 60, 120, 180, 240, 300], wrong=3)
    code, out, err = run(capsys, "calibrate", "turntable", f, "--json")
    assert code == 0, err
    v = json.loads(out)["verdict"]
    assert json.loads(out)["excluded"] == ["line 5"]
    reason = ("of the 6 touches given, 1 left out as an outlier and 5 used; take 1 more touch "
              "(re-touching one left out counts), so that 6 or more are used")
    assert any(r.endswith(reason) for r in v["reasons"]), v["reasons"]
    assert not any("take 6 or more touches" in r for r in v["reasons"])
    assert v["touches_needed"] == 6


def test_too_few_touches_without_any_left_out_says_how_many_more():
    theta = np.radians([0.0, 90.0, 180.0, 270.0])
    p = (rot_z(theta) @ [0.35, 0.0, 0.05]) @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    v = calibrate_turntable(theta, p).verdict
    assert ("redundancy 5 is too little to single out a wrong touch; take 6 or more touches (4 "
            "given: 2 more touches)") in v.reasons


# -- cell history ---------------------------------------------------------------------------------
def _history_cell(tmp_path: Path) -> Path:
    """The example cell and two updates of the torch whose provenance holds what a calibration
    with --cell records: error sources, a covariance, a checksum."""
    path = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, path)
    for k, rms in enumerate((0.05, 0.04)):
        cell = Cell.load(path)
        prov = Provenance("tcp", f"2026-01-0{k + 1}T08:00:00+01:00", rms, "6 touches")
        cell.set_tool("torch", cell.tools["torch"].T_F_TCP, prov)
        cell.save(path)
    return path


def test_cell_history_prints_one_readable_line_per_version(tmp_path, capsys):
    path = _history_cell(tmp_path)
    code, out, err = run(capsys, "cell", "history", path)
    assert code == 0, err
    head, *lines = out.splitlines()
    assert head == f"3 version(s) of {path}, oldest first (--json for every provenance field):"
    assert len(lines) == 3
    assert lines[0].startswith(f"{path}.1.bak ")
    assert "first kept version, 6 item(s): track KL1500 (track, RMS 0.110 mm); " in lines[0]
    assert lines[1].startswith(f"{path}.2.bak ") and lines[1].endswith("tool torch (tcp, RMS "
                                                                       "0.050 mm)")
    assert lines[2].startswith(f"{path} (current)") and lines[2].endswith("tool torch (tcp, "
                                                                          "RMS 0.040 mm)")
    written = cell_history(path)[2].modified
    assert f"  {written}  " in lines[2]


def test_cell_history_of_a_calibrated_cell_keeps_matrices_for_json(tmp_path, capsys):
    path = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, path)
    code, _, err = run(capsys, "simulate", "tcp", "--cell", path, "--tool", "pointer",
                       "-o", tmp_path / "tcp.csv")
    assert code == 0, err
    code, _, err = run(capsys, "calibrate", "tcp", tmp_path / "tcp.csv", "--cell", path,
                       "--name", "pointer")
    assert code == 0, err
    code, out, err = run(capsys, "cell", "history", path)
    assert code == 0, err
    lines = out.splitlines()
    assert len(lines) == 3 and all(len(line) < 400 for line in lines)
    assert "covariance" not in out and "sha256" not in out and "[[" not in out
    assert lines[2].startswith(f"{path} (current)") and "tool pointer (tcp, RMS " in lines[2]
    code, out, err = run(capsys, "cell", "history", path, "--json")
    assert code == 0, err
    data = json.loads(out)
    current = data["versions"][-1]
    assert data["cell"] == str(path) and current["current"] and current["number"] is None
    assert current["changed"] == ["tool pointer"] and current["error"] is None
    prov = current["provenance"]["tool pointer"]
    assert prov["source"] == "tcp" and len(prov["covariance_mm_rad"]) == 6
    assert prov["measurements"] == "tcp.csv"


def test_cell_history_names_a_version_it_cannot_read_in_its_line(tmp_path, capsys):
    path = _history_cell(tmp_path)
    (tmp_path / "cell.yaml.2.bak").write_text("tools: [\n")
    code, out, err = run(capsys, "cell", "history", path)
    assert code == 0, err
    line = out.splitlines()[2]
    assert line.startswith(f"{path}.2.bak ") and "not readable: " in line
    data = json.loads(run(capsys, "cell", "history", path, "--json")[1])
    broken = data["versions"][1]
    assert "not valid YAML" in broken["error"] and broken["provenance"] == {}
