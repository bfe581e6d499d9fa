"""Fuzz test of the CLI: mutated copies of valid inputs, for every command and every file kind.

Every case starts from valid inputs of one command (calibrate tcp, frame, external-tcp, track,
turntable, workpiece, positioner, also into a cell; fk, ik, also --cell; export, also URDF;
report; cell show, cell history; identify, also --propose; reach; sweep; simulate; plan; dh
from-urdf, dh convert; robots show; demo; view, also --reach and --program; iso9283 plan and
analyse, simulate iso9283, whose logs also get the faults of a tracker's log; the commands of
two robots: calibrate robot-to-robot and shared-positioner, also --update-cell, program
write-coordinated and check-coordinated of a YASKAWA job, also with times, view of a
coordinated program, identify --cell --robot-name, plan robot-to-robot) and applies one or
two seeded mutations to a file (measurement CSV, cell YAML and its backups, report JSON, URDF,
robot model YAML, layouts YAML, reach CSV, KUKA, ABB, FANUC and YASKAWA programs, timed paths,
bodies YAML: truncation, wrong types, huge
values, NaN, other encodings, swapped or misspelt columns, empty files, binary junk, European
CSV, ...) or to an option (negative, zero, NaN, infinite, 1e300, 1e-300, text), or names an
input as the output. It runs the command in process, in a folder of its own. Each run must end
with a documented exit status: 0 (done), 2 (refused input, with ``error:`` on stderr) or 3 (a
poor calibration); 1 means an unexpected failure and fails the test. No ``Traceback`` and no
Python warning (``RuntimeWarning: ...``) may appear on stdout or stderr; a run that is refused
or poor changes, creates and deletes no file (an output named like one of the inputs is
refused), and a run that succeeds changes no input it does not own (the cell file it
calibrates into) and leaves no temporary file; files written together (an identification's
model file and the cell it goes into) change all or none, and a page, YASKAWA job or ABB module
written ends with its last line (:data:`ENDS`).

``pytest -q`` runs the first cases of each command (:data:`CASES`, first number, 220);
``ROBOTCELL_FUZZ=full`` runs the full set (second number, 2,436), as ``.ci/run`` does.
``ROBOTCELL_FUZZ_SEED`` changes the seed (default 2026); the cases of a failing seed are printed.

The first cases of every command (:data:`READ_ONLY`) also run as another user, from a read-only
copy of the package and without a writable home (tests/readonly_helpers.py: numba cannot cache
its machine code, matplotlib cannot keep its settings), all in one process: the same checks, and
the same exit status and output as the same cases run here.
"""

from __future__ import annotations

import functools
import json
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from readonly_helpers import PROGRESS, read_only_install

from robotcell import pose_from_vendor, pose_to_vendor
from robotcell.kinematics.transforms import rot_z

SEED = int(os.environ.get("ROBOTCELL_FUZZ_SEED", "2026"))
#: The full set (``.ci/run``) or the first cases of each command (``pytest -q``).
FULL = os.environ.get("ROBOTCELL_FUZZ", "") == "full"
ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
EXAMPLE = EXAMPLES / "cell_kr16_track_turntable.yaml"
POSITIONER = EXAMPLES / "cell_kr16_positioner.yaml"
SEAM = EXAMPLES / "seam_part.csv"
URDF = ROOT / "src" / "robotcell" / "robots" / "urdf" / "ur5e.urdf"

#: Exit statuses the CLI documents (README, "Files and exit status"; 3 = poor calibration).
DOCUMENTED = {0, 2, 3}
#: A Python warning as the CLI would print it (``warning: RuntimeWarning: overflow ...``).
PYTHON_WARNING = re.compile(r"\b[A-Z]\w*Warning\b")

#: Cases per command: (in ``pytest -q``, in the full set). The fast cases are the first ones of
#: the full set's sequence.
CASES = {"tcp": (12, 120), "frame": (12, 120), "external-tcp": (8, 60), "track": (10, 110),
         "turntable": (10, 110), "workpiece": (8, 100), "positioner": (5, 50),
         "fk": (10, 110), "fk-cell": (6, 60), "ik": (8, 100), "ik-cell": (6, 60),
         "export": (8, 90), "urdf": (5, 60), "cell-show": (8, 90), "report": (5, 80),
         "identify": (3, 50), "reach": (4, 60), "sweep": (4, 40), "simulate": (8, 80),
         "plan": (1, 6), "dh-from-urdf": (6, 60), "dh-convert": (6, 50), "robots-show": (6, 50),
         "demo": (2, 10), "view": (4, 40), "view-reach": (3, 30), "view-program": (4, 50),
         "cell-history": (4, 50)}
#: Commands whose cases need not include a successful run (demo: only refused options, since a
#: valid demo takes seconds; plan: few cases, each mutated).
REFUSALS_ONLY = {"demo", "plan"}


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
    """30 exact tracker rows of the nominal KR 16: a1..a6 (deg), x, y, z (mm); enough for the
    default 5-fold cross-validation (24 rows per fit, 18 needed)."""
    from robotcell import load_robot

    robot = load_robot("kuka_kr16")
    q = np.radians(rng.uniform([-60, -100, 40, -90, -60, -90], [60, -50, 110, 90, 60, 90], (30, 6)))
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
            new = (str(rng.choice(["1e300", "-1e300", "9e15", "1e12", "1.0e+308", "-1.0e+308"]))
                   if kind == "huge-number"
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


#: Option values that are wrong, huge, tiny or not numbers.
BAD_FLOATS = ["-1", "0", "nan", "inf", "-inf", "1e300", "-1e300", "1e-300", "abc", "1e15", ""]
#: Values for options that take a list of numbers.
BAD_LISTS = ["1,2", "nan,0,0", "a,b,c", "1e300,0,0", "", "0,0,0,0,0,0,0", "1e-300,0,0"]


def _bad(rng: np.random.Generator, values: list[str] = BAD_FLOATS) -> str:
    return str(rng.choice(values))


def _maybe(rng: np.random.Generator, p: float, options: dict[str, list[str]]) -> list[str]:
    """With probability ``p``: one of ``options`` with one of its values."""
    if rng.random() >= p:
        return []
    name = str(rng.choice(sorted(options)))
    return [name, str(rng.choice(options[name]))]


# -- the commands ---------------------------------------------------------------------------------
class Case:
    """One run: its arguments, what was mutated, the files it may write when it succeeds, and
    the files it writes all together or none of (an identification into a cell: the cell and
    the model file)."""

    def __init__(self, args: list, what: str, writes: tuple[Path, ...] = (),
                 together: tuple[Path, ...] = ()):
        self.args = [str(a) for a in args]
        self.what = what
        self.writes = writes
        self.together = together


def _calibrate(command: str, rng: np.random.Generator, d: Path, good: dict[str, Path]
               ) -> tuple[list, str, list[Path]]:
    """calibrate tcp, frame, external-tcp, track, turntable, workpiece: touches in the robot
    base, or simulated joint values with --cell (a copy of the example, sometimes mutated)."""
    in_cell = command not in ("external-tcp",) and rng.random() < 0.35
    if in_cell:
        valid = good[f"{command}.csv"].read_text()
    else:
        valid = {"tcp": _tcp_csv, "frame": _frame_csv, "track": _track_csv,
                 "turntable": _turntable_csv, "workpiece": _workpiece_csv,
                 "external-tcp": _external_csv}[command](rng)
    content, what = mutate_csv(valid, rng) if rng.random() < 0.85 else (valid, "valid")
    if rng.random() < 0.3 and isinstance(content, str) and content.count("\n") > 2:
        content, second = mutate_csv(content, rng)
        what += f" + {second}"
    path = _write(d / "m.csv", content)
    args: list = ["calibrate", command, path]
    inputs = [path]
    if in_cell:
        cell = _write(d / "cell.yaml", EXAMPLE.read_text(encoding="utf-8"))
        if rng.random() < 0.2:
            cell, w = _mutated(EXAMPLE.read_text(encoding="utf-8"), rng, d, "cell.yaml")
            what += f"; {w}"
        args += ["--cell", cell, *CELL_OPTIONS[command]]
        inputs.append(cell)
    if command == "workpiece" and (not in_cell or rng.random() < 0.5):
        tt = _write(d / "tt.json", good["world.json" if in_cell else "turntable.json"].read_text())
        if rng.random() < 0.3:
            tt_content, tt_what = mutate_json(tt.read_text(), rng)
            tt = _write(d / "tt.json", tt_content)
            what += f"; turntable.json: {tt_what}"
        args += ["--turntable", tt]
        inputs.append(tt)
    opts = _maybe(rng, 0.25, {"--sigma": BAD_FLOATS + ["0.05"], "--tool": BAD_LISTS + ["torch"],
                              "--robot": ["kuka_kr16", "nosuch", "", str(d / "m.csv")]})
    if command == "turntable":
        opts += _maybe(rng, 0.2, {"--height": BAD_FLOATS + ["-50"]})
    if command == "track":
        opts += _maybe(rng, 0.2, {"--reference": BAD_LISTS + ["1500,800,300"],
                                  "--axis": ["y", "z"], "--roll": ["zero", "one"]})
    if command == "tcp":
        opts += _maybe(rng, 0.1, {"--world": ["5d", "7d"], "--name": ["torch", "bad name", ""]})
    return args + opts, what + " " + " ".join(opts), inputs


#: Options of a calibration into the example cell (what simulate says to pass).
CELL_OPTIONS = {"tcp": ["--name", "pointer"], "frame": ["--name", "fixture", "--tool", "pointer"],
                "track": ["--tool", "pointer", "--reference", "1500,800,300"],
                "turntable": ["--tool", "pointer", "--height=-50"],
                "workpiece": ["--name", "part", "--tool", "pointer"]}


def _external_csv(rng: np.random.Generator) -> str:
    """Touches of a fixed TCP from 5 directions and of points on its +X axis and XY plane."""
    rows = [["tcp", *map(float, [1200.0, 300.0, 500.0] + rng.normal(0, 0.05, 3))] for _ in range(5)]
    rows += [["x", *map(float, [1300.0, 300.0, 500.0] + rng.normal(0, 0.05, 3))],
             ["xy", *map(float, [1200.0, 400.0, 500.0] + rng.normal(0, 0.05, 3))]]
    return _csv(["point", "x", "y", "z"], rows)


def _case(command: str, rng: np.random.Generator, d: Path, good: dict[str, Path]) -> Case:
    """A mutated case of ``command`` in folder ``d``; with probability 0.05 its output file is
    one of its inputs."""
    out = d / f"result{int(rng.integers(0, 3))}.txt"
    together: list = []
    if command in ("tcp", "frame", "external-tcp", "track", "turntable", "workpiece"):
        args, what, inputs = _calibrate(command, rng, d, good)
        if rng.random() < 0.5:
            args, writes = args + ["--json", "-o", out], [out]
        else:
            writes = []
    else:
        args, what, inputs, writes, *together = BUILDERS[command](rng, d, good, out)
    writes = list(writes)
    if "--cell" in args and args[0] == "calibrate":
        cell = Path(args[args.index("--cell") + 1])
        writes += [cell, cell.with_name(cell.name + ".1.bak"), cell.with_name(cell.name + ".lock")]
    args = [str(a) for a in args]
    if inputs and "-o" in args and rng.random() < 0.05:
        onto = inputs[int(rng.integers(0, len(inputs)))]
        args[args.index("-o") + 1] = str(onto)
        what += f"; -o onto the input {Path(onto).name}"
        writes = []
    return Case(args, what, tuple(writes), tuple(together[0]) if together else ())


def _fk(rng, d, good, out):
    content, what = mutate_csv(_joints_csv(rng), rng)
    path = _write(d / "joints.csv", content)
    robot, inputs = "kuka_kr16", [path]
    if rng.random() < 0.2:
        robot, w = _mutated(good["model.yaml"].read_text(), rng, d, "model.yaml")
        inputs.append(robot)
        what += f"; {w}"
    opts = _maybe(rng, 0.2, {"--tool": BAD_LISTS, "--joints": BAD_LISTS + ["0,-90,90,0,0,1e300"]})
    if "--joints" in opts:
        args = ["fk", robot, *opts]
    else:
        args = ["fk", robot, "--input", path, "-o", out, *opts]
    fmt = str(rng.choice(["kuka", "abb", "fanuc", "matrix", "ur"]))
    return [*args, "--format", fmt], f"{what} {' '.join(opts)}", inputs, [out]


def _ik(rng, d, good, out):
    content, what = mutate_csv(_poses_csv(rng), rng)
    path = _write(d / "poses.csv", content)
    extra = ["--all"] if rng.random() < 0.3 else []
    extra += _maybe(rng, 0.25, {"--near": BAD_LISTS + ["0,-90,90,0,0,0", "0,-90,90,0,0,1e6"],
                                "--tool": BAD_LISTS, "--pose": BAD_LISTS + ["1e300,0,0,0,0,0"]})
    if "--pose" in extra:
        return ["ik", "kuka_kr16", *extra], " ".join(extra), [], []
    return (["ik", "kuka_kr16", "--input", path, "-o", out, *extra], f"{what} {' '.join(extra)}",
            [path], [out])


def _cell_file(rng, d, command):
    content, what = mutate_text(EXAMPLE.read_text(encoding="utf-8"), rng)
    path = _write(d / "cell.yaml", content)
    if command == "export":
        fmt = str(rng.choice(["kuka", "abb", "fanuc", "yaskawa"]))
        return None, ["export", "--cell", path, "--format", fmt], what, [path]
    return None, ["cell", "show", path], what, [path]


def _export(rng, d, good, out):
    _, args, what, inputs = _cell_file(rng, d, "export")
    return [*args, "-o", out], what, inputs, [out]


def _cell_show(rng, d, good, out):
    _, args, what, inputs = _cell_file(rng, d, "cell-show")
    return args, what, inputs, []


def _report(rng, d, good, out):
    source = good[str(rng.choice(["turntable.json", "tcp.json", "world.json"]))]
    content, what = mutate_json(source.read_text(), rng)
    path = _write(d / "r.json", content)
    html = d / "r.html"
    return ["report", path, "-o", html], what, [path], [html]


def _mutated(valid: str, rng: np.random.Generator, d: Path, name: str) -> tuple[Path, str]:
    """``valid`` (a CSV when ``name`` ends so, else YAML, URDF or JSON text) mutated, written
    to ``d/name``."""
    content, what = (mutate_csv if name.endswith(".csv") else mutate_text)(valid, rng)
    return _write(d / name, content), f"{name}: {what}"


def _cell_for(command: str, rng, d) -> tuple[Path, str]:
    """The example cell (the positioner's for the positioner commands), mutated in 15 %."""
    text = (POSITIONER if command in ("positioner", "simulate-positioner") else EXAMPLE
            ).read_text(encoding="utf-8")
    if rng.random() < 0.15:
        return _mutated(text, rng, d, "cell.yaml")
    return _write(d / "cell.yaml", text), "valid cell"


def _identify(rng, d, good, out):
    if rng.random() < 0.1:
        n = str(rng.choice(["0", "-1", "2", "5000", "abc", "5"]))
        opts = ["--seed", _bad(rng, ["-1", "abc", "1.5", "7"])] if rng.random() < 0.5 else []
        return (["identify", "--propose", n, "--robot", "kuka_kr16", "-o", out, *opts],
                f"--propose {n} {' '.join(opts)}", [], [out])
    path, what = _mutated(_tracker_csv(rng), rng, d, "tracker.csv")
    opts = _maybe(rng, 0.3, {"--accuracy": BAD_FLOATS, "--angle-accuracy": BAD_FLOATS,
                             "--folds": ["-1", "0", "1", "1000", "abc"],
                             "--j23-factor": BAD_FLOATS + ["-1"]})
    return (["identify", path, "--robot", "kuka_kr16", "-o", out, *opts],
            f"{what} {' '.join(opts)}", [path], [out])


def _reach_sweep(command: str):
    def build(rng, d, good, out):
        cell, what = _cell_for(command, rng, d)
        path, w = _mutated(SEAM.read_text(encoding="utf-8"), rng, d, "seam.csv")
        what += "; " + w
        opts = _maybe(rng, 0.15, {"--table": BAD_FLOATS + ["400"], "--frame": ["nosuch", "world"],
                                  "--tool": ["nosuch", "pointer"]})
        common = ["--frame", "part", "--tool", "torch", *opts]
        if command == "reach":
            opts2 = _maybe(rng, 0.15, {"--track": BAD_FLOATS + ["7000"]})
            return (["reach", "--cell", cell, path, *common, *opts2, "-o", out],
                    f"{what} {' '.join(opts + opts2)}", [cell, path], [out, out.with_suffix(".html")])
        layouts = "robot:\n  y: [-300, 0]\nturntable:\n  a: {from: 0, to: 90, steps: 2}\n"
        lay = _write(d / "layouts.yaml", layouts)
        if rng.random() < 0.5:
            lay, w = _mutated(layouts, rng, d, "layouts.yaml")
            what += "; " + w
        workers = str(rng.choice(["0", "-1", "abc"])) if rng.random() < 0.1 else "1"
        top = _maybe(rng, 0.1, {"--top": ["-1", "0", "abc", "1e300"]})
        return (["sweep", "--cell", cell, "--targets", path, "--layouts", lay, *common, *top,
                 "--workers", workers, "-o", out], f"{what} {' '.join(opts + top)}",
                [cell, path, lay], [out])
    return build


def _positioner(rng, d, good, out):
    path, what = _mutated(good["positioner.csv"].read_text(encoding="utf-8"), rng, d, "touches.csv")
    if rng.random() < 0.5:
        cell, w = _cell_for("positioner", rng, d)
        return (["calibrate", "positioner", path, "--cell", cell, "--tool", "pointer"],
                f"{what}; {w}", [path, cell], [cell, cell.with_name(cell.name + ".1.bak"),
                                               cell.with_name(cell.name + ".lock")])
    return (["calibrate", "positioner", path, "--robot", "kuka_kr16", "--tool",
             "250,0,0,0,0,0", "--json", "-o", out], what, [path], [out])


#: Design options of simulate and plan, with wrong values.
DESIGN = {"--noise": BAD_FLOATS + ["0.1"], "--seed": ["-1", "abc", "1.5", "3"],
          "--touches": ["-1", "0", "1", "100000", "abc"], "--tilt": BAD_FLOATS + ["90"],
          "--size": BAD_FLOATS, "--travel": BAD_FLOATS, "--radius": BAD_FLOATS,
          "--height": BAD_FLOATS, "--angles": BAD_LISTS + ["0,0,0"], "--point": BAD_LISTS,
          "--tilts": BAD_LISTS + ["10,20", "0,0,0"], "--rotates": BAD_LISTS + ["500"],
          "--positions": ["-1", "0", "1", "abc"], "--track": BAD_FLOATS + ["7000"],
          "--repeats": ["-1", "0", "abc"], "--reference": BAD_LISTS}


def _simulate(rng, d, good, out):
    procedure = str(rng.choice(["tcp", "frame", "track", "turntable", "workpiece", "positioner"]))
    cell, what = _cell_for("simulate-positioner" if procedure == "positioner" else procedure,
                           rng, d)
    opts = _maybe(rng, 0.5, DESIGN)
    extra = {"frame": ["--frame", "fixture"], "workpiece": ["--frame", "part"]}.get(procedure, [])
    return (["simulate", procedure, "--cell", cell, "--tool", "pointer", *extra, "-o", out,
             *opts], f"{procedure}: {what} {' '.join(opts)}", [cell], [out])


def _plan(rng, d, good, out):
    procedure = str(rng.choice(["tcp", "track"]))
    cell, what = _cell_for(procedure, rng, d)
    opts = _maybe(rng, 0.8, {**{k: DESIGN[k] for k in ("--noise", "--seed", "--touches",
                                                         "--track")},
                             "--runs": ["-1", "abc", "1e300"], "--max-size": BAD_FLOATS,
                             "--max-radius": BAD_FLOATS})
    return (["plan", procedure, "--cell", cell, "--tool", "pointer", "--runs", "0", *opts,
             "-o", out], f"{procedure}: {what} {' '.join(opts)}", [cell], [out])


def _fk_ik_cell(command: str):
    def build(rng, d, good, out):
        positioner = rng.random() < 0.5
        cell, what = _cell_for("positioner" if positioner else command, rng, d)
        if command == "fk-cell":
            path, what = _mutated(_cell_joints_csv(rng, positioner), rng, d, "joints.csv")
            opts = _maybe(rng, 0.2, {"--track": BAD_FLOATS + ["7000"], "--table": BAD_LISTS})
            return (["fk", "--cell", cell, "--input", path, "--frame", "part", "--tool", "torch",
                     "-o", out, *opts], f"{what} {' '.join(opts)}", [cell, path], [out])
        path, what = _mutated(_poses_csv(rng), rng, d, "poses.csv")
        table = str(rng.choice(["normal-up", "10,20", "10", _bad(rng)])) if positioner else \
            str(rng.choice(["150", "90", _bad(rng)]))
        opts = _maybe(rng, 0.15, {"--track": BAD_FLOATS + ["7000"]})
        return (["ik", "--cell", cell, "--input", path, "--frame", "part", "--tool", "torch",
                 "--table", table, "-o", out, *opts], f"{what} --table {table} {' '.join(opts)}",
                [cell, path], [out])
    return build


def _urdf(rng, d, good, out):
    cell, what = _mutated((POSITIONER if rng.random() < 0.3 else EXAMPLE).read_text("utf-8"),
                          rng, d, "cell.yaml")
    return ["export", "--cell", cell, "--format", "urdf", "-o", out], what, [cell], [out]


def _dh_from_urdf(rng, d, good, out):
    path, what = _mutated(URDF.read_text(encoding="utf-8"), rng, d, "arm.urdf")
    opts = _maybe(rng, 0.2, {"--signs": BAD_LISTS + ["1,-1,1,1,1,1"],
                             "--tip-link": ["nosuch", "base_link"], "--base-link": ["nosuch"]})
    conv = str(rng.choice(["standard", "modified"]))
    return (["dh", "from-urdf", path, "--convention", conv, "-o", out, *opts],
            f"{what} {' '.join(opts)}", [path], [out])


def _dh_convert(rng, d, good, out):
    path, what = _mutated(good["model.yaml"].read_text(), rng, d, "model.yaml")
    return (["dh", "convert", path, "--to", str(rng.choice(["standard", "modified"])), "-o", out],
            what, [path], [out])


def _robots_show(rng, d, good, out):
    path, what = _mutated(good["model.yaml"].read_text(), rng, d, "model.yaml")
    return ["robots", "show", path], what, [path], []


def _demo(rng, d, good, out):
    opts = _maybe(rng, 1.0, {"--noise": ["-1", "0", "nan", "inf", "-inf", "abc", "", "1e-300"],
                             "--seed": ["-1", "abc", "1.5", ""]})
    return ["demo", "-o", d / "demo", *opts], " ".join(opts), [], [d / "demo"]


def _view(kind: str):
    """view CELL (options mutated), view --reach REACH.csv (the CSV mutated), view --program
    PROGRAM (a KUKA, ABB or FANUC program of the example seam, one of its files mutated)."""
    def build(rng, d, good, out):
        cell, what = _cell_for("view", rng, d)
        html = d / "view.html"
        inputs = [cell]
        if kind == "cell":
            opts = _maybe(rng, 0.7, {"--joints": BAD_LISTS + ["0,-90,90,0,45,0", "0,-90,90,0,0,400"],
                                     "--track": BAD_FLOATS + ["7000", "1500"],
                                     "--table": BAD_LISTS + ["30", "400", "30,90"],
                                     "--tool": ["torch"]})
        elif kind == "reach":
            path, w = _mutated(good["reach.csv"].read_text(encoding="utf-8"), rng, d, "reach.csv")
            what += "; " + w
            inputs.append(path)
            opts = ["--reach", path, "--tool", "torch",
                    *_maybe(rng, 0.2, {"--track": BAD_FLOATS + ["2324"],
                                       "--table": BAD_LISTS + ["150"]})]
        else:
            vendor = str(rng.choice(["kuka", "abb", "fanuc"]))
            files = [Path(shutil.copy(f, d)) for f in sorted(good[f"prog_{vendor}"].iterdir())]
            target = files[int(rng.integers(0, len(files)))]
            if rng.random() < 0.85:
                content, w = mutate_text(target.read_text(encoding="utf-8"), rng)
                _write(target, content)
                what += f"; {target.name}: {w}"
            main = next(f for f in files if f.suffix.lower() in (".src", ".mod", ".ls"))
            inputs += files
            opts = ["--program", main,
                    *_maybe(rng, 0.15, {"--joints": ["0,-90,90,0,45,0"], "--track": ["100"],
                                        "--pulses-per-degree": BAD_LISTS + ["100"],
                                        "--reach": [str(cell)]})]
        return (["view", cell, *opts, "-o", html], f"{what} {' '.join(map(str, opts))}", inputs,
                [html])
    return build


def _cell_history(rng, d, good, out):
    """cell history CELL: the cell file and up to three numbered backups, any of them mutated
    (a version that cannot be read is listed as such); or no cell file at all (refused unless a
    backup is left)."""
    text = EXAMPLE.read_text(encoding="utf-8")
    cell, what = _cell_for("cell-history", rng, d)
    inputs, backups = [cell], int(rng.integers(0, 4))
    if rng.random() < 0.2:  # half of them with no backup either: the one refusal of the command
        cell.unlink()
        what, inputs, backups = "no cell file", [], backups * int(rng.integers(0, 2))
    for k in range(1, backups + 1):
        backup = d / f"cell.yaml.{k}.bak"
        if rng.random() < 0.3:
            backup, w = _mutated(text, rng, d, backup.name)
            what += f"; {w}"
        else:
            _write(backup, text)
        inputs.append(backup)
    return ["cell", "history", cell], what, inputs, []


BUILDERS = {"fk": _fk, "ik": _ik, "export": _export, "cell-show": _cell_show, "report": _report,
            "identify": _identify, "reach": _reach_sweep("reach"), "sweep": _reach_sweep("sweep"),
            "positioner": _positioner, "simulate": _simulate, "plan": _plan,
            "fk-cell": _fk_ik_cell("fk-cell"), "ik-cell": _fk_ik_cell("ik-cell"), "urdf": _urdf,
            "dh-from-urdf": _dh_from_urdf, "dh-convert": _dh_convert,
            "robots-show": _robots_show, "demo": _demo, "view": _view("cell"),
            "view-reach": _view("reach"), "view-program": _view("program"),
            "cell-history": _cell_history}


# -- the cell file's safety: the whole-cell refit, a lock left behind, links ----------------------
def _calibrated(good: dict[str, Path]) -> Path:
    """A folder with a copy of the example cell whose tool pointer and frame fixture are
    calibrated from the touch files tcp.csv and frame.csv beside it (made once)."""
    from robotcell.cell import Cell
    from robotcell.cell import calibrate as cellcal

    folder = good["tcp.csv"].parent / "calibrated"
    if not folder.is_dir():
        folder.mkdir()
        shutil.copy(EXAMPLE, folder / "cell.yaml")
        for name in ("tcp.csv", "frame.csv"):
            shutil.copy(good[name], folder / name)
        cell = cellcal.tcp(Cell.load(folder / "cell.yaml"), folder / "tcp.csv", "pointer").cell
        cell = cellcal.frame(cell, folder / "frame.csv", "fixture", tool="pointer").cell
        cell.save(folder / "cell.yaml")
        for kept in folder.glob("cell.yaml.*"):  # its backup and lock file
            kept.unlink()
    return folder


def _cell_writes(cell: Path, backup: int = 1) -> list[Path]:
    """What an update of ``cell`` writes: the file, its next backup, its lock file."""
    return [cell, cell.with_name(f"{cell.name}.{backup}.bak"), cell.with_name(cell.name + ".lock")]


def _cell_refit(rng, d, good, out):
    """calibrate cell on a calibrated cell: a touch file or the cell mutated; -o as text, as
    JSON, named for another kind, onto a touch file or onto the cell through a link."""
    for f in _calibrated(good).iterdir():
        shutil.copy(f, d / f.name)
    cell, touches = d / "cell.yaml", [d / "tcp.csv", d / "frame.csv"]
    what = "valid"
    if rng.random() < 0.3:
        target = touches[int(rng.integers(0, 2))]
        content, w = mutate_csv(target.read_text(), rng)
        _write(target, content)
        what = f"{target.name}: {w}"
    elif rng.random() < 0.2:
        cell, what = _mutated(cell.read_text(), rng, d, "cell.yaml")
    kind = str(rng.choice(["none", "json", "text", "json-name", "touch", "link"]))
    outputs, options = [], []
    if kind == "json":
        outputs, options = [d / "res.json"], ["--json", "-o", d / "res.json"]
    elif kind == "text":
        outputs, options = [out], ["-o", out]
    elif kind == "json-name":
        options = ["-o", d / "res.json"]
        what += "; -o res.json without --json (never written)"
    elif kind == "touch":
        onto = touches[int(rng.integers(0, 2))]
        options, what = ["--json", "-o", onto], what + f"; -o onto the input {onto.name}"
    elif kind == "link":
        os.symlink("cell.yaml", d / "view.txt")
        options, what = ["-o", d / "view.txt"], what + "; -o onto the input cell.yaml, linked"
    return (["calibrate", "cell", "--cell", cell, *options], what, [cell, *touches],
            _cell_writes(cell) + outputs)


def _cell_lock(rng, d, good, out):
    """calibrate tcp into a cell whose lock file a killed process left (empty, or with bytes in
    it), whose lock file is a folder (refused), or whose backups have gaps."""
    cell = _write(d / "cell.yaml", EXAMPLE.read_text(encoding="utf-8"))
    content, what = mutate_csv(good["tcp.csv"].read_text(), rng) if rng.random() < 0.5 else \
        (good["tcp.csv"].read_text(), "valid")
    touches = _write(d / "tcp.csv", content)
    lock = cell.with_name("cell.yaml.lock")
    kind = str(rng.choice(["left", "junk", "folder", "gaps"]))
    backup = 1
    if kind == "left":
        lock.touch()
    elif kind == "junk":
        _write(lock, bytes(rng.integers(0, 256, 50, dtype=np.uint8)))
    elif kind == "folder":
        lock.mkdir()
        what += " (never written)"
    else:
        for k in (1, 3):
            _write(cell.with_name(f"cell.yaml.{k}.bak"), EXAMPLE.read_text(encoding="utf-8"))
        backup = 4
    return (["calibrate", "tcp", touches, "--cell", cell, "--name", "pointer"],
            f"{what}; lock {kind}", [cell, touches], _cell_writes(cell, backup))


def _cell_link(rng, d, good, out):
    """calibrate tcp into a cell given through a symbolic link (written where it points) or a
    hard link (refused), sometimes with -o through a symbolic link."""
    (d / "shared").mkdir()
    real = _write(d / "shared" / "cell.yaml", EXAMPLE.read_text(encoding="utf-8"))
    content, what = mutate_csv(good["tcp.csv"].read_text(), rng) if rng.random() < 0.4 else \
        (good["tcp.csv"].read_text(), "valid")
    touches = _write(d / "tcp.csv", content)
    cell, writes = d / "cell.yaml", _cell_writes(real) + [d / "cell.yaml"]
    if rng.random() < 0.3:
        os.link(real, cell)
        what, writes = what + "; --cell with 2 hard links (never written)", []
    else:
        os.symlink(os.path.join("shared", "cell.yaml"), cell)
        what += "; --cell through a link"
    options = []
    if rng.random() < 0.4:
        os.symlink(os.path.join("shared", "res.json"), d / "res.json")
        options = ["--json", "-o", d / "res.json"]
        writes += [d / "res.json", d / "shared" / "res.json"]  # (the link reads as its target)
        what += "; -o through a link"
    return (["calibrate", "tcp", touches, "--cell", cell, "--name", "pointer", *options], what,
            [cell, touches], writes)


CASES.update({"cell-refit": (3, 30), "cell-lock": (3, 30), "cell-link": (3, 30)})
BUILDERS.update({"cell-refit": _cell_refit, "cell-lock": _cell_lock, "cell-link": _cell_link})


# -- the ISO 9283 test: plan, analyse, simulate --------------------------------------------------
def _mutate_log(text: str, rng: np.random.Generator) -> tuple[bytes | str, str]:
    """A mutation of a measurement log: one a log of ISO 9283 can have (a pose the plan lacks,
    too few cycles, one value in metres, a NaN, a column missing), else a CSV mutation."""
    rows = _split(text)
    head = rows[0]
    i = int(rng.integers(1, len(rows)))
    kind = str(rng.choice(["unknown-pose", "few-cycles", "metres-value", "nan", "no-column",
                           "csv", "csv", "csv"]))
    if kind == "unknown-pose":
        rows[i][head.index("pose")] = str(rng.choice(["P6", "p1", "", "line_3", "arc"]))
    elif kind == "few-cycles":
        rows = [head, *(r for r in rows[1:] if r[0] in ("1", "2", "3"))]
    elif kind == "metres-value":
        j = head.index(str(rng.choice(["x", "y", "z"])))
        rows[i][j] = repr(float(rows[i][j]) / 1e3)
    elif kind == "nan":
        rows[i][int(rng.integers(0, len(head)))] = "nan"
    elif kind == "no-column":
        j = head.index(str(rng.choice(["cycle", "pose", "x", "a"])))
        rows = [r[:j] + r[j + 1:] for r in rows]
    else:
        return mutate_csv(text, rng)
    return _join(rows), kind


#: Options of ``iso9283 analyse`` mutated (limits without -o: a FAIL writes its report).
ISO_LIMITS = {"--limit-ap": BAD_FLOATS + ["0.001", "5"], "--limit-rp": BAD_FLOATS + ["5"],
              "--limit-at": BAD_FLOATS, "--limit-rt": BAD_FLOATS}


def _iso_analyse(rng, d, good, out):
    """iso9283 analyse: the log (mostly) or the plan mutated; a limit, or the report written."""
    meas, plan = d / "meas.csv", d / "plan.csv"
    shutil.copy(good["iso_plan.csv"], plan)
    if rng.random() < 0.8:
        content, what = _mutate_log(good["iso_meas.csv"].read_text(), rng)
        _write(meas, content)
        what = f"meas.csv: {what}"
    else:
        shutil.copy(good["iso_meas.csv"], meas)
        plan, what = _mutated(good["iso_plan.csv"].read_text(), rng, d, "plan.csv")
    opts = _maybe(rng, 0.3, ISO_LIMITS) + (["--device-frame"] if rng.random() < 0.1 else [])
    report = d / "report.html"
    output = [] if any(o.startswith("--limit") for o in opts) else ["-o", report]
    json_flag = ["--json"] if rng.random() < 0.5 else []
    return (["iso9283", "analyse", meas, "--plan", plan, *json_flag, *opts, *output],
            f"{what} {' '.join(opts)}", [meas, plan], [report] if output else [])


def _iso_plan(rng, d, good, out):
    """iso9283 plan of a 400 mm cube (fast), the cell or an option mutated, sometimes with the
    KUKA programs."""
    cell, what = _cell_for("iso9283-plan", rng, d)
    opts = _maybe(rng, 0.7, {"--size": BAD_FLOATS + ["5000", "1"], "--centre": BAD_LISTS,
                             "--orientation": BAD_LISTS, "--track": BAD_FLOATS + ["7000"],
                             "--table": BAD_LISTS, "--cycles": ["-1", "0", "abc", "1e300"],
                             "--path-cycles": ["-1", "abc"], "--speed": BAD_FLOATS,
                             "--frame": ["nosuch", "part"], "--tool": ["nosuch", ""]})
    size = [] if "--size" in opts else ["--size", "400"]
    tool = [] if "--tool" in opts else ["--tool", "torch"]
    plan_out = d / "plan_out.csv"
    progs = ["--programs", d / "prog", "--format", "kuka"] if rng.random() < 0.3 else []
    return (["iso9283", "plan", "--cell", cell, *tool, *size, *opts, "-o", plan_out, *progs],
            f"{what} {' '.join(opts)}", [cell], [plan_out, d / "prog"])


def _simulate_iso(rng, d, good, out):
    """simulate iso9283: the true cell or the plan mutated, or an option."""
    cell, what = _cell_for("simulate-iso9283", rng, d)
    plan = d / "plan.csv"
    if rng.random() < 0.3:
        plan, w = _mutated(good["iso_plan.csv"].read_text(), rng, d, "plan.csv")
        what = f"{what}; {w}"
    else:
        shutil.copy(good["iso_plan.csv"], plan)
    opts = _maybe(rng, 0.6, {"--noise": BAD_FLOATS, "--angle-noise": BAD_FLOATS,
                             "--cycles": ["-1", "0", "9", "abc", "100000"],
                             "--path-cycles": ["-1", "5", "abc"], "--spacing": BAD_FLOATS,
                             "--seed": ["-1", "abc", "1.5"]})
    log = d / "meas_out.csv"
    return (["simulate", "iso9283", "--cell", cell, "--plan", plan, "--spacing", "10", *opts,
             "-o", log], f"{what} {' '.join(opts)}", [cell, plan], [log])


CASES.update({"iso9283-analyse": (6, 80), "iso9283-plan": (2, 20), "simulate-iso9283": (3, 30)})
BUILDERS.update({"iso9283-analyse": _iso_analyse, "iso9283-plan": _iso_plan,
                 "simulate-iso9283": _simulate_iso})


TWO_ROBOTS = EXAMPLES / "cell_two_robots_positioner.yaml"


@functools.lru_cache(maxsize=1)
def _robot_to_robot_tables() -> tuple[str, str]:
    """The two robots of the two-robot example touching 5 common points twice with their torches
    (joint values, 0.05 mm touch error): the reference (kuka, its track at 0) and the other."""
    from robotcell.cell import Cell
    from robotcell.kinematics.transforms import invert
    from robotcell.studies.robottorobot import (
        SimulatedRobot,
        default_points,
        simulate_robot_to_robot,
        table_text,
    )

    cell = Cell.load(TWO_ROBOTS)
    kuka, abb = cell.for_robot("kuka"), cell.for_robot("abb")
    T = invert(kuka.frame_pose("robot")) @ abb.frame_pose("robot")
    robots = [SimulatedRobot(kuka.robot, np.eye(4), kuka.tools["torch"].T_F_TCP, "kuka"),
              SimulatedRobot(abb.robot, T, abb.tools["torch"].T_F_TCP, "abb")]
    tables = simulate_robot_to_robot(robots, default_points(T), noise=5e-5,
                                     rng=np.random.default_rng(SEED), repeats=2)
    return table_text(tables[0]), table_text(tables[1])


def _robot_to_robot(rng, d, good, out):
    """calibrate robot-to-robot: one robot's touches mutated, with the two-robot cell (mutated
    in 15 %) or with the models and tools given, and an option sometimes wrong."""
    ref_text, other_text = _robot_to_robot_tables()
    ref, what = ((_mutated(ref_text, rng, d, "r1.csv")) if rng.random() < 0.5
                 else (_write(d / "r1.csv", ref_text), "r1.csv valid"))
    other, w = ((_mutated(other_text, rng, d, "r2.csv")) if rng.random() < 0.7
                else (_write(d / "r2.csv", other_text), "r2.csv valid"))
    what += f"; {w}"
    inputs = [ref, other]
    if rng.random() < 0.5:
        cell = _write(d / "cell.yaml", TWO_ROBOTS.read_text(encoding="utf-8"))
        if rng.random() < 0.15:
            cell, w = _mutated(TWO_ROBOTS.read_text(encoding="utf-8"), rng, d, "cell.yaml")
            what += f"; {w}"
        args = ["--cell", cell, "--robot", "abb", "--reference", "kuka", "--tool-ref", "torch",
                "--tool-other", "torch"]
        inputs.append(cell)
        opts = _maybe(rng, 0.3, {"--robot": ["kuka", "nosuch", ""], "--tool-other": ["nosuch"],
                                 "--track-ref": BAD_FLOATS + ["9000"],
                                 "--track-other": ["100", "abc"]})
    else:
        args = ["--robot-ref", "kuka_kr16", "--tool-ref", "312.5,-1.2,95,0,45,0",
                "--robot-other", "abb_irb2400", "--tool-other", "300,0,90,0,45,0"]
        opts = _maybe(rng, 0.3, {"--tool-ref": BAD_LISTS, "--robot-other": ["nosuch", ""],
                                 "--reference": ["kuka"]})
    opts += _maybe(rng, 0.2, {"--sigma": BAD_FLOATS + ["0.05"],
                              "--tool-sigma": BAD_FLOATS + ["0.2"]})
    json_out = ["--json", "-o", out] if rng.random() < 0.4 else []
    return (["calibrate", "robot-to-robot", ref, other, *args, *opts, *json_out],
            f"{what} {' '.join(opts)}", inputs, [out] if json_out else [])


def _program_bodies(rng, d, good, out):
    """program check --bodies: the example's bodies file mutated, or a clearance option."""
    text = (EXAMPLES / "bodies_kr16_track_turntable.yaml").read_text(encoding="utf-8")
    bodies, what = ((_mutated(text, rng, d, "bodies.yaml")) if rng.random() < 0.8
                    else (_write(d / "bodies.yaml", text), "bodies.yaml valid"))
    opts = _maybe(rng, 0.3, {"--clearance": BAD_FLOATS + ["2000", "180"]})
    shutil.copytree(good["prog_kuka"], d / "prog")
    src = next((d / "prog").glob("*.src"))
    return (["program", "check", src, "--cell", EXAMPLE, "--bodies", bodies, *opts],
            f"{what} {' '.join(opts)}", [bodies, d / "prog"], [])


CASES.update({"robot-to-robot": (4, 60), "program-bodies": (3, 40)})
BUILDERS.update({"robot-to-robot": _robot_to_robot, "program-bodies": _program_bodies})


@functools.lru_cache(maxsize=1)
def _shared_positioner_tables() -> tuple[str, str, str, str]:
    """The two robots of the two-robot example, the KUKA at track 1000 mm: each touching its own
    point on the positioner's plate at 3 tilt by 4 rotate values, then 5 common points twice
    (joint values, 0.05 mm touch error)."""
    import io

    from robotcell.cell import Cell
    from robotcell.kinematics.transforms import invert
    from robotcell.studies.robottorobot import (
        SimulatedRobot,
        default_points,
        simulate_robot_to_robot,
        table_text,
    )
    from robotcell.studies.simulate import simulate

    cell = Cell.load(TWO_ROBOTS)
    rng = np.random.default_rng(SEED)
    kuka, abb = cell.for_robot("kuka"), cell.for_robot("abb")
    plates = []
    for view, track, radius in ((kuka, 1.0, 0.2), (abb, None, 0.15)):
        buf = io.StringIO()
        simulate(view, "positioner", noise=5e-5, seed=rng, tool="torch", track=track,
                 radius=radius).write_csv(buf)
        plates.append(buf.getvalue())
    T = invert(kuka.frame_pose("robot", track=1.0)) @ abb.frame_pose("robot")
    robots = [SimulatedRobot(kuka.robot, np.eye(4), kuka.tools["torch"].T_F_TCP, "kuka"),
              SimulatedRobot(abb.robot, T, abb.tools["torch"].T_F_TCP, "abb")]
    tables = simulate_robot_to_robot(robots, default_points(T), noise=5e-5, rng=rng, repeats=2)
    return plates[0], plates[1], table_text(tables[0]), table_text(tables[1])


def _shared_positioner(rng, d, good, out):
    """calibrate shared-positioner: one of the four touch files mutated (or the cell, in 15 %),
    and an option sometimes wrong."""
    texts = _shared_positioner_tables()
    names = ["pos_kuka.csv", "pos_abb.csv", "r2r_kuka.csv", "r2r_abb.csv"]
    bad = int(rng.integers(len(names) + 1))
    files, what = [], []
    for k, (name, text) in enumerate(zip(names, texts, strict=True)):
        if k == bad:
            path, w = _mutated(text, rng, d, name)
            what.append(w)
        else:
            path = _write(d / name, text)
        files.append(path)
    cell = _write(d / "cell.yaml", TWO_ROBOTS.read_text(encoding="utf-8"))
    if rng.random() < 0.15:
        cell, w = _mutated(TWO_ROBOTS.read_text(encoding="utf-8"), rng, d, "cell.yaml")
        what.append(w)
    opts = _maybe(rng, 0.3, {"--robot": ["kuka", "nosuch", ""], "--tool-other": ["nosuch"],
                             "--track-ref": BAD_FLOATS + ["0", "9000"],
                             "--sigma": BAD_FLOATS + ["0.05"],
                             "--tool-sigma": BAD_FLOATS + ["0.2"]})
    json_out = ["-o", out] if rng.random() < 0.4 else []
    args = ["calibrate", "shared-positioner", files[0], files[1], "--common", files[2], files[3],
            "--cell", cell, "--reference", "kuka", "--robot", "abb", "--tool-ref", "torch",
            "--tool-other", "torch", "--track-ref", "1000", *opts, *json_out]
    return (args, f"{'; '.join(what) or 'all valid'} {' '.join(opts)}", [*files, cell],
            [out] if json_out else [])


CASES.update({"shared-positioner": (3, 30)})
BUILDERS.update({"shared-positioner": _shared_positioner})


# -- programs and calibrations of two robots: coordinated programs, their view, identify and
# -- the shared positioner into a cell, planning the common points -----------------------------
TWO_YASKAWA = EXAMPLES / "cell_two_yaskawa_positioner.yaml"
TWO_ABB = EXAMPLES / "cell_two_abb_positioner.yaml"
#: The example paths of the coordinated programs (file names in the case's folder -> examples).
YASKAWA_SEAMS = {"rob1": "seam_rob1_floor.csv", "rob2": "seam_rob2.csv"}
TIMED_SEAMS = {"rob1": "seam_rob1_timed.csv", "rob2": "seam_rob2_timed.csv"}


@functools.lru_cache(maxsize=2)
def _coordinated_texts(vendor: str) -> dict[str, str]:
    """The example's coordinated program (file name -> text): the YASKAWA job of the two-robot
    YASKAWA cell (100 pulses per degree) or the ABB MultiMove modules of the two-ABB cell."""
    import tempfile

    from robotcell.cell import Cell
    from robotcell.programs.coordinated import write_coordinated

    yaskawa = vendor == "yaskawa"
    seams = YASKAWA_SEAMS if yaskawa else {"rob1": "seam_rob1.csv", "rob2": "seam_rob2.csv"}
    with tempfile.TemporaryDirectory() as folder:
        files = write_coordinated({r: EXAMPLES / f for r, f in seams.items()},
                                  Cell.load(TWO_YASKAWA if yaskawa else TWO_ABB),
                                  {"rob1": "torch", "rob2": "torch"}, "part", vendor, folder,
                                  "seams", pulses_per_degree=[100, 100] if yaskawa else None
                                  ).files
        return {Path(f).name: Path(f).read_text(encoding="utf-8") for f in files}


def _mutate_job(text: str, rng: np.random.Generator) -> tuple[str, str]:
    """A mutation of a YASKAWA job of two robots: a line dropped, group 2's ``+MOVJ``/``+MOVL``
    part removed, a group line changed, a station position in group 2's part, a number of a
    position garbled; else a text mutation."""
    lines = text.splitlines()
    moves = [i for i, line in enumerate(lines) if line.startswith("MOV")]
    kind = str(rng.choice(["drop-line", "drop-plus", "group", "station-in-plus",
                           "garble-number", "text"]))
    if kind == "drop-line":
        i = int(rng.integers(0, len(lines)))
        what = f"line {i + 1} dropped ({lines.pop(i)[:20]})"
    elif kind == "drop-plus":
        i = moves[int(rng.integers(0, len(moves)))]
        lines[i] = lines[i].split("  +")[0]
        what = f"line {i + 1} without its +MOV"
    elif kind == "group":
        group = str(rng.choice(["///GROUP1", "///GROUP2"]))
        i = next(k for k, line in enumerate(lines) if line.startswith(group))
        lines[i] = str(rng.choice(["///GROUP1 RB1", "///GROUP1 RB2,ST1", "///GROUP2 RB1",
                                   "///GROUP2 RB2,ST1", "///GROUP1 RB1,ST1,ST2", "///GROUP3 RB3",
                                   "///GROUP1", ""]))
        what = f"group line {i + 1} -> {lines[i]!r}"
    elif kind == "station-in-plus":
        i = moves[int(rng.integers(0, len(moves)))]
        lines[i] = re.sub(r"(\+MOV\w C\d+)", r"\1 EC00000", lines[i])
        what = f"line {i + 1}: EC in group 2's part"
    elif kind == "garble-number":
        i = [k for k, line in enumerate(lines) if re.match(r"E?C\d+=", line)]
        i = i[int(rng.integers(0, len(i)))]
        head, values = lines[i].split("=")
        values = values.split(",")
        values[int(rng.integers(0, len(values)))] = str(rng.choice(
            ["nan", "", "abc", "1e300", "-9999999", "1.2.3", "١٢", "inf"]))
        lines[i] = head + "=" + ",".join(values)
        what = f"line {i + 1} garbled: {lines[i]}"
    else:
        content, what = mutate_text(text, rng)
        return content, what
    return "\n".join(lines) + "\n", what


def _copy_seams(d: Path, seams: dict[str, str]) -> dict[str, Path]:
    return {robot: Path(shutil.copy(EXAMPLES / name, d / name)) for robot, name in seams.items()}


def _write_coordinated_args(files: dict[str, Path], cell: Path, d: Path,
                            ppd: str = "100,100") -> list:
    return ["program", "write-coordinated", *(f"{r}={f}" for r, f in files.items()), "--cell",
            cell, "--tool", "torch", "--frame", "part", "--format", "yaskawa",
            "--pulses-per-degree", ppd, "-o", d / "prog", "--name", "seams"]


def _coordinated_yaskawa(rng, d, good, out):
    """program write-coordinated --format yaskawa (a path file mutated, or --pulses-per-degree
    wrong), or program check-coordinated of the written job mutated."""
    ppd = str(rng.choice(BAD_LISTS + ["100", "100,100,100", "0,0", "-100,100", "1e300,100"])
              ) if rng.random() < 0.2 else "100,100"
    if rng.random() < 0.5:
        files = _copy_seams(d, YASKAWA_SEAMS)
        robot = str(rng.choice(sorted(files)))
        _, what = _mutated(files[robot].read_text(encoding="utf-8"), rng, d, files[robot].name)
        if rng.random() < 0.1:  # a robot the cell lacks, or one robot twice
            files = {"rob1": files["rob1"], str(rng.choice(["rob3", "rob1 ", ""])): files["rob2"]}
            what += f"; robots {', '.join(map(repr, files))}"
        return (_write_coordinated_args(files, TWO_YASKAWA, d, ppd), f"{what}; ppd {ppd}",
                list(files.values()), [d / "prog"])
    job = d / "SEAMS.jbi"
    content, what = _mutate_job(_coordinated_texts("yaskawa")["SEAMS.jbi"], rng)
    _write(job, content)
    robots = _maybe(rng, 0.1, {"--robots": ["rob2,rob1", "rob1", "rob1,rob3", ""]})
    return (["program", "check-coordinated", job, "--cell", TWO_YASKAWA,
             "--pulses-per-degree", ppd, *robots], f"{what}; ppd {ppd} {' '.join(robots)}",
            [job], [])


def _mutate_times(text: str, rng: np.random.Generator) -> tuple[bytes | str, str]:
    """A mutation of a timed path file: a time not increasing, NaN, empty, negative, huge, the
    column dropped or misspelt, a ``lin`` made ``ptp``; else a CSV mutation."""
    rows = _split(text)
    t = rows[0].index("time")
    i = int(rng.integers(1, len(rows)))
    kind = str(rng.choice(["not-increasing", "same-time", "time-value", "no-time",
                           "misspelt-time", "ptp", "csv"]))
    if kind == "not-increasing":
        k = int(rng.integers(1, len(rows)))
        rows[i][t], rows[k][t] = rows[k][t], rows[i][t]
        if i == k:
            rows[i][t] = str(float(rows[i][t]) - 3.0)
    elif kind == "same-time":
        k = min(i + 1, len(rows) - 1) if i < len(rows) - 1 else i - 1
        rows[i][t] = rows[k][t]
    elif kind == "time-value":
        rows[i][t] = str(rng.choice(["nan", "NaN", "", "-1", "inf", "1e300", "abc", "1e-7",
                                     "10.0000001", "1,5"]))
    elif kind == "no-time":
        rows = [r[:t] + r[t + 1:] for r in rows]
    elif kind == "misspelt-time":
        rows[0][t] = str(rng.choice(["Time", "time_s", "t", "tiem"]))
    elif kind == "ptp":
        rows[i][rows[0].index("motion")] = "ptp"
    else:
        return mutate_csv(text, rng)
    return _join(rows), f"{kind} line {i + 1}"


def _coordinated_timed(rng, d, good, out):
    """program write-coordinated of the timed example paths (YASKAWA cell): the times of one
    file (or both) mutated."""
    files = _copy_seams(d, TIMED_SEAMS)
    what = []
    for robot in sorted(files):
        if rng.random() < 0.6 or (robot == "rob2" and not what):
            content, w = _mutate_times(files[robot].read_text(encoding="utf-8"), rng)
            _write(files[robot], content)
            what.append(f"{files[robot].name}: {w}")
    return (_write_coordinated_args(files, TWO_YASKAWA, d), "; ".join(what),
            list(files.values()), [d / "prog"])


def _view_coordinated(rng, d, good, out):
    """view CELL --program A --program B [--bodies B.yaml]: the ABB MultiMove example, one
    module or the bodies file mutated, or an option wrong; the page is written whole or not."""
    modules = {name: _write(d / name, text)
               for name, text in _coordinated_texts("abb").items()}
    files = [modules[name] for name in sorted(modules)]
    bodies_text = (EXAMPLES / "bodies_two_robots_positioner.yaml").read_text(encoding="utf-8")
    bodies = _write(d / "bodies.yaml", bodies_text)
    what = "valid"
    kind = rng.random()
    if kind < 0.5:
        target = files[int(rng.integers(0, len(files)))]
        content, w = mutate_text(target.read_text(encoding="utf-8"), rng)
        if rng.random() < 0.5:  # the MultiMove structure broken
            lines = target.read_text(encoding="utf-8").splitlines()
            sync = [i for i, line in enumerate(lines) if "\\ID:=" in line or "SyncMove" in line]
            i = sync[int(rng.integers(0, len(sync)))]
            new = str(rng.choice(["", "\\ID:=15", "\\ID:=abc"]))
            lines[i] = (re.sub(r"\\ID:=\d+", lambda _: new, lines[i]) if "\\ID:=" in lines[i]
                        else "")
            content, w = "\n".join(lines) + "\n", f"line {i + 1} -> {lines[i].strip()!r}"
        _write(target, content)
        what = f"{target.name}: {w}"
    elif kind < 0.8:
        bodies, what = _mutated(bodies_text, rng, d, "bodies.yaml")
    opts = ["--bodies", bodies] if rng.random() < 0.7 or "bodies" in what else []
    opts += _maybe(rng, 0.3, {"--clearance": BAD_FLOATS + ["3"],
                              "--robots": ["rob2,rob1", "rob1", "rob1,rob3", "", "rob1,rob1"]})
    programs = [a for f in files for a in ("--program", f)]
    if rng.random() < 0.1:
        programs, what = programs[:2], what + "; one --program"
    html = d / "view.html"
    return (["view", TWO_ABB, *programs, *opts, "-o", html], f"{what} {' '.join(map(str, opts))}",
            [*files, bodies], [html])


def _identify_robot_name(rng, d, good, out):
    """identify --cell CELL --robot-name NAME -o ARM.yaml on the two-robot cell: the tracker's
    rows (of the nominal KR 16) mutated, or the name wrong; the cell and the model file are
    written together or neither is."""
    cell = _write(d / "cell.yaml", TWO_ROBOTS.read_text(encoding="utf-8"))
    content, what = mutate_csv(_tracker_csv(rng), rng) if rng.random() < 0.7 else \
        (_tracker_csv(rng), "valid")
    tracker = _write(d / "tracker.csv", content)
    name = str(rng.choice(["kuka"] * 6 + ["abb", "nope", "", "KUKA", "kuka "]))
    robot = ["--robot", "kuka_kr16"] if rng.random() < 0.5 else []
    opts = _maybe(rng, 0.15, {"--folds": ["0", "1", "abc"], "--sigma": BAD_FLOATS})
    arm = d / "arm.yaml"
    return (["identify", tracker, *robot, "--cell", cell, "--robot-name", name,
             *opts, "-o", arm], f"{what}; --robot-name {name!r} {' '.join(robot + opts)}",
            [cell, tracker], [arm, *_cell_writes(cell)], (cell, arm))


def _shared_positioner_cell(rng, d, good, out):
    """calibrate shared-positioner --update-cell: as the group above, into the cell file, which
    is byte-identical after any refusal."""
    args, what, inputs, writes = _shared_positioner(rng, d, good, out)
    cell = Path(args[args.index("--cell") + 1])
    if rng.random() < 0.1:
        args += ["--accept-poor"]
    return [*args, "--update-cell"], what, inputs, [*writes, *_cell_writes(cell)]


def _plan_robot_to_robot(rng, d, good, out):
    """plan robot-to-robot on the two-robot cell (no Monte Carlo runs): --track-ref or
    --track-other wrong (the KUKA's track, the ABB has none), either robot the reference."""
    reference, other = ("kuka", "abb") if rng.random() < 0.6 else ("abb", "kuka")
    bad = BAD_FLOATS + ["9000", "-5000", "1000", "3000", "3000.0001", "0x10", "1e-320"]
    opts = _maybe(rng, 0.9, {"--track-ref": bad, "--track-other": bad})
    opts += _maybe(rng, 0.1, {"--noise": BAD_FLOATS})
    csv = d / "points.csv"
    return (["plan", "robot-to-robot", "--cell", TWO_ROBOTS, "--robot", other, "--reference",
             reference, "--seed", "1", "--runs", "0", *opts, "-o", csv],
            f"{reference} the reference {' '.join(opts)}", [], [csv])


CASES.update({"coordinated-yaskawa": (4, 40), "coordinated-timed": (2, 30),
              "view-coordinated": (2, 30), "identify-robot-name": (2, 30),
              "shared-positioner-cell": (2, 30), "plan-robot-to-robot": (2, 30)})
BUILDERS.update({"coordinated-yaskawa": _coordinated_yaskawa,
                 "coordinated-timed": _coordinated_timed, "view-coordinated": _view_coordinated,
                 "identify-robot-name": _identify_robot_name,
                 "shared-positioner-cell": _shared_positioner_cell,
                 "plan-robot-to-robot": _plan_robot_to_robot})




def _edit_rows(text: str, edit) -> str:
    return _join(edit(_split(text)))


def _set(rows: list[list[str]], i: int, column: str, value: str) -> list[list[str]]:
    rows[i][rows[0].index(column)] = value
    return rows


#: Bad inputs of the ISO 9283 commands, each refused with exit status 2 on one 'error:' line
#: naming the file (and the line where there is one), nothing written: (the command's
#: arguments after the files, the file edited, its edit, what the message says).
ISO_BAD = {
    "log NaN": ("analyse", "meas", lambda t: _edit_rows(t, lambda r: _set(r, 4, "y", "nan")),
                r"meas\.csv: line 5: column 'y' is NaN"),
    "log missing column": ("analyse", "meas",
                           lambda t: _edit_rows(t, lambda r: [c[:2] + c[3:] for c in r]),
                           r"meas\.csv: missing column\(s\) x"),
    "log pose not in plan": ("analyse", "meas",
                             lambda t: _edit_rows(t, lambda r: _set(r, 7, "pose", "P6")),
                             r"meas\.csv: line 8: pose 'P6' is not in the plan"),
    "log too few cycles": ("analyse", "meas",
                           lambda t: _edit_rows(t, lambda r: [r[0], *(c for c in r[1:]
                                                                      if c[0] in "1234")]),
                           r"meas\.csv: P\d has 4 cycles \(its last on line \d+\)"),
    "log mixed units": ("analyse", "meas",
                        lambda t: _edit_rows(t, lambda r: _set(r, 9, "x",
                                                               repr(float(r[9][2]) / 1e3))),
                        r"meas\.csv: line 10: P\d lies [0-9.]+ mm from the median.*mixed units"),
    "log binary garbage": ("analyse", "meas",
                           lambda t: bytes(np.random.default_rng(5).integers(0, 256, 300,
                                                                              dtype=np.uint8)),
                           r"meas\.csv: "),
    "log empty": ("analyse", "meas", lambda t: "",
                  r"meas\.csv: needs a header line and at least one data line"),
    "plan NaN (analyse)": ("analyse", "plan",
                           lambda t: _edit_rows(t, lambda r: _set(r, 2, "x", "nan")),
                           r"plan\.csv: line 3: column 'x' has 'nan'"),
    "plan pose twice (simulate)": ("simulate", "plan",
                                   lambda t: _edit_rows(t, lambda r: _set(r, 3, "pose", "P2")),
                                   r"plan\.csv: line 4: pose 'P2' is named twice"),
    "plan empty (simulate)": ("simulate", "plan", lambda t: "",
                              r"plan\.csv: needs a header line"),
}


@pytest.mark.parametrize("case", list(ISO_BAD))
def test_cli_fuzz_iso9283_bad_inputs_exit_2_naming_the_line(case, good, tmp_path, capsys,
                                                           monkeypatch):
    command, which, edit, message = ISO_BAD[case]
    monkeypatch.chdir(tmp_path)
    files = {"meas": tmp_path / "meas.csv", "plan": tmp_path / "plan.csv"}
    shutil.copy(good["iso_meas.csv"], files["meas"])
    shutil.copy(good["iso_plan.csv"], files["plan"])
    _write(files[which], edit(files[which].read_text()))
    shutil.copy(EXAMPLE, tmp_path / "truth.yaml")
    before = _files(tmp_path)
    args = (["iso9283", "analyse", files["meas"], "--plan", files["plan"], "--json", "-o",
             tmp_path / "report.html"] if command == "analyse" else
            ["simulate", "iso9283", "--cell", tmp_path / "truth.yaml", "--plan", files["plan"],
             "-o", tmp_path / "log.csv"])
    code, out, err = run(capsys, *args)
    assert code == 2, err
    assert err.startswith("error: ") and len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in out + err and re.search(message, err), err
    assert out == "" and _files(tmp_path) == before


def _write(path: Path, content: bytes | str) -> Path:
    if isinstance(content, str):
        path.write_bytes(content.encode("utf-8", errors="surrogatepass"))
    else:
        path.write_bytes(content)
    return path


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()}


@pytest.fixture(scope="module")
def good(tmp_path_factory) -> dict[str, Path]:
    """Valid inputs made once: turntable results (--json output; in the robot base and, from a
    cell, in the world) and a TCP result, for workpiece and report; touches simulated in the
    example cells, for the calibrations into a cell; a robot model file."""
    from robotcell import load_robot
    from robotcell.calibration.tcp import calibrate_tool
    from robotcell.calibration.turntable import calibrate_turntable
    from robotcell.cell import Cell
    from robotcell.cell import calibrate as cellcal
    from robotcell.robot.models import save_robot
    from robotcell.studies.simulate import simulate

    d = tmp_path_factory.mktemp("good")
    rng = np.random.default_rng(SEED)
    f, th = _turntable_rows(rng)
    (d / "turntable.json").write_text(json.dumps(calibrate_turntable(np.radians(th), f * 1e-3)
                                                 .to_json()))
    flange = pose_from_vendor([[0, 0, 0, 60.0 * k, 160 + 5 * k, 10 * k] for k in range(6)], "kuka")
    flange[:, :3, 3] = np.array([1.1, -0.2, 0.3]) - flange[:, :3, :3] @ [0.01, 0.005, 0.2]
    (d / "tcp.json").write_text(json.dumps(calibrate_tool(flange).to_json()))
    cell = Cell.load(EXAMPLE)
    for procedure, kw in (("tcp", {}), ("frame", {"frame": "fixture"}), ("track", {}),
                          ("turntable", {}), ("workpiece", {"frame": "part"})):
        simulate(cell, procedure, seed=SEED, tool="pointer", **kw).write_csv(d / f"{procedure}.csv")
    world = cellcal.turntable(cell, d / "turntable.csv", tool="pointer", height=-0.05).result
    (d / "world.json").write_text(json.dumps(world.to_json()))
    simulate(Cell.load(POSITIONER), "positioner", seed=SEED, tool="pointer").write_csv(
        d / "positioner.csv")
    save_robot(load_robot("kuka_kr16"), d / "model.yaml")
    from robotcell.iso9283 import plan as iso_plan
    from robotcell.iso9283 import simulate as iso_simulate
    from robotcell.iso9283 import write_log, write_plan

    iso = iso_plan(cell, "torch", size=0.4)
    write_plan(iso, d / "iso_plan.csv")
    write_log(iso_simulate(cell, iso, cycles=10, path_cycles=10, spacing=0.01, seed=SEED),
              d / "iso_meas.csv")
    from robotcell.cli import main
    from robotcell.programs import write_program

    for vendor in ("kuka", "abb", "fanuc"):
        write_program(SEAM, cell, "torch", "part", vendor, d / f"prog_{vendor}")
    try:
        main(["reach", "--cell", str(EXAMPLE), str(SEAM), "--frame", "part", "--tool", "torch",
              "--table", "150", "-o", str(d / "reach.csv")])
    except SystemExit as exc:
        assert not exc.code
    return {p.name: p for p in d.iterdir()}


@pytest.mark.parametrize("command", list(CASES))
def test_cli_fuzz(command, tmp_path, capsys, monkeypatch, good):
    rng = np.random.default_rng([SEED, list(CASES).index(command)])
    monkeypatch.chdir(tmp_path)
    n = CASES[command][1 if FULL else 0]
    failures = []
    codes: dict[int, int] = {}
    for k in range(n):
        d = tmp_path / f"case{k}"
        d.mkdir()
        case = _case(command, rng, d, good)
        before = _files(d)
        code, out, err = run(capsys, *case.args)
        codes[code] = codes.get(code, 0) + 1
        problems = _problems(case, d, code, out, err, before)
        if problems:
            failures.append(f"case {k} ({case.what}): {', '.join(problems)}; robotcell "
                            f"{' '.join(case.args)}\n  stderr: {err.strip()[-300:]}")
        shutil.rmtree(d)
    assert not failures, (f"seed {SEED}, {len(failures)} of {n} cases failed:\n"
                          + "\n".join(failures[:8]))
    # The mutations must exercise both outcomes, else the test could not fail (checked on the
    # full set: a few fast cases may all end one way).
    if FULL:
        assert codes.get(2, 0) > 0 and (command in REFUSALS_ONLY or codes.get(0, 0) > 0), codes


def _problems(case: Case, d: Path, code: int, out: str, err: str, before: dict[str, bytes]
              ) -> list[str]:
    """What is wrong with the run of ``case`` in folder ``d`` (its files were ``before``), which
    ended with ``code``, ``out`` and ``err``; the runs' folder is ``d``'s parent."""
    after = _files(d)
    problems = []
    if code not in DOCUMENTED:
        problems.append(f"exit status {code}")
    if "Traceback" in out or "Traceback" in err:
        problems.append("traceback")
    if PYTHON_WARNING.search(err) or PYTHON_WARNING.search(out):
        problems.append("a Python warning")
    if code == 2 and "error:" not in err:
        problems.append("exit 2 without 'error:'")
    if code != 0 and after != before:
        problems.append(f"a refused run changed files {_diff(before, after)}")
    owned = {str(p.relative_to(d)) for w in case.writes
             for p in ([w, *w.rglob("*")] if w.is_dir() else [w])}
    if code == 0 and _diff(before, after) - owned:
        problems.append(f"changed inputs {sorted(_diff(before, after) - owned)}")
    if "-o onto the input" in case.what and code != 2:
        problems.append("an output onto an input was not refused")
    if "(never written)" in case.what and code == 0:
        problems.append("a run that can write nothing succeeded")
    if code == 0 and [name for name in _diff(before, after) & set(after)
                      if not after[name].rstrip().endswith(ENDS.get(Path(name).suffix, b""))]:
        problems.append("a file written in part (without its last line)")
    changed = {str(p.relative_to(d)) for p in case.together} & _diff(before, after)
    if changed and len(changed) < len(case.together):
        problems.append(f"only {sorted(changed)} of {[p.name for p in case.together]} changed")
    if any(name.endswith(".tmp") for name in after):
        problems.append("temporary files left")
    if sorted(p.name for p in d.parent.iterdir() if not p.name.startswith("case")):
        problems.append("files written outside the case's folder")
    return problems


#: The last line of a file of each kind that a command writes whole (a page, a YASKAWA job, an
#: ABB module).
ENDS = {".html": b"</html>", ".jbi": b"END", ".mod": b"ENDMODULE"}


#: Cases per command run as another user from a read-only install, without a writable home
#: (tests/readonly_helpers.py): the first ones of each command's sequence (in ``pytest -q``, in
#: the full set).
READ_ONLY = (2, 10)


def test_cli_fuzz_read_only_install(good, tmp_path, capsys, monkeypatch):
    # The first cases of every command, as a user who can write neither robotcell's folder nor
    # a home (numba cannot cache there, nor matplotlib keep its settings), all in one process
    # (the kernels compiled in memory once): the checks above, no exit 1, and the same exit
    # status and output as the same cases run here, from the normal install.
    n = READ_ONLY[1 if FULL else 0]
    with read_only_install() as install:
        runs = _read_only_cases(install.work, n, good)
        normal = _read_only_cases(tmp_path, n, good)
        for (*_, d, before), (*_, here, _) in zip(runs, normal, strict=True):
            for name in before:  # the same times of writing (cell history lists them)
                os.utime(here / name, ns=((d / name).stat().st_atime_ns,
                                          (d / name).stat().st_mtime_ns))
        install.give(install.work)
        results = install.robotcell_runs([(case.args, d.parent) for _, _, case, d, _ in runs])
        failures = []
        for (command, k, case, d, before), (code, out, err), (*_, twin, here, _) in zip(
                runs, results, normal, strict=True):
            problems = _problems(case, d, code, out, err, before)
            monkeypatch.chdir(here.parent)
            expected = [x.replace(str(tmp_path), str(install.work)) if isinstance(x, str) else x
                        for x in run(capsys, *twin.args)]
            if [code, out, PROGRESS.sub("", err)] != [*expected[:2], PROGRESS.sub("", expected[2])]:
                problems.append(f"not the result of a normal run {expected}")
            if problems:
                failures.append(f"{command} case {k} ({case.what}): {', '.join(problems)}; "
                                f"robotcell {' '.join(case.args)}\n  stderr: {err.strip()[-300:]}")
    assert not failures, (f"seed {SEED}, {len(failures)} of {len(runs)} cases failed:\n"
                          + "\n".join(failures[:8]))


def _read_only_cases(folder: Path, n: int, good: dict[str, Path]
                     ) -> list[tuple[str, int, Case, Path, dict[str, bytes]]]:
    """The first ``n`` cases of every command in ``folder/COMMAND/caseK``: the command, ``K``,
    the case, its folder and its files; the example files the cases name, copied to
    ``folder/examples``."""
    cases = []
    examples = Path(shutil.copytree(EXAMPLES, folder / "examples"))
    for command in CASES:
        rng = np.random.default_rng([SEED, list(CASES).index(command)])
        (folder / command).mkdir()
        for k in range(n):
            d = folder / command / f"case{k}"
            d.mkdir()
            case = _case(command, rng, d, good)
            # the user may not read the repository: the example files it names are copied
            case.args = [a.replace(str(EXAMPLES), str(examples)) for a in case.args]
            cases.append((command, k, case, d, _files(d)))
    return cases


def _diff(before: dict[str, bytes], after: dict[str, bytes]) -> set[str]:
    return {k for k in before.keys() | after.keys() if before.get(k) != after.get(k)}



# -- controllers: numbers, names and outputs a controller cannot hold -----------------------------
# Fixed cases, each checked as every fuzz run is: a documented exit status, the refusal named on
# an 'error:' line, no traceback or Python warning, and a refused run changes no file.
def _tool_99(d: Path) -> Path:
    text = EXAMPLE.read_text(encoding="utf-8").replace("  torch:\n    number: 1",
                                                         "  torch:\n    number: 99")
    return _write(d / "cell.yaml", text)


def _seam_written(d: Path, name: str, fmt: str) -> Path:
    """The example seam as ``d/name``, its program already written into ``d/prog``."""
    from robotcell.cell import Cell
    from robotcell.programs import write_program

    path = Path(shutil.copy(SEAM, d / name))
    write_program(path, Cell.load(EXAMPLE), "torch", "part", fmt, d / "prog",
                  pulses_per_degree=100)
    return path


def _program_write(path: Path, cell: Path, fmt: str, folder: Path) -> list:
    return ["program", "write", path, "--cell", cell, "--tool", "torch", "--frame", "part",
            "--format", fmt, "--pulses-per-degree", "100", "-o", folder]


def _export_tool_99(fmt: str, out: str):
    return lambda d: (["export", "--cell", _tool_99(d), "--format", fmt, "-o", d / out])


def _two_jobs_of_one_name(d: Path) -> list:
    _seam_written(d, "seam_part_a.csv", "yaskawa")
    return _program_write(Path(shutil.copy(SEAM, d / "seam_part_b.csv")), EXAMPLE, "yaskawa",
                          d / "prog")


def _over_a_hand_made_program(d: Path) -> list:
    _write(d / "SEAM_PART.ls", "/PROG SEAM_PART\n/MN\n/END\n")
    return _program_write(SEAM, EXAMPLE, "fanuc", d)


def _beside_its_name_in_capitals(d: Path) -> list:
    _write(d / "SEAM_PART.SRC", "DEF SEAM_PART()\nEND\n")
    return _program_write(SEAM, EXAMPLE, "kuka", d)


def _src_without_dat(d: Path) -> list:
    _seam_written(d, "seam.csv", "kuka")
    (d / "prog" / "seam.dat").unlink()
    return ["program", "check", d / "prog" / "seam.src", "--cell", EXAMPLE]


#: case -> (builder of its arguments in a folder, exit status, words of the refusal)
CONTROLLER_CASES = {
    "export kuka, tool 99": (_export_tool_99("kuka", "k.dat"), 2, "TOOL_DATA[1..16]"),
    "export fanuc, tool 99": (_export_tool_99("fanuc", "f.txt"), 2, "UTOOL[1..9]"),
    "export yaskawa, tool 99": (_export_tool_99("yaskawa", "y.txt"), 2, "TOOL[0..23]"),
    "export abb, tool 99": (_export_tool_99("abb", "a.mod"), 0, ""),
    "program write kuka, tool 99": (lambda d: _program_write(SEAM, _tool_99(d), "kuka",
                                                             d / "prog"), 2, "TOOL_DATA[1..16]"),
    "export kuka -o x.src": (lambda d: ["export", "--cell", EXAMPLE, "--format", "kuka", "-o",
                                        d / "x.src"], 2, "the name says a KUKA program"),
    "two yaskawa jobs of one name": (_two_jobs_of_one_name, 2, "it is a program written from"),
    "a program over a hand-made one": (_over_a_hand_made_program, 2, "robotcell did not write"),
    "a program beside its name in capitals": (_beside_its_name_in_capitals, 2,
                                              "takes the two names for one program"),
    # read, every motion named as not checked with the .dat to copy (a KRL program may have
    # no .dat of its own, its points being global ones of other modules)
    "program check, .src without its .dat": (_src_without_dat, 0, ""),
}


@pytest.mark.parametrize("name", list(CONTROLLER_CASES))
def test_cli_fuzz_controller_limits(name, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    build, expected, message = CONTROLLER_CASES[name]
    args = build(tmp_path)
    before = _files(tmp_path)
    code, out, err = run(capsys, *args)
    assert code == expected, err
    assert "Traceback" not in out + err and not PYTHON_WARNING.search(out + err)
    if code == 2:
        assert "error:" in err and message in err, err
        assert _files(tmp_path) == before


# -- spreadsheet cells, numbers, comment lines, folder outputs, history, touches left out ---------
# Each case is checked as the cases above are (documented exit status, no traceback, no Python
# warning, nothing changed by a refused run) and for what its input must give: an empty cell
# where the command has a default, a trailing separator or a note column is read as the valid
# file is (same exit status); an empty cell where a value is needed, a value under a column
# without a name, a number with "_" or digits of another script, a comment or title line are
# refused (exit 2) naming their line; a folder output given a file is refused saying so.

#: Cases per kind: (in ``pytest -q``, in the full set).
CELL_CASES = {"empty-cells": (8, 80), "numbers": (4, 40), "comment-lines": (4, 40),
              "folder-output": (2, 16), "history": (2, 20), "left-out": (2, 12)}


def _seam_with_defaults(rng: np.random.Generator) -> str:
    """The example seam with the columns that have a default per line: motion, speed, zone."""
    lines = SEAM.read_text(encoding="utf-8").splitlines()
    rows = [lines[0] + ",motion,speed,zone"]
    rows += [f"{line},{'lin' if k else 'ptp'},{int(rng.integers(20, 200))},"
             f"{int(rng.integers(0, 3))}" for k, line in enumerate(lines[1:])]
    return "\n".join(rows) + "\n"


#: Per command: the valid CSV, the arguments (the file as ``{csv}``), and the columns that must
#: have a value on every line, and those with a default per line.
_CELL_COMMANDS = {
    "tcp": (_tcp_csv, ["calibrate", "tcp", "{csv}"], list("xyzabc"), []),
    "frame": (_frame_csv, ["calibrate", "frame", "{csv}"], ["point", *"xyz"], ["note"]),
    "turntable": (_turntable_csv, ["calibrate", "turntable", "{csv}"], [*"xyz", "e1"], []),
    "fk": (_joints_csv, ["fk", "kuka_kr16", "--input", "{csv}"], [f"a{i}" for i in range(1, 7)],
           []),
    "fk-cell": (lambda rng: _cell_joints_csv(rng, False),
                ["fk", "--cell", EXAMPLE, "--input", "{csv}", "--tool", "torch"],
                [*(f"a{i}" for i in range(1, 7)), "track"], []),
    "program": (_seam_with_defaults,
                ["program", "write", "{csv}", "--cell", EXAMPLE, "--tool", "torch", "--frame",
                 "part", "--format", "kuka", "-o", "prog"],
                [*"xyzabc", "table"], ["motion", "speed", "zone"]),
}


def _empty_cells(rows: list[list[str]], rng: np.random.Generator, needed: list[str],
                 defaults: list[str]) -> tuple[list[list[str]], str, str]:
    """One mutation about empty cells: (rows, what, expected: ``"same"`` or an error text)."""
    kind = str(rng.choice(["trailing-separator", "empty-note", "empty-default", "empty-needed",
                           "unnamed-value", "unused-empty"]))
    header = rows[0]
    i = int(rng.integers(1, len(rows)))
    if kind == "trailing-separator":
        return [r + [""] * int(rng.integers(1, 3)) for r in rows], kind, "same"
    if kind in ("empty-note", "unused-empty"):
        name = "note" if kind == "empty-note" else "operator"
        if name not in header:
            rows = [header + [name]] + [r + ["Prüfung 3"] for r in rows[1:]]
        j = rows[0].index(name)
        for r in rows[1:]:
            r[j] = r[j] if rng.random() < 0.3 else ""
        return rows, kind, "same"
    if kind == "empty-default" and defaults:
        j = header.index(str(rng.choice(defaults)))
        rows[i][j] = ""
        return rows, f"{kind} {header[j]} line {i + 1}", "same"
    if kind == "unnamed-value":
        rows = [header + [""]] + [r + (["7"] if k == i else [""])
                                  for k, r in enumerate(rows[1:], 1)]
        return rows, f"{kind} line {i + 1}", f"line {i + 1}: value '7' in column {len(header) + 1}"
    j = header.index(str(rng.choice(needed)))
    rows[i][j] = ""
    return rows, f"empty {header[j]} line {i + 1}", f"line {i + 1}: empty value in column"


def _numbers(rows: list[list[str]], rng: np.random.Generator) -> tuple[list[list[str]], str, str]:
    """A number rewritten: with "_" or digits of another script (refused naming the line), or
    in another form a spreadsheet writes (``1.500000E+03``: read as the valid file)."""
    cells = [(i, j) for i in range(1, len(rows)) for j, c in enumerate(rows[i])
             if re.fullmatch(r"-?\d{2,}\.\d+", c)]
    i, j = cells[int(rng.integers(0, len(cells)))]
    value = rows[i][j]
    kind = str(rng.choice(["grouped", "script", "exponent"]))
    if kind == "exponent":
        rows[i][j] = f"{float(value):.9E}"
        return rows, f"{kind} line {i + 1}", "same"
    sign, digits = ("-", value[1:]) if value.startswith("-") else ("", value)
    rows[i][j] = (sign + digits[0] + "_" + digits[1:] if kind == "grouped"
                  else sign + digits.translate(str.maketrans("0123456789", "٠١٢٣٤٥٦٧٨٩")))
    return rows, f"{kind} {rows[i][j]} line {i + 1}", f"line {i + 1}: column"


def _comment_lines(rows: list[list[str]], rng: np.random.Generator
                   ) -> tuple[list[list[str]], str, str]:
    """A comment line above the header or among the data, or a title line above the header."""
    kind = str(rng.choice(["comment-above", "comment-among", "title"]))
    if kind == "comment-above":
        return [["# touches of cell 3", " KR 16"]] + rows, kind, "is a comment above the header"
    if kind == "title":
        return [["Touches of cell 3"]] + rows, kind, "a title above the header?"
    i = int(rng.integers(1, len(rows)))
    return rows[:i] + [["# re-touched", " see below"]] + rows[i:], f"{kind} line {i + 1}", \
        f"line {i + 1} starts with '#'"


def _cell_case(kind: str, rng: np.random.Generator, d: Path) -> tuple[Case, str]:
    """A case of ``kind`` in folder ``d``, and what it must give: ``"same"`` (the exit status of
    the valid input), ``"history"`` or a text the error must hold."""
    if kind == "folder-output":
        f = _write(d / "prog", "my notes\n")
        out = str(rng.choice([str(f), str(f / "sub")]))
        args = (["demo", "-o", out] if rng.random() < 0.3 else
                ["program", "write", SEAM, "--cell", EXAMPLE, "--tool", "torch", "--frame",
                 "part", "--format", "kuka", "-o", out])
        expect = "is a file, not a folder" if out.endswith("sub") else "exists and is a file"
        return Case(args, f"-o {out}"), expect
    if kind == "history":
        build = _cell_history(rng, d, {}, d / "out.txt")
        args = build[0] + (["--json"] if rng.random() < 0.5 else [])
        return Case(args, build[1]), "history"
    if kind == "left-out":
        rows = _split(_turntable_csv(rng))
        k = int(rng.integers(1, len(rows)))
        rows[k][0] = f"{float(rows[k][0]) + float(rng.uniform(3.0, 30.0)):.6f}"
        path = _write(d / "t.csv", _join(rows))
        return Case(["calibrate", "turntable", path], f"line {k + 1} off"), "left-out"
    command = str(rng.choice(sorted(_CELL_COMMANDS)))
    valid, argv, needed, defaults = _CELL_COMMANDS[command]
    rows = _split(valid(rng))
    (d / "valid.csv").write_text(_join(rows))
    if kind == "empty-cells":
        rows, what, expect = _empty_cells(rows, rng, needed, defaults)
    elif kind == "numbers":
        rows, what, expect = _numbers(rows, rng)
    else:
        rows, what, expect = _comment_lines(rows, rng)
    path = _write(d / "m.csv", _join(rows))
    writes = (d / "prog",) if command == "program" else ()
    return Case([str(path) if a == "{csv}" else a for a in argv], f"{command}: {what}",
                writes), expect


def _expected(expect: str, case: Case, d: Path, code: int, out: str, err: str,
              capsys) -> list[str]:
    """What is wrong with the outcome of a case against what its input must give."""
    if expect == "same":
        valid = [str(d / "valid.csv") if a.endswith("m.csv") else a for a in case.args]
        shutil.rmtree(d / "prog", ignore_errors=True)
        want = run(capsys, *valid)[0]
        return [] if code == want else [f"exit {code}, the valid file gives {want}"]
    if expect == "history":
        if code != 0 or "--json" not in case.args:
            return [] if code in (0, 2) else [f"exit {code}"]
        json.loads(out)
        return []
    if expect == "left-out":
        wrong = "left out as" in out and "take 6 or more touches" in out
        return ["the verdict counts the touches as if none were left out"] if wrong else []
    return [] if code == 2 and expect in err else [f"exit {code} without {expect!r}"]


@pytest.mark.parametrize("kind", list(CELL_CASES))
def test_cli_fuzz_spreadsheet_cells(kind, tmp_path, capsys, monkeypatch):
    rng = np.random.default_rng([SEED, 100 + list(CELL_CASES).index(kind)])
    monkeypatch.chdir(tmp_path)
    failures = []
    for k in range(CELL_CASES[kind][1 if FULL else 0]):
        d = tmp_path / f"case{k}"
        d.mkdir()
        monkeypatch.chdir(d)
        case, expect = _cell_case(kind, rng, d)
        before = _files(d)
        code, out, err = run(capsys, *case.args)
        after = _files(d)
        problems = []
        if code not in DOCUMENTED:
            problems.append(f"exit status {code}")
        if "Traceback" in out + err or PYTHON_WARNING.search(out + err):
            problems.append("a traceback or a Python warning")
        if code != 0 and after != before:
            problems.append(f"a refused run changed files {_diff(before, after)}")
        owned = {str(p.relative_to(d)) for w in case.writes
                 for p in ([w, *w.rglob("*")] if w.is_dir() else [w])}
        if code == 0 and _diff(before, after) - owned:
            problems.append(f"changed inputs {sorted(_diff(before, after) - owned)}")
        problems += _expected(expect, case, d, code, out, err, capsys)
        if problems:
            failures.append(f"case {k} ({case.what}): {', '.join(problems)}; robotcell "
                            f"{' '.join(case.args)}\n  stderr: {err.strip()[-300:]}")
        monkeypatch.chdir(tmp_path)
        shutil.rmtree(d)
    assert not failures, (f"seed {SEED}, {len(failures)} cases failed:\n"
                          + "\n".join(failures[:8]))

