"""Every ``robotcell`` shell command of README.md, docs/*.md and the --help texts runs as
documented.

The commands are taken from the ```sh, ```console and plain ``` blocks (a line that starts with
``robotcell``, backslash continuations joined, ``#`` comments dropped), from the concrete inline
commands of the prose (not the synopses with placeholders) and from the examples of every
command's --help. They run in process, in order, in a fresh folder that holds a copy of
``examples/``, as a user who runs them from the root of the repository. The input files a command
names are made the way the docs say: ``cell.yaml`` is a copy of the example cell (of the
positioner cell for positioner commands), touch files come from ``robotcell simulate``,
``joints.csv`` from ``identify --propose``, ``poses.csv`` from ``fk --input``, a cell for
``calibrate cell`` from a TCP and a turntable calibration into it, ``tracker.csv``
from the block of docs/identification.md that simulates it, the files of ``calibrate
shared-positioner`` from ``robotcell demo --robots 2``; the cell of a command that filters
(``compensate``, ``program compensate``, ``program check`` of a filtered program) gets the arm
identified from that ``tracker.csv`` (``identify ... --cell cell.yaml``, docs/accuracy.md). Each
command must exit 0 without a
traceback and write the files it names. ``LEFT_OUT`` lists the commands not run, and why.
"""

from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import pytest
from cli_helpers import run
from test_commissioning import readme_sequence

from robotcell.io.yamlfile import dump_yaml, parse_yaml

ROOT = Path(__file__).resolve().parent.parent
FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"^[ \t]*```([\w-]*)[ \t]*\n(.*?)^[ \t]*```[ \t]*$", re.DOTALL | re.MULTILINE)
TRACK_CELL = "examples/cell_kr16_track_turntable.yaml"
POSITIONER_CELL = "examples/cell_kr16_positioner.yaml"
#: An inline command (`robotcell ...` in the prose), and what makes one a synopsis, not a command.
INLINE = re.compile(r"`(robotcell [^`]+)`")
PLACEHOLDER = re.compile(r"\.\.\.|[|\[]|\b[A-Z]{3,}\b|\b[A-Z](,[A-Z])+\b")

#: Commands left out, with why (matched against the start of the command line).
LEFT_OUT = {
    # Synopses with placeholders, not commands.
    "robotcell dh from-urdf FILE": "a synopsis (FILE, [options])",
    "robotcell dh convert MODEL": "a synopsis",
    "robotcell dh explain MODEL": "a synopsis",
    "robotcell dh symbolic MODEL": "a synopsis",
    "robotcell simulate PROCEDURE": "a synopsis",
    "robotcell plan PROCEDURE": "a synopsis",
    # Touches typed from the pendant as positions or flange poses (x, y, z[, a, b, c]): the
    # user's own measurements; `simulate` writes joint values, which need --robot or --cell.
    # The same commands with --robot/--cell run below; tests/test_cli_calibrate.py runs these.
    "robotcell calibrate tcp touches.csv#": "pendant flange poses",
    "robotcell calibrate frame base.csv": "pendant positions",
    "robotcell calibrate external-tcp": "pendant positions",
    "robotcell calibrate track touches.csv": "pendant positions (with --cell it runs)",
    "robotcell calibrate turntable table.csv --json": "pendant positions (with --cell it runs)",
    "robotcell calibrate turntable table.csv --height": "pendant positions",
    "robotcell calibrate workpiece wp.csv --turntable": "pendant positions",
    "robotcell report turntable.json": "the --json of a pendant-position turntable run",
    # Minutes of computation, not seconds (each is timed in its own test or benchmark).
    "robotcell plan turntable": "a Monte Carlo of 100 calibrations, about 5 s; 'plan frame' in "
                                "plan --help runs (tests/test_plan.py)",
    "robotcell identify examples/identification/ipa_ur10_random_poses.csv":
        "5-fold cross-validation on 62 rows (tests/test_identification_real.py)",
    "robotcell sweep --cell cell.yaml --targets seam.csv --layouts layouts.yaml --scheduler":
        "needs a running Dask cluster (tests/test_sweep.py starts a local one)",
    "robotcell sweep --cell c.yaml --targets t.csv --layouts l.yaml --scheduler":
        "needs a running Dask cluster",
    "robotcell sweep --cell cell.yaml --targets seam.csv --layouts l.yaml --workers 8":
        "8 processes on a shared machine; --workers 2 runs above (README)",
    "robotcell demo -o /tmp/demo": "writes outside the test folder; 'robotcell demo' runs",
    "robotcell dh from-urdf ": "the user's URDF file (tests/test_cli_dh.py converts URDFs)",
    "robotcell dh explain arm.urdf": "the user's URDF file",
    "robotcell identify tracker.csv --robot fanuc_m20ia": "tracker.csv is a KR 16 set",
    "robotcell calibrate frame touches.csv#": "pendant positions",
    "robotcell calibrate track touches.csv --reference 1500,800,300#": "pendant positions",
    "robotcell report base.json": "the --json of a pendant-position frame run",
    "robotcell dh symbolic": "needs the 'symbolic' extra (sympy), 4-6 s each "
                             "(tests/test_dh_procedure_symbolic.py)",
    "robotcell identify --compliance#": "names an option in the prose, not a command",
    "robotcell fk --cell#": "names an option in the prose, not a command",
    "robotcell ik --cell#": "names an option in the prose, not a command",
    "robotcell identify fanuc.csv": "no simulated FANUC set in the docs (test_identification_cli)",
}


def commands() -> list[tuple[str, int, str]]:
    """(file name, line, command) of every robotcell command in the docs, in order."""
    found = []
    for path in FILES:
        text = path.read_text(encoding="utf-8")
        for m in BLOCK.finditer(text):
            if m.group(1) not in ("sh", "console", ""):
                continue
            first = text.count("\n", 0, m.start(2)) + 1
            lines = m.group(2).splitlines()
            i = 0
            while i < len(lines):
                line, start = lines[i].strip(), i
                while line.endswith("\\") and i + 1 < len(lines):
                    i += 1
                    line = line[:-1].rstrip() + " " + lines[i].strip()
                i += 1
                if line.startswith("robotcell "):
                    found.append((path.name, first + start, line.split(" #")[0].strip()))
        prose = BLOCK.sub(lambda m: "\n" * m.group(0).count("\n"), text)
        for m in INLINE.finditer(prose):
            command = " ".join(m.group(1).split())
            if ("--" in command or "." in command) and not PLACEHOLDER.search(command):
                found.append((path.name, prose.count("\n", 0, m.start()) + 1, command))
    return found


def help_examples() -> list[tuple[str, int, str]]:
    """("--help of CMD", line, command) of every example in the commands' help texts."""
    import click

    from robotcell.cli import cli

    found = []

    def walk(group: click.Group, path: tuple[str, ...]) -> None:
        for name in group.list_commands(click.Context(group)):
            cmd = group.get_command(click.Context(group), name)
            if isinstance(cmd, click.Group):
                walk(cmd, (*path, name))
                continue
            lines = (cmd.help or "").splitlines()
            for i, line in enumerate(lines):
                line = line.strip()
                while line.endswith("\\") and i + 1 < len(lines):
                    i += 1
                    line = line[:-1].rstrip() + " " + lines[i].strip()
                if line.startswith("robotcell "):
                    found.append((f"{' '.join((*path, name))} --help", i, line))

    walk(cli, ())
    return found


def left_out(command: str) -> str | None:
    """The reason a command is left out, or None."""
    for start, why in LEFT_OUT.items():
        if (command + "#").startswith(start):
            return why
    return None


def _simulate(capsys, procedure: str, out: str, cell: str, *extra: str) -> None:
    code, _, err = run(capsys, "simulate", procedure, "--cell", cell, "--seed", "1", "-o", out,
                       *extra)
    assert code == 0, err


def _tracker() -> None:
    """tracker.csv: run the block of docs/identification.md that simulates it."""
    text = (ROOT / "docs" / "identification.md").read_text(encoding="utf-8")
    code = next(b for b in re.findall(r"^```python\n(.*?)^```", text, re.DOTALL | re.MULTILINE)
                if '"tracker.csv"' in b)
    exec(compile(code, "identification.md", "exec"), {})  # noqa: S102


def prepare(capsys, argv: list[str]) -> None:
    """Make the input files ``argv`` names, the way the docs say."""
    positioner = "positioner" in argv or POSITIONER_CELL in argv
    truth = POSITIONER_CELL if positioner else TRACK_CELL
    shutil.copy(truth, "cell.yaml")
    for name, source in (("positioner.yaml", POSITIONER_CELL), ("c.yaml", TRACK_CELL),
                         ("seam.csv", "examples/seam_part.csv"),
                         ("t.csv", "examples/seam_part.csv"),
                         ("l.yaml", "examples/layouts_kr16.yaml"),
                         ("layouts.yaml", "examples/layouts_kr16.yaml")):
        if name in argv:
            shutil.copy(source, name)
    if "truth.yaml" in argv:
        shutil.copy(truth, "truth.yaml")
    if "truth_calibrated.yaml" in argv:  # docs/simulate.md: cp truth.yaml truth_calibrated.yaml
        shutil.copy(truth, "truth.yaml")
        shutil.copy(truth, "truth_calibrated.yaml")
    if argv[:2] == ["calibrate", "cell"]:  # a cell whose calibrations recorded their files
        for proc, extra in (("tcp", ["--name", "pointer"]),
                            ("turntable", ["--tool", "pointer", "--height=-50"])):
            _simulate(capsys, proc, f"{proc}.csv", truth, "--tool", "pointer")
            code, _, err = run(capsys, "calibrate", proc, f"{proc}.csv", "--cell", "cell.yaml",
                               "--sigma", "0.1", *extra)
            assert code == 0, err
        return
    if argv[:2] == ["calibrate", "shared-positioner"]:  # the files of the two-robot demo
        if not Path(argv[2]).exists():
            code, _, err = run(capsys, "demo", "--robots", "2", "-o", str(Path(argv[2]).parent))
            assert code == 0, err
        return
    if argv[:2] == ["calibrate", "robot-to-robot"]:  # two robots' files, simulated as documented
        code, _, err = run(capsys, "simulate", "robot-to-robot", "--seed", "1", "--ref-output",
                           argv[2], "--other-output", argv[3])
        assert code == 0, err
        return
    if argv[0] == "calibrate":
        proc, data = argv[1], argv[2]
        tool = argv[argv.index("--tool") + 1] if "--tool" in argv else "pointer"
        if tool not in ("torch", "pointer"):  # X,Y,Z,A,B,C: the pointer of the truth is that tool
            cell = parse_yaml(Path(truth).read_text(encoding="utf-8"), truth)
            x, y, z, a, b, c = map(float, tool.split(","))
            cell["tools"]["pointer"]["frame"] = {"x": x, "y": y, "z": z, "a": a, "b": b, "c": c}
            truth = "truth_tool.yaml"
            Path(truth).write_text(dump_yaml(cell), encoding="utf-8")
        extra = ["--tool", "torch" if proc == "tcp" or tool == "torch" else "pointer"]
        if proc in ("frame", "workpiece"):
            extra += ["--frame", "part" if proc == "workpiece" else "fixture"]
        _simulate(capsys, proc, data, truth, *extra)
        if "--cell" not in argv:  # a robot without a track (the column needs the cell file)
            header, *rows = Path(data).read_text(encoding="utf-8").splitlines()
            names = header.split(",")
            if "track" in names:
                k = names.index("track")
                Path(data).write_text("\n".join(",".join(v for j, v in enumerate(r.split(","))
                                                         if j != k) for r in [header, *rows]),
                                      encoding="utf-8")
    if argv[0] == "identify" and "tracker.csv" in argv:
        _tracker()
    if argv[:2] == ["program", "check-coordinated"]:  # the modules write-coordinated writes
        mod = Path(argv[2])
        code, _, err = run(capsys, "program", "write-coordinated", "rob1=examples/seam_rob1.csv",
                           "rob2=examples/seam_rob2.csv", "--cell",
                           "examples/cell_two_abb_positioner.yaml", "--tool", "torch", "--frame",
                           "part", "--format", "abb", "-o", str(mod.parent), "--name",
                           mod.stem.rsplit("_T_ROB", 1)[0])
        assert code == 0, err
    if argv[0] == "compensate" or (argv[0] == "program" and (
            argv[1] == "compensate" or any("filtered" in a for a in argv))):
        _tracker()
        code, _, err = run(capsys, "identify", "tracker.csv", "--robot", "kuka_kr16",
                           "--accuracy", "0.02", "--folds", "2", "-o", "kr16_identified.yaml",
                           "--cell", "cell.yaml")
        assert code == 0, err
    if argv[0] in ("fk", "ik") and "--input" in argv:
        given = argv[argv.index("--input") + 1]
        code, _, err = run(capsys, "identify", "--propose", "10", "--robot", "kuka_kr16",
                           "--seed", "1", "-o", "joints.csv")
        assert code == 0, err
        if argv[0] == "ik":  # poses.csv: what fk writes for these joints, same frame and format
            fk = ["fk", *(["--cell", "cell.yaml"] if "--cell" in argv else [argv[1]])]
            for opt in ("--format", "--frame", "--tool"):
                if opt in argv:
                    fk += [opt, argv[argv.index(opt) + 1]]
            code, _, err = run(capsys, *fk, "--input", "joints.csv", "--output", given)
            assert code == 0, err


#: The commissioning sequence of the README and docs/calibration.md runs in order, each command
#: on the files the step before wrote, in tests/test_commissioning.py.
SEQUENCE = set(readme_sequence())
CASES = [c for c in commands() + help_examples()
         if left_out(c[2]) is None and c[2] not in SEQUENCE]


def test_the_extraction_finds_the_commands():
    found = [c for _, _, c in commands()]
    assert any(c.startswith("robotcell sweep --cell examples/") and "--workers 2" in c
               for c in found)  # a continued line, joined
    assert "robotcell robots" in found and len(CASES) >= 35
    every = [c for _, _, c in commands() + help_examples()]
    unused = [k for k in LEFT_OUT if not any((c + "#").startswith(k) for c in every)]
    assert not unused, f"LEFT_OUT entries that match no command: {unused}"


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """One folder for the commands in order (a later command may read an earlier one's file)."""
    tmp = tmp_path_factory.mktemp("docs")
    shutil.copytree(ROOT / "examples", tmp / "examples")
    return tmp


@pytest.mark.parametrize("where,line,command", CASES,
                         ids=[f"{f}:{n}".replace(" ", "_") for f, n, _ in CASES])
def test_documented_command_runs(where, line, command, folder, capsys, monkeypatch):
    monkeypatch.chdir(folder)
    argv = shlex.split(command)[1:]
    prepare(capsys, argv)
    code, out, err = run(capsys, *argv)
    assert "Traceback" not in out + err
    assert code == 0, f"{where}:{line}: {command}\n{err}"
    for opt in ("-o", "--output", "--report"):
        if opt in argv:
            written = Path(argv[argv.index(opt) + 1])
            if argv[0] == "program":  # -o is the folder of the program files
                assert written.is_dir() and any(written.iterdir()), f"{opt} not written"
            else:
                assert written.is_file(), f"{opt} not written"

