"""A cell file is never lost, corrupted, raced or cut.

- Every YAML file robotcell writes reads back as what was meant, whatever its size: the whole-
  cell refit of the README's cell loads after every run and does not grow from refit to refit.
- Updates of one cell file are serialised: eight processes calibrating one cell at the same
  moment lose no result, the backups are a consistent history, a killed holder of the lock
  blocks nobody.
- A cell file or output given through a symbolic link is updated where the link points; a file
  with several hard links is refused, naming why.

``pytest -q`` refits the README's cell for the seeds the defects were found with (20, 40, 50);
``ROBOTCELL_FUZZ=full`` refits it for 40 seeds, as ``.ci/run`` does.
"""

from __future__ import annotations

import itertools
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from test_commissioning import readme_sequence

from robotcell import load_robot
from robotcell.cell import Cell, Provenance
from robotcell.cell import calibrate as cellcal
from robotcell.cell.history import backups, cell_history
from robotcell.cell.schema import save_cell
from robotcell.cell.update import update_cell_file
from robotcell.errors import InputError, RobotcellError
from robotcell.io import yamlfile
from robotcell.io.fileio import atomic_write
from robotcell.io.locking import LOCK_WAIT, file_lock, lock_path
from robotcell.io.yamlfile import dump_yaml, parse_yaml
from robotcell.robot.models import save_robot
from robotcell.studies.simulate import simulate
from robotcell.studies.sweep import read_layouts

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
EXAMPLE = EXAMPLES / "cell_kr16_track_turntable.yaml"
FULL = os.environ.get("ROBOTCELL_FUZZ", "") == "full"
#: Seeds of the README's sequence (added to each --seed of it): the three a refit made
#: unreadable, or 40 of them.
SEEDS = list(range(0, 400, 10)) if FULL else [20, 40, 50]
LONG = 12_000  # characters: a line beyond 10,000


def _snapshot(folder: Path, locks: bool = True) -> dict[str, bytes]:
    """Every file under ``folder`` and its content (without the lock files: ``locks`` False)."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and (locks or p.suffix != ".lock")}


# -- 0. every file written reads back -------------------------------------------------------------
def _long_data() -> dict:
    """Data whose naive YAML has lines beyond 10,000 characters and keys with spaces."""
    sources = {f"frames.part {k:012x} of the whole cell": [[1.234567e-5 * (i - j) for j in range(9)]
                                                            for i in range(7)]
               for k in range(40)}
    return {"note": "fitted with the whole cell; " * (LONG // 28),
            "key with spaces": {"inner key with spaces": "x y z" * 3000, "n": 1},
            "sources": sources, "row": [1e-7 * k for k in range(2000)],
            "flat": {f"track {k:x}": k for k in range(1200)}, "empty": {}, "none": []}


def test_dump_yaml_reads_back_lines_beyond_10000_characters_and_keys_with_spaces():
    data = _long_data()
    text = dump_yaml(data)
    assert parse_yaml(text, "t") == data
    # (no line is broken inside a key, and no one-line collection is longer than FLOW_MAX)
    assert max(len(line) for line in text.splitlines() if "[" in line or "{" in line) \
        < yamlfile.FLOW_MAX + 100


def test_a_text_that_would_not_read_back_is_refused_and_nothing_written(tmp_path, monkeypatch):
    """Whatever breaks the YAML text (a line broken inside a key did), it is never installed:
    the cell file stays as it was, without a backup."""
    path = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, path)
    cell = Cell.load(path)
    cell.set_tool("torch", cell.tools["torch"].T_F_TCP, Provenance("tcp", rms_mm=0.1))
    writer = yamlfile._yaml

    def broken():
        y = writer()
        dump = y.dump
        y.dump = lambda data, stream: (dump(data, stream), stream.write("tools: {a b: [1,\n"))
        return y

    monkeypatch.setattr(yamlfile, "_yaml", broken)
    before = _snapshot(tmp_path)
    with pytest.raises(RobotcellError, match="does not read back as what was meant"):
        cell.save(path)
    assert _snapshot(tmp_path, locks=False) == before  # (the lock file stays: it is no content)


def test_a_cell_that_would_not_load_is_never_installed(tmp_path):
    path = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, path)

    def refusing(data, origin, base):
        raise InputError(f"{origin}: key 'tools.torch.frame.x' is 1e+308 mm")

    before = _snapshot(tmp_path)
    with pytest.raises(InputError, match=r"the cell as it would be written does not load \(.*"
                       r"1e\+308 mm\); .*cell.yaml is unchanged"):
        save_cell(Cell.load(path), path, refusing)
    assert _snapshot(tmp_path, locks=False) == before


def test_the_cell_writer_reads_back_long_provenance_with_keys_with_spaces(tmp_path):
    path = tmp_path / "cell.yaml"
    shutil.copy(EXAMPLE, path)  # its provenance is written in flow style: {source: nominal}
    cell = Cell.load(path)
    sources = {f"frames.part {k:012x}": np.random.default_rng(k).normal(0, 1e-4, (6, 40))
               for k in range(10)}
    prov = Provenance("tcp", rms_mm=0.1, note="fitted with the whole cell " * 450,
                      sources=sources, inputs=("tools.pointer", "track"))
    cell.set_tool("pointer", cell.tools["pointer"].T_F_TCP, prov)
    cell.save(path)
    back = Cell.load(path).tools["pointer"].provenance
    assert back.note == prov.note and len(back.note) > 10_000
    assert set(back.sources) == set(sources)
    for name, f in sources.items():
        np.testing.assert_allclose(back.sources[name], f, rtol=1e-5, atol=1e-12)


def test_the_model_writer_reads_back_a_line_beyond_10000_characters(tmp_path):
    robot = replace(load_robot("kuka_kr16"), title="KR 16, identified; " * (LONG // 19))
    save_robot(robot, tmp_path / "arm.yaml")
    assert load_robot(tmp_path / "arm.yaml").title == robot.title


def test_a_layouts_file_written_with_a_line_beyond_10000_characters_is_read(tmp_path):
    """robotcell reads layouts files and writes none; one written by the YAML writer with a
    grid of 2000 values (12,000 characters on one line in flow style) is read."""
    values = [round(-1000 + k * 0.5, 1) for k in range(2000)]
    path = tmp_path / "layouts.yaml"
    path.write_text(dump_yaml({"robot": {"y": values}}))
    layouts = read_layouts(path)
    assert [lay.values["robot.y"] for lay in layouts] == values


# -- 0. the whole-cell refit of the README's cell -------------------------------------------------
def commission(capsys, base: int) -> None:
    """The README's calibration sequence in the current folder, every --seed plus ``base``."""
    for command in readme_sequence():
        argv = shlex.split(command)
        if argv[0] == "cp":
            shutil.copy(argv[1], argv[2])
            continue
        if argv[1] in ("report", "export", "cell"):
            continue
        if "--seed" in argv:
            argv[argv.index("--seed") + 1] = str(int(argv[argv.index("--seed") + 1]) + base)
        code, _, err = run(capsys, *argv[1:])
        assert code == 0, f"{command}\n{err}"


@pytest.mark.parametrize("base", SEEDS)
def test_refits_of_the_readme_cell_load_and_do_not_grow(tmp_path, capsys, monkeypatch, base):
    """The README's cell, calibrated and then refitted three times: the file loads after every
    run, each item's note says once that it was fitted with the whole cell, its rms_mm is the
    refit's, and from the second refit on the file keeps its lines and its size (within 2 %,
    the digits of numbers that change in their last places)."""
    monkeypatch.chdir(tmp_path)
    shutil.copytree(EXAMPLES, tmp_path / "examples")
    commission(capsys, base)
    sizes, lines = [], []
    for _ in range(3):
        code, out, err = run(capsys, "calibrate", "cell", "--cell", "cell.yaml", "--json")
        assert code == 0, err
        cell = Cell.load("cell.yaml")  # loads after every run
        steps = {s["item"]: s for s in json.loads(out)["steps"]}
        for key, item in (("tools.torch", cell.tools["torch"]), ("track", cell.track),
                          ("turntable", cell.turntable), ("frames.part", cell.frames["part"])):
            prov = item.provenance
            assert prov.note.count("fitted with the whole cell") == 1, prov.note
            assert prov.rms_mm == pytest.approx(steps[key]["rms_mm"], rel=1e-9)
        text = Path("cell.yaml").read_text()
        sizes.append(len(text))
        lines.append(text.count("\n"))
    assert lines[2] == lines[1] == lines[0], lines
    assert sizes[2] <= sizes[1] * 1.02, sizes


# -- 0. calibrate cell -o -------------------------------------------------------------------------
@pytest.fixture
def calibrated(tmp_path, monkeypatch) -> Path:
    """A copy of the example cell with a tool and a frame calibrated from touch files."""
    monkeypatch.chdir(tmp_path)
    shutil.copy(EXAMPLE, "cell.yaml")
    truth = Cell.load(EXAMPLE)
    simulate(truth, "tcp", seed=1, tool="pointer", noise=1e-4).write_csv("tcp.csv")
    simulate(truth, "frame", seed=2, tool="pointer", frame="fixture", noise=1e-4).write_csv(
        "frame.txt")  # (a name that says no kind of file: only its identity refuses -o onto it)
    cell = cellcal.tcp(Cell.load("cell.yaml"), "tcp.csv", "pointer", sigma=1e-4).cell
    cell = cellcal.frame(cell, "frame.txt", "fixture", tool="pointer", sigma=1e-4).cell
    cell.save("cell.yaml")
    return tmp_path


@pytest.mark.parametrize("args, message", [
    (["-o", "cell.yaml"], "-o cell.yaml: the name says YAML, but this writes the report"),
    (["--json", "-o", "cell.yaml"], ("-o cell.yaml: the name says YAML, but this writes the "
                                     "result as JSON")),
    (["-o", "cell.txt"], "-o/--output cell.txt names the same file as --cell cell.yaml"),
    (["-o", "./link.txt"], "-o/--output ./link.txt names the same file as --cell cell.yaml"),
    (["-o", "tcp.csv"], "-o tcp.csv: the name says CSV"),
    (["-o", "frame.txt"], ("-o/--output frame.txt names the same file as the touch file of "
                           "frames.fixture frame.txt, which this command reads")),
    (["-o", "res.json"], ("the name says JSON, but this writes the report (add --json for the "
                          "JSON result) as text")),
])
def test_calibrate_cell_o_is_checked_as_every_commands_and_changes_nothing(calibrated, capsys,
                                                                          args, message):
    """``-o`` onto the cell (through a hard or symbolic link too), onto a touch file the cell
    records, or named for another kind of file: exit 2, every file as it was."""
    os.link("cell.yaml", "cell.txt")
    os.symlink("cell.yaml", "link.txt")
    before = _snapshot(calibrated)
    code, _, err = run(capsys, "calibrate", "cell", "--cell", "cell.yaml", *args)
    assert code == 2 and message in err, err
    assert _snapshot(calibrated) == before
    assert Path("link.txt").is_symlink() and os.path.samefile("cell.yaml", "cell.txt")


def test_calibrate_cell_json_o_writes_the_result(calibrated, capsys):
    code, out, err = run(capsys, "calibrate", "cell", "--cell", "cell.yaml", "--json", "-o",
                         "res.json")
    assert code == 0, err
    assert json.loads(Path("res.json").read_text())["procedure"] == "cell"
    assert "verdict:" in out and "wrote res.json" in err  # the report on the terminal


# -- 1. concurrent updates ------------------------------------------------------------------------
def test_a_change_is_made_again_on_the_version_another_update_wrote(calibrated):
    """While a calibration runs, another process writes the cell: the change is repeated on
    that version, both results are in the file, and the backups are the versions in order."""
    notes, calls = [], []

    def change(cell):
        calls.append(cell)
        if len(calls) == 1:  # another update lands while this one computes
            other = Cell.load("cell.yaml")
            other.update_frame("part", other.frames["part"].pose, Provenance("manual", note="B"))
            other.save("cell.yaml")
        out = cellcal.tcp(cell, "tcp.csv", "torch", sigma=1e-4)
        return out.cell, out

    done = update_cell_file("cell.yaml", change, on_note=notes.append)
    assert done.repeated and len(calls) == 2
    assert any("updated by another process while this ran" in n for n in notes)
    cell = Cell.load("cell.yaml")
    assert cell.frames["part"].provenance.note == "B"
    assert cell.tools["torch"].provenance.source == "tcp"
    history = cell_history("cell.yaml")
    assert [v.changed for v in history[-2:]] == [["frame part"], ["tool torch"]]


def test_a_change_that_cannot_be_made_on_the_newer_version_writes_nothing(calibrated):
    def change(cell):
        if not (calibrated / "changed").exists():
            (calibrated / "changed").touch()
            other = Cell.load("cell.yaml")
            other.tools.pop("pointer")
            other.frames.pop("fixture")
            other.save("cell.yaml")
        out = cellcal.frame(cell, "frame.txt", "fixture", tool="pointer", sigma=1e-4)
        return out.cell, out

    with pytest.raises(InputError, match="pointer"):
        update_cell_file("cell.yaml", change)
    assert "pointer" not in Cell.load("cell.yaml").tools  # the other update's version, as it was


#: A process that says it is ready (its modules imported) in the file ``ready.N`` and
#: calibrates into the cell at the moment the file ``go`` appears.
WORKER = """
import os, pathlib, sys, time
import robotcell.cli.calibrate, robotcell.cli.calibrate_axes
from robotcell.cli import main
pathlib.Path(f"ready.{os.getpid()}").touch()
while not pathlib.Path("go").exists():
    time.sleep(0.005)
main(sys.argv[1:])
"""


def test_eight_processes_calibrating_one_cell_at_once_lose_nothing(calibrated):
    truth = Cell.load(EXAMPLE)
    simulate(truth, "turntable", seed=3, tool="pointer", noise=1e-4).write_csv("table.csv")
    jobs = [["calibrate", "tcp", "tcp.csv", "--name", f"t{k}"] for k in range(4)]
    jobs += [["calibrate", "frame", "frame.txt", "--tool", "pointer", "--name", f"f{k}"]
             for k in range(3)]
    jobs.append(["calibrate", "turntable", "table.csv", "--tool", "pointer"])
    items = [f"tool t{k}" for k in range(4)] + [f"frame f{k}" for k in range(3)]
    items.append("turntable DKP_400_01")
    procs = [subprocess.Popen([sys.executable, "-c", WORKER, *job, "--cell", "cell.yaml"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for job in jobs]
    deadline = time.monotonic() + 300
    while len(list(Path().glob("ready.*"))) < len(procs) and time.monotonic() < deadline:
        time.sleep(0.05)
    Path("go").touch()
    results = [(p.wait(timeout=300), *p.communicate()) for p in procs]
    cell = Cell.load("cell.yaml")
    written = {item for item, (code, _, err) in zip(items, results) if code == 0}
    for item, (code, out, err) in zip(items, results):
        assert code in (0, 2), err
        assert "Traceback" not in err
        if code == 2:  # refused: says why, and does not claim to have written
            assert "error:" in err and "updated cell.yaml" not in err, err
        else:
            assert "updated cell.yaml" in err
    assert len(written) >= 1
    assert {t for t in (f"tool {n}" for n in cell.tools) if t in items} == \
        {i for i in written if i.startswith("tool")}
    assert {f for f in (f"frame {n}" for n in cell.frames) if f in items} == \
        {i for i in written if i.startswith("frame")}
    assert (cell.turntable.provenance.measurements is not None) == \
        ("turntable DKP_400_01" in written)
    # One backup per update, in order: each version adds one result to the one before.
    history = cell_history("cell.yaml")
    assert [n for n, _ in backups("cell.yaml")] == list(range(1, len(history)))
    new = history[-len(written) - 1:]
    assert [len(v.changed) for v in new[1:]] == [1] * len(written)
    assert sorted(v.changed[0] for v in new[1:]) == sorted(written)
    for before, after in itertools.pairwise(new):
        assert set(before.provenance) <= set(after.provenance)
        kept = set(before.provenance) - set(after.changed)
        assert all(after.provenance[k] == before.provenance[k] for k in kept)


HOLDER = """
import sys, time
from robotcell.io.locking import file_lock
with file_lock("cell.yaml"):
    print("held", flush=True)
    time.sleep(float(sys.argv[1]))
"""


@contextmanager
def holder(seconds: float, kill: bool = False) -> Iterator[subprocess.Popen]:
    """Another process holding the lock of ``cell.yaml`` for ``seconds`` (killed at once with
    ``kill``, as ``kill -9`` does)."""
    proc = subprocess.Popen([sys.executable, "-c", HOLDER, str(seconds)], stdout=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout.readline().strip() == "held"
        if kill:
            proc.kill()
            proc.wait(timeout=30)
        yield proc
    finally:
        proc.kill()
        proc.wait(timeout=30)
        proc.stdout.close()


def _calibrate_tool(cell):
    out = cellcal.tcp(cell, "tcp.csv", "torch", sigma=1e-4)
    return out.cell, out


def test_a_process_killed_while_holding_the_lock_does_not_block_the_next_update(calibrated):
    with holder(600, kill=True):
        assert lock_path("cell.yaml").exists()  # left behind; the OS released the lock itself
        start = time.monotonic()
        done = update_cell_file("cell.yaml", _calibrate_tool)
    assert time.monotonic() - start < LOCK_WAIT / 2  # (the calibration: no wait)
    assert done.backup is not None and Cell.load("cell.yaml").tools["torch"].provenance.source \
        == "tcp"


def test_an_update_waits_for_the_lock_says_so_and_gives_up_with_nothing_written(calibrated):
    with holder(600):
        before = _snapshot(calibrated)
        notes = []
        start = time.monotonic()
        with pytest.raises(InputError, match=r"cell.yaml is being updated by another process, "
                           r"which has held its lock .*cell.yaml.lock for more than 1 s; nothing "
                           "was written"):
            update_cell_file("cell.yaml", _calibrate_tool, wait=1.0, on_note=notes.append)
        assert 1.0 <= time.monotonic() - start < LOCK_WAIT  # (the calibration, and 1 s)
        assert notes == [(f"waiting for cell.yaml: another process is updating it (lock "
                          f"{lock_path('cell.yaml')}); waiting at most 1 s")]
        assert _snapshot(calibrated) == before


def test_the_command_line_waits_for_an_update_and_then_writes(calibrated, capsys):
    with holder(6.0) as proc:  # (longer than the calibration before the lock)
        code, _, err = run(capsys, "calibrate", "tcp", "tcp.csv", "--cell", "cell.yaml",
                           "--name", "torch")
        assert proc.wait(timeout=30) == 0  # it let go, was not killed
    assert code == 0, err
    assert "waiting for cell.yaml: another process is updating it" in err
    assert "updated cell.yaml: tool 'torch'" in err


def test_the_lock_is_taken_again_by_its_holder(tmp_path):
    with file_lock(tmp_path / "a.yaml", wait=0), file_lock(tmp_path / "a.yaml", wait=0):
        pass
    with file_lock(tmp_path / "a.yaml", wait=0):  # released by the outer holder
        pass


# -- 2. links -------------------------------------------------------------------------------------
@pytest.fixture
def shared(calibrated) -> tuple[Path, Path]:
    """The calibrated cell moved to ``shared/``, linked into ``project/`` as ``cell.yaml``."""
    (calibrated / "shared").mkdir()
    (calibrated / "project").mkdir()
    for name in ("cell.yaml", "tcp.csv", "frame.txt"):
        shutil.move(name, calibrated / "shared" / name)
    for old in calibrated.glob("cell.yaml.*"):  # (its touch files are named relative to it)
        old.unlink()
    link = calibrated / "project" / "cell.yaml"
    os.symlink(os.path.join("..", "shared", "cell.yaml"), link)
    return calibrated / "shared" / "cell.yaml", link


def test_cell_through_a_symbolic_link_is_updated_where_it_points(shared, capsys):
    real, link = shared
    before = real.read_text()
    code, _, err = run(capsys, "calibrate", "tcp", real.parent / "tcp.csv", "--cell", link,
                       "--name", "torch")
    assert code == 0, err
    assert link.is_symlink() and link.resolve() == real.resolve()
    assert real.read_text() != before
    assert Cell.load(link).tools["torch"].provenance.source == "tcp"
    assert [p.name for p in real.parent.glob("cell.yaml.*.bak")] == ["cell.yaml.1.bak"]
    assert (real.parent / "cell.yaml.1.bak").read_text() == before
    assert sorted(p.name for p in link.parent.iterdir()) == ["cell.yaml"]  # nothing beside it
    assert [v.number for v in cell_history(link)] == [1, None]


def test_calibrate_cell_through_a_link_and_o_through_a_link(shared, capsys):
    real, link = shared
    (real.parent / "results").mkdir()
    os.symlink(os.path.join("..", "shared", "results", "res.json"), link.parent / "res.json")
    code, _, err = run(capsys, "calibrate", "cell", "--cell", link, "--json", "-o",
                       link.parent / "res.json")
    assert code == 0, err
    assert (link.parent / "res.json").is_symlink()
    assert json.loads((real.parent / "results" / "res.json").read_text())["procedure"] == "cell"
    assert link.is_symlink() and (real.parent / "cell.yaml.1.bak").is_file()
    assert "fitted with the whole cell" in Cell.load(real).tools["pointer"].provenance.note


def test_o_through_a_link_to_the_cell_is_refused(shared, capsys):
    real, link = shared
    os.symlink(real, link.parent / "out.txt")
    before = _snapshot(real.parent)
    code, _, err = run(capsys, "calibrate", "cell", "--cell", link, "-o", link.parent / "out.txt")
    assert code == 2 and "names the same file as --cell" in err
    assert _snapshot(real.parent) == before and (link.parent / "out.txt").is_symlink()


def test_a_cell_file_with_several_hard_links_is_refused_naming_why(calibrated, capsys):
    os.link("cell.yaml", "other.yaml")
    before = _snapshot(calibrated)
    code, _, err = run(capsys, "calibrate", "tcp", "tcp.csv", "--cell", "cell.yaml", "--name",
                       "torch")
    assert code == 2
    assert re.search(r"error: cannot write cell.yaml: the file has 2 hard links \(other names "
                     r"for the same file\); replacing it would leave the other names with the "
                     r"old content", err), err
    assert _snapshot(calibrated) == before
    assert os.path.samefile("cell.yaml", "other.yaml")
    with pytest.raises(InputError, match="2 hard links"):
        Cell.load("cell.yaml").save("cell.yaml")


def test_an_output_with_several_hard_links_is_refused_before_any_work(calibrated, capsys):
    Path("res.json").write_text("{}")
    os.link("res.json", "res_copy.json")
    before = _snapshot(calibrated)
    code, _, err = run(capsys, "calibrate", "tcp", "tcp.csv", "--json", "-o", "res.json")
    assert code == 2 and "-o/--output cannot write res.json: the file has 2 hard links" in err
    assert _snapshot(calibrated) == before
    with pytest.raises(InputError, match="2 hard links"):
        atomic_write("res.json", "[]")


def test_an_output_through_a_symbolic_link_is_written_where_it_points(tmp_path, capsys,
                                                                      monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "data").mkdir()
    os.symlink(os.path.join("data", "model.yaml"), "model.yaml")
    code, _, err = run(capsys, "dh", "convert", str(ROOT / "src" / "robotcell" / "robots"
                                                    / "kuka_kr16.yaml"),
                       "--to", "modified", "-o", "model.yaml")
    assert code == 0, err
    assert Path("model.yaml").is_symlink() and load_robot("data/model.yaml").convention == \
        "modified"
    atomic_write("model.yaml", textwrap.dedent("x: 1\n"))
    assert Path("model.yaml").is_symlink() and Path("data/model.yaml").read_text() == "x: 1\n"
