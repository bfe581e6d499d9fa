"""The README's commands print what they printed when the layout of the package last changed.

A change of the package's layout (moving code between modules, registries, context objects) must
leave what a user sees alone. This test runs the README's commands, as tests/test_docs_commands.py
and tests/test_commissioning.py do, and compares their output, normalised for what changes from
run to run (the folder, timings, dates, file checksums, the sign of a printed zero), with
``tests/data/readme_golden.json``.

A deliberate change of output is recorded by running ``ROBOTCELL_GOLDEN=write pytest
tests/test_readme_golden.py`` and committing the new file with the reason in the commit message.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
from pathlib import Path

import pytest
from cli_helpers import run
from test_commissioning import readme_sequence
from test_docs_commands import commands, left_out, prepare

ROOT = Path(__file__).resolve().parent.parent
GOLDEN = ROOT / "tests" / "data" / "readme_golden.json"

#: What differs between two runs of the same command: the folder, times, dates, checksums.
VARIABLE = [
    (re.compile(r"/\S*/readme\d*"), "<folder>"),
    (re.compile(r"\b\d+(\.\d+)? ?(s|ms|seconds)\b"), "<time>"),
    (re.compile(r"\d{4}-\d\d-\d\d[T ]\d\d:\d\d(:\d\d(\.\d+)?)?([+-]\d\d:?\d\d|Z)?"), "<date>"),
    (re.compile(r"\b[0-9a-f]{12,64}\b"), "<hash>"),
    # A zero printed with the sign of a rounding error (-0.0000) is the same number.
    (re.compile(r"-(0\.0+)(?![0-9])"), r" \1"),
]


def _normalise(text: str) -> str:
    for pattern, replacement in VARIABLE:
        text = pattern.sub(replacement, text)
    return text


def _readme_commands() -> list[str]:
    """The README's commands, in the order a reader meets them, as the docs tests run them."""
    sequence = readme_sequence()
    listed = [c for f, _, c in commands() if f == "README.md" and left_out(c) is None
              and c not in sequence]
    return [*sequence, *listed]


def _outputs(folder: Path, capsys) -> dict[str, str]:
    shutil.copytree(ROOT / "examples", folder / "examples")
    seen: dict[str, str] = {}
    for command in _readme_commands():
        argv = shlex.split(command)
        if argv[0] == "cp":
            shutil.copy(argv[1], argv[2])
            continue
        if command not in readme_sequence():
            prepare(capsys, argv[1:])
        code, out, err = run(capsys, *argv[1:])
        seen[command] = _normalise(f"exit {code}\n--- stdout\n{out}--- stderr\n{err}")
    return seen


def test_the_readme_commands_print_what_they_printed(tmp_path, capsys, monkeypatch):
    folder = tmp_path / "readme"
    folder.mkdir()
    monkeypatch.chdir(folder)
    # A progress bar appears after a job has run a while: when, depends on the machine's load.
    monkeypatch.setattr("robotcell.cli.progress.PROGRESS_AFTER", float("inf"))
    seen = _outputs(folder, capsys)
    if os.environ.get("ROBOTCELL_GOLDEN") == "write":
        GOLDEN.write_text(json.dumps(seen, indent=1, sort_keys=False) + "\n", encoding="utf-8")
        pytest.skip("golden file written")
    golden = json.loads(GOLDEN.read_text(encoding="utf-8"))
    assert sorted(seen) == sorted(golden), "the README's commands changed: write the file anew"
    changed = [c for c in golden if seen[c] != golden[c]]
    assert not changed, "\n\n".join(f"{c}\nwas:\n{golden[c]}\nnow:\n{seen[c]}" for c in changed)
