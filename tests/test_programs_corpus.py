"""Real programs from public repositories (tests/data/programs/<vendor>/, sources and licences in
each folder's README.md): every one is read and checked against a minimal cell with exit status
0 or 3, never refused; and every format robotcell writes is read back the same."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from programs_helpers import CELL, SEAM

from robotcell.cell import Cell
from robotcell.controllers.registry import by_suffix
from robotcell.programs import read_program, write_program

DATA = Path(__file__).resolve().parent / "data" / "programs"
#: The program files of each vendor's corpus (a KUKA program is its .src).
MAIN = {"kuka": ".src", "abb": ".mod", "fanuc": ".ls", "yaskawa": ".jbi", "ur": ".script"}


def _corpus(vendor: str) -> list[Path]:
    return sorted(p for p in (DATA / vendor).rglob("*") if p.suffix.lower() == MAIN[vendor])


def _sources(vendor: str) -> set[str]:
    """The independent sources of a vendor's files: the README's repositories."""
    text = (DATA / vendor / "README.md").read_text()
    rows = [ln.split("|")[2] for ln in text.splitlines() if ln.startswith("| `")]
    found = (re.search(r"(?:^\s*|after )([A-Za-z0-9_.-]+/[A-Za-z0-9_.-]+),", r) for r in rows)
    return {m.group(1) for m in found if m}


CASES = [(v, p) for v in MAIN for p in _corpus(v)]


@pytest.mark.parametrize("vendor", list(MAIN))
def test_each_corpus_has_five_programs_from_three_sources_with_their_licences(vendor):
    files = _corpus(vendor)
    assert len(files) >= 5
    readme = (DATA / vendor / "README.md").read_text()
    for f in files:
        assert f"`{f.relative_to(DATA / vendor).as_posix()}" in readme, f
    assert len(_sources(vendor)) >= 3, _sources(vendor)
    # every copied file's licence is beside it; the others are excerpts written for the tests
    for folder in {f.parent for f in files}:
        top = folder if folder.parent == DATA / vendor else folder.parent
        assert top.name == "excerpts" or (top / "LICENSE").is_file() or any(
            "header" in ln for ln in readme.splitlines() if top.name in ln), top


@pytest.mark.parametrize("vendor,path", CASES, ids=[p.name for _, p in CASES])
def test_a_real_program_is_read_and_checked_never_refused(vendor, path, capsys):
    program, skipped = read_program(path)
    assert by_suffix(path.suffix.lower()).name == vendor
    assert all(s.startswith(("line ", "P[", "the program")) for s in skipped), skipped
    code, out, err = run(capsys, "program", "check", path, "--cell", DATA / vendor / "cell.yaml")
    assert code in (0, 3), err  # 3: bad points, named in a table; never 2, a refusal
    assert "Traceback" not in out + err
    if not program.points:
        assert code == 0 and "no point checked" in out


def test_the_corpus_reads_the_constructs_it_was_chosen_for():
    krc2 = read_program(DATA / "kuka" / "kuka_experimental" / "KR_C2" / "ros_rsi.src")
    assert [p.name for p in krc2[0].points] == ["HOME"]  # DECL AXIS HOME set in the .src
    _milling, notes = read_program(DATA / "kuka" / "excerpts" / "milling_side.src")
    assert any("geometric operator" in n for n in notes)
    mm, notes = read_program(DATA / "abb" / "excerpts" / "multimove_t_rob1.mod")
    assert [p.motion for p in mm.points] == ["ptp", "ptp", "lin"] and not notes
    assert mm.points[2].config is None  # ConfL \Off
    surface, notes = read_program(DATA / "fanuc" / "excerpts" / "surface.ls")
    assert sum("Tool_Offset, PR[15]" in n for n in notes) == 2 and len(surface.points) == 2
    arg, notes = read_program(DATA / "yaskawa" / "excerpts" / "ARGWELD.JBI")
    assert [p.name for p in arg.points] == ["C00000", "C00001"] and not notes


# -- round trips: written by robotcell, read back by robotcell --------------------------------
@pytest.fixture(scope="module")
def cell() -> Cell:
    return Cell.load(CELL)


# UR: a UR arm moves without the example cell's track (refused); test_programs_ur.py reads
# its written programs back
@pytest.mark.parametrize("vendor", [v for v in MAIN if v != "ur"])
def test_a_written_program_reads_back_as_written(cell, tmp_path, vendor):
    result = write_program(SEAM, cell, "torch", "part", vendor, tmp_path / "p",
                           pulses_per_degree=100 if vendor == "yaskawa" else None)
    program, skipped = read_program(result.files[0])
    assert not skipped
    written = result.programs[0]
    assert [p.name for p in program.points] == [p.name for p in written.points]
    assert [p.motion for p in program.points] == [p.motion for p in written.points]
    for got, want in zip(program.points, written.points):
        # YASKAWA: 3 decimals of mm; FANUC: 3 decimals of mm and of deg, as controllers save them
        tol = {"yaskawa": 2e-6, "fanuc": 2e-5}.get(vendor, 1e-9)
        assert np.allclose(got.pose, want.pose, atol=tol)
        # KUKA keeps S and T for PTP points only: the controller ignores them on LIN
        if vendor != "kuka" or got.motion == "ptp":
            assert got.config == want.config
        for k, v in want.external.items():  # KUKA writes the unused E axes as 0 too
            assert got.external[k] == pytest.approx(v, abs=1e-3)
