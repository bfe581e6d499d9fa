"""Kernels written once: Python first, compiled by numba once single-pose calls add up."""

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

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


def _double(x):
    return 2.0 * x


def _double_sum(x):
    s = 0.0
    for i in range(x.shape[0]):
        s += _double(x[i])
    return s


def _triple(x):
    return 3.0 * x


def _triple_sum(x):
    s = 0.0
    for i in range(x.shape[0]):
        s += _triple(x[i])
    return s


def test_a_kernel_calls_its_helpers_in_python_and_compiled(monkeypatch):
    # A kernel split into functions of its file: the batch calls them as Python (on arrays), the
    # compiled kernel compiled; a helper not given to the Kernel is refused by numba.
    from numba.core.errors import TypingError

    monkeypatch.setattr(jit, "_KERNELS", [])
    x = np.array([1.0, 2.0, 3.0])
    k = jit.Kernel(_double_sum, (_double,))
    assert k.fn(x) == 12.0
    assert k.compile()(x) == 12.0
    np.testing.assert_array_equal(k.fn(np.array([x, -x]).T), [12.0, -12.0])  # still Python
    with pytest.raises(TypingError, match="_triple"):
        jit.Kernel(_triple_sum).compile()(x)


def _halve(x):
    return 0.5 * x


def test_a_helper_compiled_inline_is_inlined_into_its_callers():
    # A helper split out of a hot compiled kernel costs no call: numba inlines it.
    helper = jit.compiled(inline=True)(_halve)
    assert helper.targetoptions["inline"] == "always"
    assert helper(3.0) == 1.5
    assert jit.compiled(_halve).targetoptions["inline"] == "never"


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


def _triple_in(folder: Path):
    """A function defined in a module file of its own in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "kern.py").write_text("def triple(x):\n    return 3.0 * x\n")
    spec = importlib.util.spec_from_file_location(f"kern_{folder.name}", folder / "kern.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.triple


@pytest.mark.parametrize("writable", [None, "NUMBA_CACHE_DIR", "__pycache__", "user-wide"])
def test_machine_code_is_cached_where_numba_can_write_else_compiled_in_memory(writable, tmp_path,
                                                                              monkeypatch):
    # numba's places, in its order: NUMBA_CACHE_DIR, __pycache__ beside the source, the user-wide
    # cache ($XDG_CACHE_HOME/numba). A file where a folder must be makes a place unwritable,
    # for root too.
    import numba

    src = tmp_path / writable if writable else tmp_path / "none"
    places = {"NUMBA_CACHE_DIR": tmp_path / "cache", "__pycache__": src / "__pycache__",
              "user-wide": tmp_path / "xdg" / "numba"}
    for name, place in places.items():
        if name != writable:
            place.parent.mkdir(parents=True, exist_ok=True)
            place.write_text("not a folder")
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(places["NUMBA_CACHE_DIR"])
                        if writable == "NUMBA_CACHE_DIR" else "")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setattr(jit, "_CACHE_WRITABLE", {})
    fn = _triple_in(src)
    f = jit.compiled(fn)  # no error where numba's cache=True raises
    assert f(2.0) == 6.0
    cached = list(tmp_path.rglob("kern.triple-*.nbi"))  # numba's index of the machine code
    if writable is None:
        with pytest.raises(RuntimeError, match="cannot cache function 'triple'"):
            numba.njit(cache=True)(fn)
        assert cached == [] and jit._CACHE_WRITABLE == {str(src): False}
    else:
        assert len(cached) == 1 and cached[0].is_relative_to(places[writable])
        assert jit._CACHE_WRITABLE == {str(src): True}
