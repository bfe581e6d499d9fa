"""The cell show command, in process through the CLI entry point."""

from pathlib import Path

from cli_helpers import run

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"




def test_show_lists_every_item_with_values_and_provenance(capsys):
    code, out, _ = run(capsys, "cell", "show", str(EXAMPLE))
    assert code == 0
    assert "robot kuka_kr16" in out and "track KL1500: 0 .. 6000 mm" in out
    rows = {line.split()[0]: line for line in out.splitlines()[4:] if line.split()}
    assert "312.500" in rows["torch"] and "45.000" in rows["torch"] and "rms 0.270 mm" in rows["torch"]
    assert "frame (turntable)" in rows["part"] and "workpiece" in rows["part"]
    assert "3000.000" in rows["DKP_400_01"] and rows["pointer"].rstrip().endswith("nominal")


def test_show_bad_file_exits_2(capsys, tmp_path):
    bad = tmp_path / "c.yaml"
    bad.write_text("robot: {model: kuka_kr16}\ntrack: {axis: q}\n")
    code, out, err = run(capsys, "cell", "show", str(bad))
    assert code == 2 and out == "" and "key 'track.axis'" in err and str(bad) in err
