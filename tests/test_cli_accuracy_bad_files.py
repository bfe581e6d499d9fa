"""Bad files and options for ``robotcell compensate`` and ``robotcell program compensate``: every
run ends with a documented status (0; 2 with one ``error:`` line naming the cause; 3 naming the
poses or points that cannot be filtered), never 1 or a traceback, and a refused run writes
nothing."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import CELL, EXT, SEAM, mutated_program, outcome_problems, write_mutation
from test_cli_fuzz import mutate_csv

from robotcell import load_robot, save_robot
from robotcell.cell import Cell
from robotcell.programs import write_program

SEED = 2024


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """An identified example cell (the KR 16 with its upper arm 1 mm longer), the example seam
    as poses in its frame 'part', and the seam written for the nominal cell in every format."""
    d = tmp_path_factory.mktemp("accuracy")
    nominal = load_robot("kuka_kr16")
    j = nominal.joints[1]
    arm = replace(nominal, name="kr16_identified", ik_seed=nominal,
                  joints=(nominal.joints[0], replace(j, a=j.a + 1e-3), *nominal.joints[2:]))
    save_robot(arm, d / "arm.yaml")
    (d / "cell.yaml").write_text(CELL.read_text().replace(
        "model: kuka_kr16", f"model: kuka_kr16\n  identified: {d / 'arm.yaml'}"))
    out = {"cell": d / "cell.yaml", "poses": d / "poses.csv"}
    out["poses"].write_text(SEAM.read_text())
    nominal_cell = Cell.load(CELL)
    for vendor, ext in EXT.items():
        res = write_program(SEAM, nominal_cell, "torch", "part", vendor, d / vendor,
                            pulses_per_degree=100)
        out[vendor] = Path(next(f for f in res.files if f.endswith(ext)))
    return out


def _check(code: int, out: str, err: str, match: str, code_wanted: int = 2) -> None:
    assert "Traceback" not in out + err
    assert code == code_wanted, err
    assert err.count("error:") == 1 and match.lower() in err.lower(), err


def _args(files, poses, out, *extra):
    return ["compensate", poses, "--cell", files["cell"], "--tool", "torch", "--frame", "part",
            "-o", out, *extra]


def test_the_valid_inputs_filter(files, tmp_path, capsys):
    code, out, err = run(capsys, *_args(files, files["poses"], tmp_path / "cmd.csv"))
    assert code == 0, err
    assert "36 poses filtered" in out


@pytest.mark.parametrize("content,match", [
    ("x,y,z,a,b\n0,0,0,0,0\n", "missing column(s) c"),
    ("x,y,z,a,b,c\nabc,0,0,0,0,0\n", "must be numeric"),
    ("", "header line and at least one data line"),
    ("x,y,z,a,b,c,s\n0,0,0,0,0,0,6\n", "missing column(s) t of the kuka configuration"),
    ("x,y,z,a,b,c,s,t\n0,0,0,0,0,0,6.5,2\n", "line 2: column 's' must be an integer"),
    ("x,y,z,a,b,c,s,t,cfx\n0,0,0,0,0,0,6,2,0\n", "configuration columns of kuka and abb"),
    ('x,y,z,a,b,c,config\n0,0,0,0,0,0,"Q U T, 0, 0, 0"\n', "line 2: column 'config': CONFIG"),
    ("x,y,z,a,b,c,table\n0,0,0,0,0,0,9999\n", "outside the table limits"),
    ("x,y,z,a,b,c\n1e300,0,0,0,0,0\n", "beyond 1e+15"),
    (SEAM.read_text().encode("utf-16"), "UTF-16"),
    (bytes(range(256)) * 2, "not a text file"),
])
def test_a_bad_poses_file_exits_2_and_writes_nothing(files, tmp_path, capsys, content, match):
    path = tmp_path / "p.csv"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    code, out, err = run(capsys, *_args(files, path, tmp_path / "cmd.csv"))
    _check(code, out, err, match)
    assert not (tmp_path / "cmd.csv").exists()


@pytest.mark.parametrize("extra,match", [
    (["--tool", "gripper"], "tool 'gripper' is not a tool of the cell"),
    (["--frame", "wall"], "wall"),
    (["--max-correction", "0"], "--max-correction must be from"),
    (["--max-correction", "nan"], "--max-correction must be from"),
    (["--report", "r.csv"], "the name says CSV"),
])
def test_bad_options_exit_2_naming_the_option(files, tmp_path, capsys, extra, match):
    code, out, err = run(capsys, *_args(files, files["poses"], tmp_path / "cmd.csv"), *extra)
    _check(code, out, err, match)
    assert not (tmp_path / "cmd.csv").exists()


def test_outputs_onto_inputs_and_of_the_wrong_kind_are_refused(files, tmp_path, capsys):
    code, out, err = run(capsys, *_args(files, files["poses"], files["poses"]))
    _check(code, out, err, "names the same file as POSES")
    code, out, err = run(capsys, *_args(files, files["poses"], tmp_path / "cmd.json"))
    _check(code, out, err, "the name says JSON")
    code, out, err = run(capsys, "compensate", files["poses"], "--cell", CELL, "--tool", "torch",
                         "--frame", "part", "-o", tmp_path / "cmd.csv")
    _check(code, out, err, "has no identified arm")


def test_program_compensate_of_files_it_cannot_take(files, tmp_path, capsys):
    (tmp_path / "prog.txt").write_text("PTP P1\n")
    code, out, err = run(capsys, "program", "compensate", tmp_path / "prog.txt", "--cell",
                         files["cell"], "-o", tmp_path / "out")
    _check(code, out, err, "unknown program file type '.txt'")
    code, out, err = run(capsys, "program", "compensate", files["kuka"], "--cell", files["cell"],
                         "-o", tmp_path / "out", "--max-correction", "-1")
    _check(code, out, err, "--max-correction must be from")
    code, out, err = run(capsys, "program", "compensate", files["yaskawa"], "--cell",
                         files["cell"], "-o", tmp_path / "out")
    _check(code, out, err, "--pulses-per-degree")
    code, out, err = run(capsys, "program", "compensate", files["kuka"], "--cell", files["cell"],
                         "-o", files["kuka"].parent)
    _check(code, out, err, "it is an input of this run")
    assert not (tmp_path / "out").exists()


def test_fuzz_mutated_poses_files_and_programs(files, tmp_path, capsys):
    """Seeded mutations of a valid poses file (compensate) and of valid programs of every format
    (program compensate): documented exit statuses only, no traceback, nothing left on
    refusal."""
    rng = np.random.default_rng(SEED)
    failures, codes = [], {}
    for k in range(20):
        vendor = str(rng.choice(list(EXT)))
        out = tmp_path / f"out{k}"
        if k % 2 == 0:
            content, what = mutate_csv(files["poses"].read_text(), rng)
            path = tmp_path / f"poses{k}.csv"
            write_mutation(path, content)
            written = out.with_suffix(".csv")
            args = _args(files, path, written)
        else:
            src = files[vendor]
            case = tmp_path / f"case{k}"
            what = mutated_program(src, case, rng)
            args = ["program", "compensate", case / src.name, "--cell", files["cell"], "-o", out,
                    "--pulses-per-degree", "100"]
            written = out
        code, stdout, err = run(capsys, *args)
        codes[code] = codes.get(code, 0) + 1
        problems = outcome_problems(code, stdout, err, written.exists())
        if problems:
            failures.append(f"case {k} ({vendor}, {what}): {', '.join(problems)}; "
                            f"{' '.join(map(str, args))}\n  {err.strip()[-300:]}")
    assert not failures, "\n".join(failures[:6])
    assert codes.get(0, 0) > 0 and codes.get(2, 0) > 0, codes
