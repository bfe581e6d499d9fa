"""KUKA programs (robotcell.programs.kuka): what pendants and offline tools write, read and
checked; truncated files refused naming the line."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import CELL, ROBODK, SEAM

from robotcell.cell import Cell
from robotcell.errors import InputError
from robotcell.programs import read_program, write_program
from robotcell.programs.check import check_program, check_program_file


@pytest.fixture(scope="module")
def cell() -> Cell:
    return Cell.load(CELL)


@pytest.fixture()
def written(cell, tmp_path):
    result = write_program(SEAM, cell, "torch", "part", "kuka", tmp_path / "p")
    src = Path(result.files[0])
    return src, src.with_suffix(".dat"), result


def test_the_written_files_are_krl_with_the_cells_tool_and_turntable_base(written):
    src, dat, _ = written
    text = src.read_text()
    assert "BAS (#INITMOV,0 )" in text and text.rstrip().endswith("END")
    assert "$TOOL=TOOL_DATA[1]" in text  # torch is TOOL_DATA[1] in 'robotcell export'
    assert "$BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,BASE_DATA[2])" in text
    first = next(ln for ln in dat.read_text().splitlines() if ln.startswith("DECL E6POS XP1="))
    assert re.search(r",S \d+,T \d+,E1 [-0-9.]+,E2 200\.0+,E3 0\.0+", first)


def _pendant_variant(src: Path, dat: Path) -> None:
    """Rewrite the files the way pendants and other tools write them: inline form with FDAT,
    typed aggregates, lower-case fields, S/T in binary, no S/T on linear points, Latin-1."""
    d = dat.read_text().splitlines()
    out = []
    for ln in d:
        m = re.match(r"DECL E6POS (XP\d+)=\{(.*)\}$", ln)
        if m:
            body = m.group(2)
            s, t = re.search(r"S (\d+),T (\d+)", body).groups()
            n = int(m.group(1)[2:])
            if n > 1:  # linear points: no S, T (the controller keeps the configuration)
                body = re.sub(r",S \d+,T \d+", "", body)
            else:
                body = body.replace(f"S {s},T {t}", f"S 'B{int(s):03b}',T 'B{int(t):06b}'")
            body = body.lower() if n % 2 else body
            out.append(f"DECL E6POS {m.group(1)}={{E6POS: {body}}}")
            out.append(f"DECL FDAT F{m.group(1)[1:]}={{TOOL_NO 1,BASE_NO 2,IPO_FRAME #BASE,"
                       'POINT2[] " ",TQ_STATE FALSE}')
        else:
            out.append(ln)
    out.insert(3, "; Schweißnaht Bauteil Ö")  # a Latin-1 comment, as KSS saves it
    dat.write_bytes("\n".join(out).encode("latin-1"))
    s = []
    for ln in src.read_text().splitlines():
        if ln.startswith(("$TOOL", "$BASE", "$ACT_EX_AX")):
            continue
        m = re.match(r"(PTP|LIN) (XP\d+)(.*)$", ln)
        if m:
            s += [f";FOLD {m.group(1)} P{m.group(2)[2:]} Vel=0.1 m/s ...", "$BWDSTART=FALSE",
                  f"FDAT_ACT=F{m.group(2)[1:]}", f"S{m.group(1)} {m.group(2)}{m.group(3)}",
                  ";ENDFOLD"]
        else:
            s.append(ln)
    src.write_text("\n".join(s) + "\n")


def test_a_pendant_style_program_reads_as_the_one_written(cell, written):
    src, dat, result = written
    _pendant_variant(src, dat)
    program, skipped = read_program(src)
    assert not skipped and len(program.points) == 36
    assert program.points[0].config.values[0] == 4 and program.points[1].config is None
    report = check_program(program, cell)
    assert report.good, report.rows()
    q = np.stack([p.q for p in report.points])
    assert np.abs(q - result.q).max() < 1e-6


def test_a_real_robodk_program_for_a_kr16_is_read_and_checked():
    # RoboDK's example station exported to a "KUKA KR 16 2" (RoboDK/Industrial-Robots-VSCode,
    # examples/Program.src, MIT): inline points, $TOOL and $BASE written as frames.
    cell = Cell.load(ROBODK / "cell_kr16.yaml")
    report = check_program_file(ROBODK / "Program.src", cell)
    assert [p.name for p in report.points] == [f"line {n}" for n in (51, 52, 54, 55, 65, 70)]
    assert [p.motion for p in report.points] == ["ptp", "ptp", "lin", "lin", "lin", "lin"]
    assert report.skipped == ["line 36: PTP $AXIS_ACT (not held by the program)"]
    assert np.allclose(np.degrees(report.points[1].q), [0, -3.68662, -0.7029, 0, -56.11471, 0])
    # every point is reachable, and every linear motion can be followed on the arm's branch:
    # the first, from a joint point whose tool is turned half round from the line's, turns
    # axis 6 by 174 deg on the way, as a controller runs it
    assert report.good, report.rows()
    assert np.degrees(report.points[2].q[5]) == pytest.approx(-173.65, abs=0.01)


@pytest.mark.parametrize("edit,match", [
    (lambda s, d: d.write_text(d.read_text().split("DECL E6POS XP9=")[0]
                               + "DECL E6POS XP9={X 12.5,Y"),
     "line 13: the aggregate is not closed"),
    (lambda s, d: d.write_text(d.read_text().replace("ENDDAT", "")), "no ENDDAT"),
    (lambda s, d: s.write_text(s.read_text().replace("\nEND\n", "\n")), "no END"),
    (lambda s, d: d.write_text(d.read_text().replace(",Y 0.000000,", ",Y 0.0.0,", 1)),
     "line 5: '0.0.0' is not a number"),
    (lambda s, d: d.write_text(d.read_text().replace("X 200.000000,", "", 1)),
     "XP1: the pose lacks X"),
])
def test_a_truncated_or_corrupt_program_is_refused_naming_the_line(written, edit, match,
                                                                   capsys):
    src, dat, _ = written
    edit(src, dat)
    with pytest.raises(InputError, match=match):
        read_program(src)
    code, _, err = run(capsys, "program", "check", src, "--cell", CELL)
    assert code == 2 and err.count("error:") == 1 and "Traceback" not in err


def test_a_base_on_the_turntable_set_without_ek_is_a_bad_point(cell, written):
    src = written[0]
    src.write_text(src.read_text().replace(
        "$BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,BASE_DATA[2])", "$BASE=BASE_DATA[2]"))
    report = check_program_file(src, cell)
    assert len(report.bad) == 36
    assert "carried by the turntable: set it with $BASE=EK(...)" in report.bad[0].problems[0]


def test_a_point_declared_in_no_file_of_the_program_is_named_not_checked(written, capsys):
    # a global point of another module's .dat (DECL GLOBAL) is valid KRL: named, not refused
    src = written[0]
    src.write_text(src.read_text().replace("PTP XP1", "PTP XP99"))
    program, skipped = read_program(src)
    assert len(program.points) == 35
    assert skipped[0].endswith("PTP XP99 (XP99 is declared in neither the program's .dat nor "
                               "its .src (a global point of another module is not read))")
    code, _, err = run(capsys, "program", "check", src, "--cell", CELL)
    assert code in (0, 3) and "note: not checked:" in err and "error:" not in err
