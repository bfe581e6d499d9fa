"""The technician's path as written: the calibration sequence of the README and of
docs/calibration.md ("Commissioning a cell, step by step") runs in order, each command on the
files the step before wrote, every step exiting 0 and every calibration graded GOOD or CHECK."""

from __future__ import annotations

import json
import re
import shlex
import shutil
from pathlib import Path

from cli_helpers import run

ROOT = Path(__file__).resolve().parent.parent
BLOCK = re.compile(r"^```sh\n(.*?)^```", re.DOTALL | re.MULTILINE)


def _lines(text: str) -> list[str]:
    """The command lines of the ```sh blocks of ``text``, comments dropped."""
    return [line.split(" #")[0].strip() for block in BLOCK.findall(text)
            for line in block.splitlines() if line.strip() and not line.startswith("#")]


def _section(path: Path, heading: str) -> str:
    text = path.read_text(encoding="utf-8")
    start = text.index(f"\n{heading}\n")
    end = text.find("\n## ", start + 1)
    return text[start:end if end > 0 else None]


def readme_sequence() -> list[str]:
    """The commands of the first block of the README's calibration section."""
    return _lines(BLOCK.search(_section(ROOT / "README.md", "## Calibration"))[0])


def docs_sequence() -> list[str]:
    """The commands of docs/calibration.md, "Commissioning a cell, step by step", in order."""
    return _lines(_section(ROOT / "docs" / "calibration.md",
                           "## Commissioning a cell, step by step"))


def test_the_readme_and_the_guide_give_one_sequence():
    steps = readme_sequence()
    assert steps == docs_sequence()
    # In the order of the issue: tool, track, turntable, frames, workpiece, then export.
    order = [next(i for i, c in enumerate(steps) if c.startswith(f"robotcell {what}"))
             for what in ("calibrate tcp", "calibrate track", "calibrate turntable",
                          "calibrate frame", "calibrate workpiece", "export")]
    assert order == sorted(order)
    # Where the inputs come from on a real cell is said beside the steps that need them.
    guide = _section(ROOT / "docs" / "calibration.md", "## Commissioning a cell, step by step")
    for said in ("**Where the `--reference` points come from:**", "**The sign of `--height`:**",
                 "Columns `a1..a6`, `e1`", "`--height=-h`"):
        assert said in guide


def test_the_sequence_runs_in_order_on_the_files_each_step_writes(tmp_path, capsys,
                                                                  monkeypatch):
    monkeypatch.chdir(tmp_path)
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    written: set[str] = set()
    verdicts = {}
    for command in readme_sequence():
        argv = shlex.split(command)
        if argv[0] == "cp":
            shutil.copy(argv[1], argv[2])
            written.add(argv[2])
            continue
        assert argv[0] == "robotcell", command
        # Every file a command reads was written by a step before it.
        reads = [a for a in argv[2:] if re.fullmatch(r"[\w.]+\.(csv|json|yaml)", a)
                 and argv[argv.index(a) - 1] not in ("-o", "--output")]
        assert set(reads) <= written, (command, set(reads) - written)
        code, out, err = run(capsys, *argv[1:])
        assert code == 0, f"{command}\n{err}"
        assert "Traceback" not in out + err and "warning" not in err
        if argv[1] == "calibrate":
            line = re.search(r"^verdict: (\w+):", out, re.MULTILINE)  # the report
            verdicts[argv[2]] = line[1].lower() if line else json.loads(out)["verdict"]["level"]
        for opt in ("-o", "--output"):
            if opt in argv:
                written.add(argv[argv.index(opt) + 1])
                assert Path(argv[argv.index(opt) + 1]).is_file(), command
    assert set(verdicts) == {"tcp", "track", "turntable", "frame", "workpiece"}
    assert set(verdicts.values()) <= {"good", "check"}, verdicts
    assert len(list(tmp_path.glob("cell.yaml.*.bak"))) == 5  # one kept version per update
    assert "MACHINE_DEF" in Path("kuka_config.dat").read_text()
