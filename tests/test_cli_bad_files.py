"""Bad files and options for identify, reach, sweep, calibrate/simulate positioner, fk/ik --cell
and export --format urdf: each exits 2 with one ``error:`` line naming the cause, never 1 or a
traceback (README, "Files and exit status")."""

from __future__ import annotations

import socket
import threading
from pathlib import Path

import pytest
from cli_helpers import run

from robotcell.io.yamlfile import dump_yaml, parse_yaml

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CELL = str(EXAMPLES / "cell_kr16_track_turntable.yaml")
POSITIONER = str(EXAMPLES / "cell_kr16_positioner.yaml")
SEAM = str(EXAMPLES / "seam_part.csv")
LAYOUTS = str(EXAMPLES / "layouts_kr16.yaml")
TRACKER = "a1,a2,a3,a4,a5,a6,x,y,z\n" + "".join(
    f"{10 * k},-90,90,{5 * k},45,0,{1000 + k},{20 * k},{1200 - k}\n" for k in range(8))

#: name -> content of a bad CSV, and a piece of the message it must give.
BAD_CSV = {
    "missing-column": ("a1,a2,a3,a4,a5,a6,x,y\n0,0,0,0,0,0,1,2\n", "column"),
    "text-number": (TRACKER.replace("\n10,", "\nabc,", 1), "numeric"),
    "nan": (TRACKER.replace("\n10,", "\nnan,", 1), "NaN"),
    "empty": ("", "header line and at least one data line"),
    "header-only": (TRACKER.splitlines()[0] + "\n", "header line and at least one data line"),
    "utf16": (TRACKER.encode("utf-16"), "UTF-16"),
    "binary": (bytes(range(256)) * 2, "not a text file"),
}


def _commands(path: str) -> dict[str, list[str]]:
    return {
        "identify": ["identify", path, "--robot", "kuka_kr16"],
        "reach": ["reach", "--cell", CELL, path, "--frame", "part", "--tool", "torch"],
        "sweep": ["sweep", "--cell", CELL, "--targets", path, "--layouts", LAYOUTS,
                  "--frame", "part", "--tool", "torch", "--workers", "1"],
        "calibrate-positioner": ["calibrate", "positioner", path, "--cell", POSITIONER,
                                 "--tool", "pointer"],
        "ik-cell": ["ik", "--cell", CELL, "--frame", "part", "--tool", "torch", "--table", "150",
                    "--input", path],
        "fk-cell": ["fk", "--cell", CELL, "--frame", "part", "--input", path],
    }


def _check(code: int, err: str, out: str, match: str) -> None:
    assert "Traceback" not in out + err
    assert code == 2, err
    assert err.count("error:") == 1 and match.lower() in err.lower(), err


@pytest.mark.parametrize("bad", list(BAD_CSV))
@pytest.mark.parametrize("command", list(_commands("x")))
def test_bad_csv(command, bad, tmp_path, capsys):
    content, match = BAD_CSV[bad]
    path = tmp_path / f"{bad}.csv"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    args = _commands(str(path))[command]
    if bad == "missing-column" and command == "fk-cell":
        return  # a1..a6 are all fk needs: x, y are unused columns (a warning)
    if bad in ("text-number", "missing-column") and command in ("reach", "sweep", "ik-cell",
                                                                "calibrate-positioner"):
        match = "missing column"  # these read poses or e1, e2: the tracker file lacks them
    code, out, err = run(capsys, *args)
    _check(code, err, out, match)


@pytest.mark.parametrize("args,output", [
    (["identify", "TRACKER", "--robot", "kuka_kr16"], "-o"),
    (["identify", "TRACKER", "--robot", "kuka_kr16"], "--report"),
    (["identify", "--propose", "10", "--robot", "kuka_kr16"], "-o"),
    (["reach", "--cell", CELL, SEAM, "--frame", "part", "--tool", "torch"], "-o"),
    (["sweep", "--cell", CELL, "--targets", SEAM, "--layouts", LAYOUTS, "--workers", "1"], "-o"),
    (["simulate", "positioner", "--cell", POSITIONER, "--tool", "pointer"], "-o"),
    (["export", "--cell", POSITIONER, "--format", "urdf"], "-o"),
    (["ik", "--cell", CELL, "--frame", "part", "--tool", "torch", "--table", "150", "--input",
      SEAM], "-o"),
])
def test_a_folder_or_a_missing_folder_as_output(args, output, tmp_path, capsys):
    (tmp_path / "tracker.csv").write_text(TRACKER)
    args = [str(tmp_path / "tracker.csv") if a == "TRACKER" else a for a in args]
    (tmp_path / "adir").mkdir()
    code, out, err = run(capsys, *args, output, tmp_path / "adir")
    _check(code, err, out, "it is a folder")
    if output != "--report":  # a report's missing folder is created, as for 'robotcell report'
        code, out, err = run(capsys, *args, output, tmp_path / "none" / "x.out")
        _check(code, err, out, "does not exist")
        assert not (tmp_path / "none").exists()


@pytest.mark.parametrize("args,match", [
    (["calibrate", "positioner", "TOUCHES", "--cell", CELL, "--tool", "pointer"],
     "has no positioner of 2 axes"),
    (["simulate", "positioner", "--cell", CELL, "--tool", "pointer"],
     "needs a cell with a positioner"),
    (["ik", "--cell", CELL, "--frame", "part", "--tool", "torch", "--table", "normal-up",
      "--pose", "60,10,5,0,135,0"], "normal-up needs a positioner"),
    (["fk", "--cell", POSITIONER, "--joints", "0,-90,90,0,45,0", "--track", "1500"],
     "the cell has no track"),
    (["fk", "--cell", POSITIONER, "--joints", "0,-90,90,0,45,0", "--table", "30"],
     "has 2 axes"),
    (["identify", "--propose", "0", "--robot", "kuka_kr16"], "must be positive"),
    (["identify", "--propose", "1000", "--robot", "kuka_kr16"], "at most 999"),
    (["identify", "TRACKER", "--robot", "kuka_kr16", "--accuracy", "0"],
     "--sigma must be a positive number"),
    (["identify", "TRACKER", "--robot", "kuka_kr16", "--j23-factor", "nan"],
     "--j23-factor must be a finite number"),
    (["sweep", "--cell", CELL, "--targets", SEAM, "--layouts", LAYOUTS, "--workers", "0"],
     "--workers must be at least 1"),
    (["sweep", "--cell", CELL, "--targets", SEAM, "--layouts", LAYOUTS, "--workers", "-1"],
     "--workers must be at least 1"),
])
def test_missing_parts_and_bad_options(args, match, tmp_path, capsys):
    (tmp_path / "tracker.csv").write_text(TRACKER)
    (tmp_path / "touches.csv").write_text("a1,a2,a3,a4,a5,a6,e1,e2\n" + "0,-90,90,0,45,0,0,0\n" * 12)
    args = [str(tmp_path / "tracker.csv") if a == "TRACKER" else
            str(tmp_path / "touches.csv") if a == "TOUCHES" else a for a in args]
    code, out, err = run(capsys, *args)
    _check(code, err, out, match)


def test_a_singular_coupling_matrix(tmp_path, capsys):
    from importlib.resources import files

    model = parse_yaml((files("robotcell") / "robots" / "kuka_kr16.yaml").read_text(), "kr16")
    eye = [[float(i == j) for j in range(6)] for i in range(6)]
    eye[2] = list(eye[1])  # axes 2 and 3 drive the same joint
    model["coupling"] = {"matrix": eye}
    (tmp_path / "m.yaml").write_text(dump_yaml(model))
    (tmp_path / "tracker.csv").write_text(TRACKER)
    cell = Path(CELL).read_text().replace("model: kuka_kr16", f"model: {tmp_path / 'm.yaml'}")
    (tmp_path / "cell.yaml").write_text(cell)
    for args in (["identify", tmp_path / "tracker.csv", "--robot", tmp_path / "m.yaml"],
                 ["reach", "--cell", tmp_path / "cell.yaml", SEAM, "--frame", "part"],
                 ["export", "--cell", tmp_path / "cell.yaml", "--format", "urdf"]):
        code, out, err = run(capsys, *args)
        _check(code, err, out, "coupling matrix is not invertible")


@pytest.mark.parametrize("layouts,match", [
    ("robot:\n  y: [1, 2\n", "not valid YAML"),
    ("gantry:\n  y: [1, 2]\n", "which the cell does not have"),
    ("robot:\n  q: [1, 2]\n", "unknown axis 'q'"),
    ("robot:\n  y: [a, 2]\n", "values must be numbers"),
    ("robot:\n  y: [.nan, 2]\n", "finite"),
    ("", "expected a mapping of components"),
    ("robot:\n  y: {from: 0, to: 1, steps: 100000000}\n", "steps must be a whole number from 1"),
    ("robot:\n  x: {from: 0, to: 1, steps: 1000}\n  y: {from: 0, to: 1, steps: 1000}\n",
     "1000000 layouts"),
    (b"\x00\xff\xfe junk \x80" * 20, "not a text file"),
])
def test_bad_layout_files(layouts, match, tmp_path, capsys):
    path = tmp_path / "l.yaml"
    path.write_bytes(layouts if isinstance(layouts, bytes) else layouts.encode())
    code, out, err = run(capsys, "sweep", "--cell", CELL, "--targets", SEAM, "--layouts", path,
                         "--frame", "part", "--tool", "torch", "--workers", "1")
    _check(code, err, out, match)


def test_a_scheduler_address_where_no_scheduler_answers(capsys):
    """Something that is not Dask listens there: a clear error at once, not a crash or a hang."""
    pytest.importorskip("distributed")
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()

    def answer():
        for _ in range(20):
            try:
                conn, _ = server.accept()
            except OSError:
                return
            conn.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n" + b"\xff" * 64)
            conn.close()

    threading.Thread(target=answer, daemon=True).start()
    try:
        code, out, err = run(capsys, "sweep", "--cell", CELL, "--targets", SEAM, "--layouts",
                             LAYOUTS, "--scheduler", f"tcp://127.0.0.1:{server.getsockname()[1]}")
    finally:
        server.close()
    _check(code, err, out, "cannot reach a Dask scheduler")
