"""The export command, in process through the CLI entry point."""

from pathlib import Path

import pytest
from cli_helpers import run

from robotcell.cell import Cell
from robotcell.controllers.data import collect
from robotcell.export import export_cell, parse_export

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"




@pytest.mark.parametrize("fmt", ["kuka", "abb", "fanuc", "yaskawa"])
def test_export_to_stdout_matches_library(capsys, fmt):
    code, out, err = run(capsys, "export", "--cell", str(EXAMPLE), "--format", fmt)
    assert code == 0 and err == ""
    assert out == export_cell(Cell.load(EXAMPLE), fmt)
    # independently of the library: the torch as the cell file writes it, x, y, z in mm
    assert all(f"{v:.6f}" in out for v in (312.5, -1.2, 95.0)), out


def test_export_to_file_parses_back(capsys, tmp_path):
    target = tmp_path / "config_lines.dat"
    code, out, err = run(capsys, "export", "--cell", str(EXAMPLE), "--format", "kuka",
                         "-o", str(target))
    assert code == 0 and out == "" and f"wrote {target}" in err
    got = parse_export(target.read_text(), "kuka")
    want = collect(Cell.load(EXAMPLE), "world")
    assert [s.name for s in got.tools] == [s.name for s in want.tools] == ["torch", "pointer"]
    assert got.turntable.name == "DKP_400_01"


def test_bad_cell_file_exits_2_naming_file_and_key(capsys, tmp_path):
    bad = tmp_path / "cell.yaml"
    bad.write_text("robot: {model: kuka_kr16}\ntools: {torch: {frame: {x: ten}}}\n")
    code, out, err = run(capsys, "export", "--cell", str(bad), "--format", "abb")
    assert code == 2 and out == ""
    assert err.startswith("error: ") and str(bad) in err and "tools.torch.frame.x" in err


def test_unknown_format_and_missing_option(capsys):
    code, _, err = run(capsys, "export", "--cell", str(EXAMPLE), "--format", "staubli")
    assert code == 2 and "staubli" in err
    code, _, err = run(capsys, "export", "--format", "kuka")
    assert code == 2 and "--cell" in err


def test_help_has_an_example(capsys):
    code, out, _ = run(capsys, "export", "--help")
    assert code == 0 and "robotcell export --cell cell.yaml --format kuka" in out
