"""robotcell installed where its user cannot write, run as that user, for the read-only tests.

:func:`read_only_install` copies the package being tested into a folder nobody can write
(folders mode 555, files 444, no ``__pycache__``), gives the user a home folder it cannot write
either, and runs ``robotcell`` from that copy (``PYTHONPATH``, ahead of any installed one) in a
new process with only ``PATH``, ``PYTHONPATH``, ``HOME`` and ``LANG`` set (no ``NUMBA_CACHE_DIR``,
no ``XDG_CACHE_HOME``, no ``MPLCONFIGDIR``): a shared install, a container run as another user, a
service account.

Permissions bind a user other than root only. As root (CI, containers), the process runs as the
unprivileged user ``nobody`` (``setpriv``, util-linux). If ``nobody`` cannot read the Python
interpreter, the test's virtual environment or the repository (a venv or a pyenv under
``/root``, mode 700), the process keeps one capability, ``CAP_DAC_READ_SEARCH``: it may read any
file and list any folder, and every write is still checked against ``nobody``'s rights. As
another user, the process runs as that user. Where none of this can be arranged (no
``setpriv``, no ``nobody``), the tests are skipped, saying why.
"""

from __future__ import annotations

import json
import os
import pwd
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pytest

import robotcell

PACKAGE = Path(robotcell.__file__).resolve().parent
ROOT = Path(__file__).resolve().parents[1]
#: What the user's process must be able to read: robotcell's dependencies and the repository.
PROBE = ("import os, sys, numba, scipy.optimize, click, robotcell\n"
         "os.listdir(sys.argv[1])\n"
         "assert robotcell.__file__.startswith(sys.argv[2]), robotcell.__file__\n")
#: Runs ``robotcell ARGS`` as the console script does, from the read-only copy only.
MAIN = ("import sys, robotcell\n"
        "assert robotcell.__file__.startswith(sys.argv.pop(1)), robotcell.__file__\n"
        "from robotcell.cli import main\n"
        "sys.exit(main())\n")
#: Runs ``robotcell ARGS`` in FOLDER for each ``[ARGS, FOLDER]`` of the JSON list on stdin, one
#: after the other in this one process, as ``cli_helpers.run`` does in the tests' process; prints
#: their ``[exit status, stdout, stderr]`` as JSON.
RUNS = ("import contextlib, io, json, os, sys, robotcell\n"
        "assert robotcell.__file__.startswith(sys.argv[1]), robotcell.__file__\n"
        "from robotcell.cli import main\n"
        "results = []\n"
        "for args, folder in json.load(sys.stdin):\n"
        "    os.chdir(folder)\n"
        "    out, err = io.StringIO(), io.StringIO()\n"
        "    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):\n"
        "        try:\n"
        "            main(args)\n"
        "            code = 0\n"
        "        except SystemExit as exc:\n"
        "            code = exc.code or 0\n"
        "    results.append([code, out.getvalue(), err.getvalue()])\n"
        "print(json.dumps(results))\n")
#: A progress bar on stderr (``reach``, ``sweep``): drawn once a job has run 2 s, which a process
#: that compiles its kernels reaches sooner (timing, not a result).
PROGRESS = re.compile(r"^(layouts|targets)\b.*\n", re.MULTILINE)
READ_SEARCH = ["--inh-caps=+dac_read_search", "--ambient-caps=+dac_read_search"]


@dataclass
class ReadOnlyInstall:
    """A read-only copy of robotcell and the user who runs it.

    Attributes
    ----------
    site : Path
        Folder holding the read-only copy of the package (``site/robotcell``).
    home : Path
        The user's home folder, which it cannot write.
    work : Path
        A folder the user can write, for its inputs and outputs.
    user : list of str
        The command prefix that runs a program as the user (empty when the tests are not root).
    uid, gid : int
        The user's ids.
    """

    site: Path
    home: Path
    work: Path
    user: list[str]
    uid: int
    gid: int

    def env(self, **extra: str) -> dict[str, str]:
        """The whole environment of the user's process, plus ``extra``."""
        return {"PATH": "/usr/bin:/bin", "PYTHONPATH": str(self.site), "HOME": str(self.home),
                "LANG": "C.UTF-8", **extra}

    def robotcell(self, args: list[str], cwd: Path, timeout: float = 900,
                  **env: str) -> subprocess.CompletedProcess[str]:
        """Run ``robotcell ARGS`` from the read-only copy, as the user, in ``cwd``, with ``env``
        added to its environment; its output as text."""
        return subprocess.run([*self.user, sys.executable, "-c", MAIN, str(self.site), *args],
                              cwd=cwd, env=self.env(**env), capture_output=True, text=True,
                              timeout=timeout, check=False)

    def robotcell_runs(self, runs: list[tuple[list[str], Path]],
                       timeout: float = 1800) -> list[tuple[int, str, str]]:
        """Run ``robotcell ARGS`` in FOLDER for each ``(ARGS, FOLDER)`` of ``runs``, as the user,
        in one process (Python warnings are errors, as in the tests); their exit status, stdout
        and stderr. The process itself must print nothing else."""
        proc = subprocess.run([*self.user, sys.executable, "-W", "error", "-c", RUNS,
                               str(self.site)], cwd=self.work, env=self.env(),
                              input=json.dumps([[a, str(f)] for a, f in runs]),
                              capture_output=True, text=True, timeout=timeout, check=False)
        assert proc.returncode == 0 and proc.stderr == "", proc.stderr
        return [tuple(r) for r in json.loads(proc.stdout.splitlines()[-1])]

    def give(self, path: Path) -> Path:
        """Make ``path`` (and what it holds) the user's, so that it can write there."""
        if os.geteuid() == 0:
            for p in [path, *path.rglob("*")]:  # a link's own owner, whether or not it points
                os.chown(p, self.uid, self.gid, follow_symlinks=False)
        return path


def _copy_read_only(site: Path) -> None:
    shutil.copytree(PACKAGE, site / "robotcell",
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    for p in sorted(site.rglob("*"), reverse=True):
        p.chmod(0o555 if p.is_dir() else 0o444)
    site.chmod(0o555)


def _as_user(install: ReadOnlyInstall) -> tuple[list[str], int, int]:
    """The command prefix that runs a program as an unprivileged user who can read this Python,
    its packages and the repository, and that user's ids; skips the test where there is none."""
    if os.geteuid() != 0:
        return [], os.getuid(), os.getgid()
    setpriv = shutil.which("setpriv")
    if setpriv is None:
        pytest.skip("running as root without setpriv (util-linux) to run as another user")
    try:
        nobody = pwd.getpwnam("nobody")
    except KeyError:
        pytest.skip("running as root, and there is no user 'nobody' to run as")
    why = [""]
    for caps in ([], READ_SEARCH):
        prefix = [setpriv, f"--reuid={nobody.pw_uid}", f"--regid={nobody.pw_gid}",
                  "--clear-groups", *caps]
        probe = subprocess.run([*prefix, sys.executable, "-c", PROBE, str(ROOT),
                                str(install.site)], cwd=install.site, env=install.env(),
                               capture_output=True, text=True, timeout=120, check=False)
        if probe.returncode == 0:
            return prefix, nobody.pw_uid, nobody.pw_gid
        why = probe.stderr.strip().splitlines()[-1:] or [f"exit {probe.returncode}"]
    pytest.skip(f"user 'nobody' cannot run this Python and robotcell's dependencies: {why[0]}")


@contextmanager
def read_only_install() -> Iterator[ReadOnlyInstall]:
    """A read-only copy of robotcell, its user and a folder that user can write; removed after.

    Skips the test (saying why) where no unprivileged user can be arranged.
    """
    base = Path(tempfile.mkdtemp(prefix="robotcell-read-only-"))
    base.chmod(0o755)  # the user must reach the copy and its work folder
    install = ReadOnlyInstall(site=base / "site", home=base / "home", work=base / "work",
                              user=[], uid=-1, gid=-1)
    try:
        _copy_read_only(install.site)
        install.home.mkdir(mode=0o555)
        install.work.mkdir()
        install.user, install.uid, install.gid = _as_user(install)
        install.give(install.work)
        yield install
    finally:
        for p in [base, *base.rglob("*")]:
            if p.is_dir() and not p.is_symlink():
                p.chmod(0o755)
        shutil.rmtree(base)
