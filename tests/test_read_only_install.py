"""robotcell installed where its user cannot write, run by a user without a writable home: the
commands that solve IK exit 0 with the same results as a normal run, and print nothing more.

numba caches compiled machine code beside the source or in the user's cache folder; where it can
write neither, robotcell compiles its kernels in memory, in each process
(:func:`robotcell.kinematics.jit.compiled`); a cache folder the user sets (``NUMBA_CACHE_DIR``)
keeps them. The commands are the README's; each runs in a new process from a read-only copy of
the package, as an unprivileged user (tests/readonly_helpers.py), and in this process as a normal
run, on copies of the same inputs.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from cli_helpers import run
from readonly_helpers import PROGRESS, ROOT, read_only_install

CELL = "examples/cell_kr16_track_turntable.yaml"
#: name: (the command's arguments, the files it writes).
COMMANDS = {
    "ik": (["ik", "kuka_kr16", "--pose", "1200,0,1200,0,90,0", "--all"], []),
    "simulate": (["simulate", "tcp", "--cell", "truth.yaml", "--tool", "torch", "--touches", "6",
                  "--seed", "1", "-o", "tcp.csv"], ["tcp.csv"]),
    "identify": (["identify", "tracker.csv", "--robot", "kuka_kr16", "-o", "kr16_identified.yaml"],
                 ["kr16_identified.yaml"]),
    "reach": (["reach", "--cell", CELL, "examples/seam_part.csv", "--frame", "part", "--tool",
               "torch", "-o", "reach.csv"], ["reach.csv", "reach.html"]),
    "sweep": (["sweep", "--cell", CELL, "--targets", "examples/seam_part.csv", "--layouts",
               "examples/layouts_kr16.yaml", "--frame", "part", "--tool", "torch", "--workers", "1",
               "-o", "sweep.csv"], ["sweep.csv"]),
}


@pytest.fixture(scope="module")
def install():
    with read_only_install() as inst:
        yield inst


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """The commands' inputs: a copy of examples/, truth.yaml (the example cell) and tracker.csv
    (the block of docs/identification.md that simulates it)."""
    d = tmp_path_factory.mktemp("inputs")
    shutil.copytree(ROOT / "examples", d / "examples")
    shutil.copy(ROOT / CELL, d / "truth.yaml")
    text = (ROOT / "docs" / "identification.md").read_text(encoding="utf-8")
    block = next(b for b in re.findall(r"^```python\n(.*?)^```", text, re.DOTALL | re.MULTILINE)
                 if '"tracker.csv"' in b)
    exec(compile(block.replace('"tracker.csv"', repr(str(d / "tracker.csv"))),  # noqa: S102
                 "identification.md", "exec"), {})
    return d


@pytest.fixture(scope="module")
def runs(install, inputs) -> dict[str, subprocess.CompletedProcess[str]]:
    """Each command run from the read-only install in a folder of its own, and the first run of
    ``ik`` with a cache folder: all at once, each in its own process (each compiles what it
    needs)."""
    jobs = {name: (args, install.give(shutil.copytree(inputs, install.work / name)), {})
            for name, (args, _) in COMMANDS.items()}
    cache = install.work / "numba-cache"  # numba makes it
    jobs["cache"] = (COMMANDS["ik"][0], install.work, {"NUMBA_CACHE_DIR": str(cache)})
    with ThreadPoolExecutor(len(jobs)) as pool:
        futures = {name: pool.submit(install.robotcell, args, cwd, **env)
                   for name, (args, cwd, env) in jobs.items()}
        return {name: f.result() for name, f in futures.items()}


@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_read_only_install_gives_the_normal_results(name, install, inputs, runs, tmp_path,
                                                      capsys, monkeypatch):
    args, written = COMMANDS[name]
    proc, mine = runs[name], install.work / name
    assert proc.returncode == 0, proc.stderr
    normal = shutil.copytree(inputs, tmp_path / "normal")
    monkeypatch.chdir(normal)
    code, out, err = run(capsys, *args)
    assert code == 0, err
    # no error, no warning, no note more than a normal run
    assert (proc.stdout, PROGRESS.sub("", proc.stderr)) == (out, PROGRESS.sub("", err))
    for f in written:
        assert (mine / f).read_bytes() == (normal / f).read_bytes(), f
    # nothing written into the install or the home: compiled in memory
    assert not list(install.site.rglob("__pycache__")) and not list(install.home.iterdir())


def test_a_cache_folder_the_user_sets_keeps_the_compiled_kernels(install, runs):
    cache, first = install.work / "numba-cache", runs["cache"]
    assert first.returncode == 0 and first.stderr == "", first.stderr
    assert first.stdout == runs["ik"].stdout
    assert list(cache.rglob("kernels.*.nbi"))  # numba's index of the IK kernels
    # the next process loads them (numba's own log of its cache)
    second = install.robotcell(COMMANDS["ik"][0], install.work, NUMBA_CACHE_DIR=str(cache),
                               NUMBA_DEBUG_CACHE="1")
    assert second.returncode == 0 and second.stderr == "", second.stderr
    assert "data loaded from" in second.stdout and "data saved to" not in second.stdout
    assert second.stdout.endswith(first.stdout)
