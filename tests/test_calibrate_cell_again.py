"""calibrate cell repeated on its own output: an item kept out of the fit (a nominal track)
keeps its error source's columns, so a second and third refit read what the first wrote."""

import shutil
from pathlib import Path

from cli_helpers import run

from robotcell.cell import Cell

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"


def test_a_refit_of_a_refit_runs_and_keeps_the_nominal_tracks_source_whole(capsys, tmp_path):
    cell = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, cell)
    for args in (["simulate", "tcp", "--cell", cell, "--tool", "pointer", "--seed", "1",
                  "-o", tmp_path / "tcp.csv"],
                 ["simulate", "turntable", "--cell", cell, "--tool", "pointer", "--seed", "2",
                  "-o", tmp_path / "tt.csv"],
                 ["calibrate", "tcp", tmp_path / "tcp.csv", "--cell", cell, "--name", "pointer",
                  "--sigma", "0.1"],
                 ["calibrate", "turntable", tmp_path / "tt.csv", "--cell", cell, "--tool",
                  "pointer", "--height=-50", "--sigma", "0.1"]):
        code, _, err = run(capsys, *args)
        assert code == 0, err
    for _ in range(3):
        code, _, err = run(capsys, "calibrate", "cell", "--cell", cell)
        assert code == 0 and "different widths" not in err, err
        sources = Cell.load(cell).turntable.provenance.sources
        assert sources["track nominal"].shape == (6, 7)  # the track's 7 parameters
