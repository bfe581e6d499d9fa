"""Fuzz test of the CLI: mutated copies of valid inputs never give a traceback.

Every case starts from a valid input of one of the main commands (calibrate tcp, frame, track,
turntable, workpiece, positioner; fk; ik; fk/ik --cell; export, also --format urdf; report; cell
show; identify, also --propose; reach; sweep, serial; simulate positioner), applies one or two seeded mutations
(truncation, wrong types, huge values, NaN, other encodings, swapped or misspelt columns, empty
files, binary junk, European CSV, ...) and runs the command in process. Each run must end with a
documented exit status: 0 (done), 2 (refused input, with ``error:`` on stderr) or 3 (a poor
calibration); 1 means an unexpected failure and fails the test. No ``Traceback`` may appear on
stdout or stderr, and a run that is refused or poor leaves no output file and no temporary file
behind.

``ROBOTCELL_FUZZ_SEED`` changes the seed (default 2026); the cases of a failing seed are printed.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from robotcell import pose_from_vendor, pose_to_vendor
from robotcell.kinematics.transforms import rot_z

SEED = int(os.environ.get("ROBOTCELL_FUZZ_SEED", "2026"))
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
EXAMPLE = EXAMPLES / "cell_kr16_track_turntable.yaml"
POSITIONER = EXAMPLES / "cell_kr16_positioner.yaml"
SEAM = EXAMPLES / "seam_part.csv"

#: Exit statuses the CLI documents (README, "Files and exit status"; 3 = poor calibration).
DOCUMENTED = {0, 2, 3}

#: Cases per command: 1,490 in all.
CASES = {"tcp": 120, "frame": 120, "track": 110, "turntable": 110, "workpiece": 100,
         "fk": 110, "ik": 100, "export": 90, "cell-show": 90, "report": 80,
         "identify": 50, "reach": 60, "sweep": 40, "positioner": 50, "simulate-positioner": 50,
         "fk-cell": 50, "ik-cell": 50, "urdf": 60}


# -- valid inputs (mm, deg) -----------------------------------------------------------------------
def _csv(header: list[str], rows: list[list[object]]) -> str:
    def cell(v: object) -> str:
        return f"{v:.6f}" if isinstance(v, float) else str(v)
    return "\n".join([",".join(header)] + [",".join(cell(v) for v in r) for r in rows]) + "\n"


def _tcp_csv(rng: np.random.Generator) -> str:
    pivot = np.array([1100.0, -200.0, 300.0])
    tcp = np.array([10.0, 5.0, 200.0])
    rows = []
    for k in range(6):
        abc = [60.0 * k, 180.0 - 25.0 * np.cos(k), 20.0 * np.sin(k)]
        T = pose_from_vendor([0, 0, 0, *abc], "kuka")
        p = pivot - T[:3, :3] @ tcp + rng.normal(0, 0.05, 3)
        rows.append([*map(float, p), *map(float, abc)])
    return _csv(["x", "y", "z", "a", "b", "c"], rows)


def _frame_csv(rng: np.random.Generator) -> str:
    T = pose_from_vendor([1500, -300, 400, 30, 2, -1], "kuka")
    local = np.array([[0, 0, 0], [300, 0, 0], [100, 200, 0]] * 2, dtype=float)
    p = local @ T[:3, :3].T + T[:3, 3] * 1e3 + rng.normal(0, 0.05, (6, 3))
    roles = ["origin", "x", "xy"] * 2
    return _csv(["point", "x", "y", "z", "note"],
                [[r, *map(float, v), "touch"] for r, v in zip(roles, p)])


def _track_csv(rng: np.random.Generator) -> str:
    e = np.linspace(0.0, 1500.0, 6)
    f = np.array([1500.0, 800.0, 300.0]) - np.outer(e, [0.9998, 0.02, 0.0]) + rng.normal(0, 0.05, (6, 3))
    return _csv(["x", "y", "z", "e1"], [[*map(float, fi), float(ei)] for fi, ei in zip(f, e)])


T_R_B = pose_from_vendor([2000, 900, 200, 90, 0.2, -0.1], "kuka")


def _turntable_rows(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    theta = np.radians([0.0, 60.0, 120.0, 180.0, 240.0, 300.0])
    p = (rot_z(theta) @ [0.35, 0.0, 0.05]) @ T_R_B[:3, :3].T + T_R_B[:3, 3]
    return p * 1e3 + rng.normal(0, 0.05, p.shape), np.degrees(theta)


def _turntable_csv(rng: np.random.Generator) -> str:
    f, th = _turntable_rows(rng)
    return _csv(["x", "y", "z", "e1"], [[*map(float, fi), float(t)] for fi, t in zip(f, th)])


def _workpiece_csv(rng: np.random.Generator) -> str:
    T_B_W = pose_from_vendor([100, -50, 80, 20, 0, 0], "kuka")
    pts = np.array([[0, 0, 0], [0.15, 0, 0], [0.05, 0.12, 0]] * 2)
    theta = np.radians([10.0, 100.0, 200.0, 250.0, 30.0, 300.0])
    rows = []
    for r, p, t in zip(["origin", "x", "xy"] * 2, pts, theta):
        T = T_R_B @ _rz4(t) @ T_B_W
        f = (T[:3, :3] @ p + T[:3, 3]) * 1e3 + rng.normal(0, 0.05, 3)
        rows.append([r, *map(float, f), float(np.degrees(t))])
    return _csv(["point", "x", "y", "z", "e1"], rows)


def _rz4(t: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = rot_z(t)
    return T


def _joints_csv(rng: np.random.Generator) -> str:
    q = rng.uniform([-60, -100, 40, -90, -60, -90], [60, -50, 110, 90, 60, 90], (4, 6))
    return _csv([f"a{i}" for i in range(1, 7)], [list(map(float, r)) for r in q])


def _poses_csv(rng: np.random.Generator) -> str:
    from robotcell import load_robot

    robot = load_robot("kuka_kr16")
    q = np.radians(rng.uniform([-60, -100, 40, -90, -60, -90], [60, -50, 110, 90, 60, 90], (4, 6)))
    v = pose_to_vendor(robot.fk(q), "kuka")
    return _csv(["x", "y", "z", "a", "b", "c"], [list(map(float, r)) for r in v])


def _tracker_csv(rng: np.random.Generator) -> str:
    """20 exact tracker rows of the nominal KR 16: a1..a6 (deg), x, y, z (mm)."""
    from robotcell import load_robot

    robot = load_robot("kuka_kr16")
    q = np.radians(rng.uniform([-60, -100, 40, -90, -60, -90], [60, -50, 110, 90, 60, 90], (20, 6)))
    xyz = (robot.fk(q) @ [0.05, 0.02, 0.1, 1.0])[:, :3] * 1e3 + [2000.0, 500.0, 0.0]
    return _csv([f"a{i}" for i in range(1, 7)] + ["x", "y", "z"],
                [list(map(float, r)) for r in np.hstack([np.degrees(q), xyz])])


def _cell_joints_csv(rng: np.random.Generator, positioner: bool) -> str:
    q = rng.uniform([-60, -100, 40, -90, -60, -90], [60, -50, 110, 90, 60, 90], (4, 6))
    ext = rng.uniform([-30, 0], [30, 180], (4, 2)) if positioner else rng.uniform(0, 6000, (4, 1))
    names = ["e1", "e2"] if positioner else ["track"]
    return _csv([f"a{i}" for i in range(1, 7)] + names,
                [list(map(float, r)) for r in np.hstack([q, ext])])


# -- mutations ------------------------------------------------------------------------------------
JUNK_VALUES = ["", " ", "abc", "nan", "NaN", "inf", "-inf", "1e300", "-1e308", "1e16", "9e15",
               "0", "-0", "1,5", "1.234,5", "true", "0x10", "1e", "--1", "∞", "١٢", "1_000",
               "'3'", '"4"', "1e-320", "3.4.5"]


def _split(text: str) -> list[list[str]]:
    return [line.split(",") for line in text.splitlines()]


def _join(rows: list[list[str]], sep: str = ",") -> str:
    return "\n".join(sep.join(r) for r in rows) + "\n"


def mutate_csv(text: str, rng: np.random.Generator) -> tuple[bytes | str, str]:
    """One mutation of a CSV text; returns the content and what was done."""
    rows = _split(text)
    kind = str(rng.choice([
        "truncate", "junk-value", "swap-columns", "misspell-column", "drop-column", "duplicate-row",
        "identical-rows", "few-rows", "empty", "header-only", "binary", "cp1252-note", "utf16",
        "bom", "european", "scale-column", "extra-column", "huge", "shuffle", "blank-lines",
        "ragged", "quote", "metres", "nul"]))
    n, m = len(rows), len(rows[0])
    i = int(rng.integers(1, n))
    j = int(rng.integers(0, min(m, len(rows[i]))))
    if kind == "truncate":
        return text[: int(rng.integers(0, len(text)))], kind
    if kind == "junk-value":
        rows[i][j] = str(rng.choice(JUNK_VALUES))
    elif kind == "swap-columns":
        a, b = rng.choice(m, 2, replace=False) if m > 1 else (0, 0)
        rows[0][a], rows[0][b] = rows[0][b], rows[0][a]
    elif kind == "misspell-column":
        name = rows[0][j]
        k = int(rng.integers(0, max(len(name), 1)))
        rows[0][j] = (name[:k] + name[k + 1:] + name[k:k + 1]) if len(name) > 1 else name + "x"
    elif kind == "drop-column":
        rows = [r[:j] + r[j + 1:] for r in rows]
    elif kind == "duplicate-row":
        rows.insert(i, list(rows[i]))
    elif kind == "identical-rows":
        rows = [rows[0]] + [list(rows[1]) for _ in rows[1:]]
    elif kind == "few-rows":
        rows = rows[: int(rng.integers(1, 4))]
    elif kind == "empty":
        return "", kind
    elif kind == "header-only":
        rows = rows[:1]
    elif kind == "binary":
        return bytes(rng.integers(0, 256, int(rng.integers(1, 400)), dtype=np.uint8)), kind
    elif kind == "cp1252-note":
        rows[0].append("note")
        for r in rows[1:]:
            r.append("Prüfstück café €")
        return _join(rows).encode("cp1252"), kind
    elif kind == "utf16":
        return _join(rows).encode("utf-16"), kind
    elif kind == "bom":
        return b"\xef\xbb\xbf" + _join(rows).encode("utf-8"), kind
    elif kind == "european":
        return _join([[c.replace(".", ",") for c in r] for r in rows], sep=";"), kind
    elif kind in ("scale-column", "metres"):
        factor = 1e-3 if kind == "metres" else float(rng.choice([1e3, -1.0, 1e6, 1e-6]))
        for r in rows[1:]:
            try:
                r[j] = repr(float(r[j]) * factor)
            except (ValueError, IndexError):
                pass
    elif kind == "extra-column":
        rows[0].append(str(rng.choice(["piont", "x", "e2", "", "a1", "nominal_x"])))
        for r in rows[1:]:
            r.append(str(rng.choice(["1", "tcp", "", "nan"])))
    elif kind == "huge":
        rows[i][j] = str(rng.choice(["1e300", "-1e300", "1e15", "1e14", "1e12", "4e9"]))
    elif kind == "shuffle":
        body = rows[1:]
        rng.shuffle(body)
        rows = [rows[0]] + body
    elif kind == "blank-lines":
        rows.insert(i, [""])
        rows.append(["   "])
    elif kind == "ragged":
        rows[i] = rows[i][:-1] if rng.random() < 0.5 else rows[i] + ["7"]
    elif kind == "quote":
        rows[i][j] = '"' + rows[i][j]
    elif kind == "nul":
        return _join(rows).replace(",", "\x00", 1), kind
    return _join(rows), kind


def mutate_text(text: str, rng: np.random.Generator) -> tuple[bytes | str, str]:
    """One mutation of a YAML or JSON text."""
    kind = str(rng.choice(["truncate", "delete-line", "junk-number", "binary", "cp1252",
                           "utf16", "bom", "empty", "swap-lines", "indent", "huge-number"]))
    lines = text.splitlines()
    i = int(rng.integers(0, len(lines)))
    if kind == "truncate":
        return text[: int(rng.integers(0, len(text)))], kind
    if kind == "delete-line":
        del lines[i]
    elif kind in ("junk-number", "huge-number"):
        import re
        numbers = [mt for mt in re.finditer(r"-?\d+(\.\d+)?", text)]
        if numbers:
            mt = numbers[int(rng.integers(0, len(numbers)))]
            new = (str(rng.choice(["1e300", "-1e300", "9e15", "1e12"])) if kind == "huge-number"
                   else str(rng.choice(["abc", ".nan", ".inf", "[1, 2]", "{}", "null", "true",
                                        "'x'", "1e999", "NaN", "Infinity", "-", "2 3"])))
            return text[:mt.start()] + new + text[mt.end():], kind
    elif kind == "binary":
        return bytes(rng.integers(0, 256, int(rng.integers(1, 400)), dtype=np.uint8)), kind
    elif kind == "cp1252":
        return ("# Zelle für Schweißen, Prüfstück\n" + text).encode("cp1252"), kind
    elif kind == "utf16":
        return text.encode("utf-16"), kind
    elif kind == "bom":
        return b"\xef\xbb\xbf" + text.encode("utf-8"), kind
    elif kind == "empty":
        return "", kind
    elif kind == "swap-lines":
        k = int(rng.integers(0, len(lines)))
        lines[i], lines[k] = lines[k], lines[i]
    elif kind == "indent":
        lines[i] = "   " + lines[i]
    return "\n".join(lines) + "\n", kind


def mutate_json(text: str, rng: np.random.Generator) -> tuple[bytes | str, str]:
    """Text mutations, or a value of the parsed object replaced by one of the wrong type."""
    if rng.random() < 0.4:
        return mutate_text(text, rng)
    data = json.loads(text)
    key = str(rng.choice(sorted(data)))
    bad = [None, "abc", 1e300, -1.0, [], {}, [1, 2], [[1, 2], [3]], True, float("nan"),
           [float("nan")] * 3, [[0.0] * 6] * 5, [["x"] * 6] * 6, [[1e300] * 6] * 6, 0]
    if rng.random() < 0.15:
        del data[key]
        return json.dumps(data), f"delete {key}"
    data[key] = bad[int(rng.integers(0, len(bad)))]
    return json.dumps(data), f"{key} -> {data[key]!r}"[:80]


#: Option values that are wrong, huge or not numbers.
BAD_FLOATS = ["-1", "0", "nan", "inf", "1e300", "-1e300", "abc", "1e15"]


# -- the commands ---------------------------------------------------------------------------------
def _case(command: str, rng: np.random.Generator, tmp: Path, good: dict[str, Path]
          ) -> tuple[list[str], str, Path | None]:
    """Arguments of one mutated case, what was mutated, and the output file the run may write."""
    out = tmp / "out" / f"result{int(rng.integers(0, 3))}.txt"
    opts: list[str] = []
    if command in ("tcp", "frame", "track", "turntable", "workpiece"):
        valid = {"tcp": _tcp_csv, "frame": _frame_csv, "track": _track_csv,
                 "turntable": _turntable_csv, "workpiece": _workpiece_csv}[command](rng)
        content, what = mutate_csv(valid, rng)
        if rng.random() < 0.3 and isinstance(content, str) and content.count("\n") > 2:
            content, second = mutate_csv(content, rng)
            what += f" + {second}"
        path = _write(tmp / "m.csv", content)
        args = ["calibrate", command, str(path)]
        if command == "workpiece":
            tt = good["turntable.json"]
            if rng.random() < 0.3:
                tt_content, tt_what = mutate_json(tt.read_text(), rng)
                tt = _write(tmp / "tt.json", tt_content)
                what += f"; turntable.json: {tt_what}"
            args += ["--turntable", str(tt)]
        if rng.random() < 0.25:
            opts = ["--sigma", str(rng.choice(BAD_FLOATS + ["0.05"]))]
        if command == "turntable" and rng.random() < 0.2:
            opts += ["--height", str(rng.choice(BAD_FLOATS))]
        if command == "track" and rng.random() < 0.2:
            opts += ["--reference", str(rng.choice(["1500,800,300", "1,2", "nan,0,0", "a,b,c"]))]
        if rng.random() < 0.5:
            opts += ["--json", "-o", str(out)]
        return args + opts, what + " " + " ".join(opts), out if "-o" in opts else None
    if command == "fk":
        content, what = mutate_csv(_joints_csv(rng), rng)
        path = _write(tmp / "joints.csv", content)
        return (["fk", "kuka_kr16", "--input", str(path), "-o", str(out),
                 "--format", str(rng.choice(["kuka", "abb", "fanuc", "matrix"]))], what, out)
    if command == "ik":
        content, what = mutate_csv(_poses_csv(rng), rng)
        path = _write(tmp / "poses.csv", content)
        extra = ["--all"] if rng.random() < 0.3 else []
        if rng.random() < 0.2:
            extra += ["--near", str(rng.choice(["0,-90,90,0,0,0", "1,2", "nan,0,0,0,0,0"]))]
        return ["ik", "kuka_kr16", "--input", str(path), "-o", str(out), *extra], what, out
    if command in ("export", "cell-show"):
        content, what = mutate_text(EXAMPLE.read_text(encoding="utf-8"), rng)
        path = _write(tmp / "cell.yaml", content)
        if command == "export":
            fmt = str(rng.choice(["kuka", "abb", "fanuc", "yaskawa"]))
            return ["export", "--cell", str(path), "--format", fmt, "-o", str(out)], what, out
        return ["cell", "show", str(path)], what, None
    if command in CELL_COMMANDS:
        return _cell_case(command, rng, tmp, good, out)
    content, what = mutate_json(good["turntable.json"].read_text(), rng)
    path = _write(tmp / "r.json", content)
    html = tmp / "out" / "r.html"
    return ["report", str(path), "-o", str(html)], what, html


#: The commands of the cell studies and identification, cased in :func:`_cell_case`.
CELL_COMMANDS = ("identify", "reach", "sweep", "positioner", "simulate-positioner", "fk-cell",
                 "ik-cell", "urdf")


def _mutated(valid: str, rng: np.random.Generator, tmp: Path, name: str) -> tuple[Path, str]:
    """``valid`` (a CSV when ``name`` ends so, else YAML) mutated, written to ``tmp/name``."""
    content, what = (mutate_csv if name.endswith(".csv") else mutate_text)(valid, rng)
    return _write(tmp / name, content), f"{name}: {what}"


def _cell_case(command: str, rng: np.random.Generator, tmp: Path, good: dict[str, Path],
               out: Path) -> tuple[list[str], str, Path | None]:
    """A mutated case of one of :data:`CELL_COMMANDS`: mostly the data file, sometimes the cell
    file or an option."""
    cell_text = (POSITIONER if command in ("positioner", "simulate-positioner") else EXAMPLE
                 ).read_text(encoding="utf-8")
    cell, what = _write(tmp / "cell.yaml", cell_text), "valid cell"
    if command in ("simulate-positioner", "urdf") or rng.random() < 0.15:
        cell, what = _mutated(cell_text, rng, tmp, "cell.yaml")
    bad = str(rng.choice(BAD_FLOATS))
    if command == "identify":
        path, what = _mutated(_tracker_csv(rng), rng, tmp, "tracker.csv")
        opts = [str(rng.choice(["--accuracy", "--folds", "--j23-factor"])), bad] \
            if rng.random() < 0.2 else []
        if rng.random() < 0.1:
            return (["identify", "--propose", str(rng.choice(["0", "-1", "2", "5000", "abc"])),
                     "--robot", "kuka_kr16", "-o", str(out)], "--propose", out)
        return ["identify", str(path), "--robot", "kuka_kr16", "-o", str(out), *opts], what, out
    if command in ("reach", "sweep"):
        path, w = _mutated(SEAM.read_text(encoding="utf-8"), rng, tmp, "seam.csv")
        what += "; " + w
        if command == "reach":
            return (["reach", "--cell", str(cell), str(path), "--frame", "part", "--tool", "torch",
                     "-o", str(out)], what, out)
        layouts = "robot:\n  y: [-300, 0]\nturntable:\n  a: {from: 0, to: 90, steps: 2}\n"
        lay = _write(tmp / "layouts.yaml", layouts)
        if rng.random() < 0.5:
            lay, w = _mutated(layouts, rng, tmp, "layouts.yaml")
            what += "; " + w
        workers = str(rng.choice(["0", "-1", "abc"])) if rng.random() < 0.1 else "1"
        return (["sweep", "--cell", str(cell), "--targets", str(path), "--layouts", str(lay),
                 "--frame", "part", "--tool", "torch", "--workers", workers, "-o", str(out)],
                what, out)
    if command == "positioner":
        path, what = _mutated(good["positioner.csv"].read_text(encoding="utf-8"), rng, tmp,
                              "touches.csv")
        if rng.random() < 0.5:
            return (["calibrate", "positioner", str(path), "--cell", str(cell), "--tool",
                     "pointer"], what, None)
        return (["calibrate", "positioner", str(path), "--robot", "kuka_kr16", "--tool",
                 "250,0,0,0,0,0", "--json", "-o", str(out)], what, out)
    if command == "simulate-positioner":
        opts = []
        if rng.random() < 0.3:
            opt = str(rng.choice(["--tilts", "--rotates", "--noise", "--radius", "--height"]))
            opts = [opt, str(rng.choice([bad, "0", "10,20", "500", "0,0,0"]))]
        return (["simulate", "positioner", "--cell", str(cell), "--tool", "pointer", "--seed",
                 "1", "-o", str(out), *opts], what + " " + " ".join(opts), out)
    if command in ("fk-cell", "ik-cell"):
        positioner = rng.random() < 0.5
        if positioner:
            cell = _write(tmp / "cell.yaml", POSITIONER.read_text(encoding="utf-8"))
        if command == "fk-cell":
            path, what = _mutated(_cell_joints_csv(rng, positioner), rng, tmp, "joints.csv")
            return (["fk", "--cell", str(cell), "--input", str(path), "--frame", "part",
                     "--tool", "torch", "-o", str(out)], what, out)
        path, what = _mutated(_poses_csv(rng), rng, tmp, "poses.csv")
        table = str(rng.choice(["normal-up", "10,20", "10", bad])) if positioner else \
            str(rng.choice(["150", "90", bad]))
        return (["ik", "--cell", str(cell), "--input", str(path), "--frame", "part", "--tool",
                 "torch", "--table", table, "-o", str(out)], f"{what} --table {table}", out)
    return ["export", "--cell", str(cell), "--format", "urdf", "-o", str(out)], what, out


def _write(path: Path, content: bytes | str) -> Path:
    if isinstance(content, str):
        path.write_bytes(content.encode("utf-8", errors="surrogatepass"))
    else:
        path.write_bytes(content)
    return path


@pytest.fixture(scope="module")
def good(tmp_path_factory) -> dict[str, Path]:
    """A valid turntable result (the --json output), for workpiece and report; positioner
    touches simulated in the example positioner cell."""
    from robotcell.calibration.turntable import calibrate_turntable
    from robotcell.cell import Cell
    from robotcell.studies.simulate import simulate

    d = tmp_path_factory.mktemp("good")
    f, th = _turntable_rows(np.random.default_rng(SEED))
    result = calibrate_turntable(np.radians(th), f * 1e-3)
    path = d / "turntable.json"
    path.write_text(json.dumps(result.to_json()))
    touches = d / "positioner.csv"
    simulate(Cell.load(POSITIONER), "positioner", seed=SEED, tool="pointer").write_csv(touches)
    return {"turntable.json": path, "positioner.csv": touches}


@pytest.mark.parametrize("command", list(CASES))
def test_cli_fuzz(command, tmp_path, capsys, good):
    rng = np.random.default_rng([SEED, list(CASES).index(command)])
    (tmp_path / "out").mkdir()
    failures = []
    codes: dict[int, int] = {}
    for k in range(CASES[command]):
        for stale in (tmp_path / "out").iterdir():
            stale.unlink()
        args, what, output = _case(command, rng, tmp_path, good)
        code, out, err = run(capsys, *args)
        codes[code] = codes.get(code, 0) + 1
        problems = []
        if code not in DOCUMENTED:
            problems.append(f"exit status {code}")
        if "Traceback" in out or "Traceback" in err:
            problems.append("traceback")
        if code == 2 and "error:" not in err:
            problems.append("exit 2 without 'error:'")
        left = sorted(p.name for p in (tmp_path / "out").iterdir())
        if code in (2, 3) and output is not None and left:
            problems.append(f"refused run left files {left}")
        if any(name.endswith(".tmp") for name in left):
            problems.append(f"temporary files left {left}")
        if problems:
            failures.append(f"case {k} ({what}): {', '.join(problems)}; robotcell "
                            f"{' '.join(args)}\n  stderr: {err.strip()[-300:]}")
    assert not failures, (f"seed {SEED}, {len(failures)} of {CASES[command]} cases failed:\n"
                          + "\n".join(failures[:8]))
    # The mutations must exercise both outcomes, else the test could not fail.
    assert codes.get(0, 0) > 0 and codes.get(2, 0) > 0, codes
