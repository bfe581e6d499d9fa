"""Kernels written once: Python first, compiled by numba once single-pose calls add up."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

import robotcell
from robotcell.kinematics import jit

SRC = str(Path(robotcell.__file__).resolve().parents[1])


def _square_sum(x):
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i] * x[i]
    return s


def test_a_kernel_runs_as_python_until_its_budget_then_compiled(monkeypatch):
    monkeypatch.setattr(jit, "PYTHON_BUDGET", 0.0)
    monkeypatch.setattr(jit, "_KERNELS", [])
    k = jit.Kernel(_square_sum)
    x = np.array([1.0, 2.0, 3.0])
    assert k.call == k._python
    assert k.call(x) == 14.0  # Python (or compiled at once when numba is loaded)
    assert k.call != k._python and "numba" in sys.modules
    assert k.call(x) == 14.0  # compiled
    assert jit._KERNELS == [k]


def test_a_few_poses_never_load_numba_and_a_loop_does():
    # A fresh process: one-pose FK and the pose check stay Python (no 0.5 s to load numba);
    # past the budget the chain is compiled, and gives the same bits.
    code = (
        "import json, sys\n"
        "import numpy as np\n"
        "from robotcell import load_robot\n"
        "from robotcell.kinematics import dh, jit\n"
        "r = load_robot('kuka_kr16')\n"
        "q = np.array([0.1, -0.5, 0.4, 1.0, 0.3, -0.2])\n"
        "before = r.fk(q, tool=np.eye(4)); r.jacobian(q)\n"
        "few = 'numba' in sys.modules\n"
        "jit.PYTHON_BUDGET = 0.0\n"
        "r.fk(q)\n"
        "after = r.fk(q, tool=np.eye(4))\n"
        "print(json.dumps([few, 'numba' in sys.modules, dh.CHAIN.call != dh.CHAIN._python,\n"
        "                  bool(np.array_equal(before, after))]))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={"PYTHONPATH": SRC, "PATH": "/usr/bin:/bin"}, timeout=300,
                          check=True)
    assert json.loads(proc.stdout.strip().splitlines()[-1]) == [False, True, True, True]
