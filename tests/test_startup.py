"""Start-up: what each command imports (a behaviour test; the timings are in
benchmarks/bench_startup.py), and that the lazy imports change no public name or help text."""

import json
import subprocess
import sys
from pathlib import Path

import click
import pytest
from cli_helpers import run

import robotcell
from robotcell.cli import COMMANDS, _help_command, cli

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cell_kr16_track_turntable.yaml"
SRC = str(Path(robotcell.__file__).resolve().parents[1])


def loaded_after(args):
    """Top-level packages and robotcell modules loaded by a fresh ``robotcell ARGS`` process."""
    code = (
        "import json, sys\n"
        "from robotcell.cli import main\n"
        "try:\n"
        f"    main({list(args)!r})\n"
        "except SystemExit:\n"
        "    pass\n"
        "print(json.dumps(sorted(sys.modules)), file=sys.stderr)\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={"PYTHONPATH": SRC, "PATH": "/usr/bin:/bin"}, timeout=120,
                          check=True)
    return set(json.loads(proc.stderr.strip().splitlines()[-1]))


HEAVY = {"numpy", "scipy", "yaml", "matplotlib", "plotly", "numba", "llvmlite"}


@pytest.mark.parametrize("args", [[], ["--version"], ["--help"], ["-h"]],
                         ids=["import", "--version", "--help", "-h"])
def test_version_and_help_import_neither_numpy_nor_scipy(args):
    # [] still runs main() without a command: it prints the usage.
    modules = loaded_after(args)
    assert not {m.split(".")[0] for m in modules} & HEAVY
    # No command module is imported to list the commands.
    assert not modules & {t.split(":")[0] for t in COMMANDS.values()}


def test_calibrate_tcp_imports_what_it_needs_only(tmp_path, capsys):
    csv = tmp_path / "tcp8.csv"
    code, _, err = run(capsys, "simulate", "tcp", "--cell", EXAMPLE, "--tool", "torch",
                       "--touches", 8, "--no-orientation", "--seed", 1, "-o", csv)
    assert code == 0, err
    modules = loaded_after(["calibrate", "tcp", str(csv), "--robot", "kuka_kr16"])
    assert "robotcell.calibration.tcp" in modules
    # scipy.stats alone costs 0.2 s; matplotlib is for reports, plotly for 3D views; no other
    # command's module.
    assert "scipy.stats" not in modules and "matplotlib" not in modules
    # numba (0.5 s) loads for the IK and for loops of single poses, not for a batch of FK
    assert "numba" not in modules and "llvmlite" not in modules
    assert not {m for m in modules if m == "plotly" or m.startswith("plotly.")}
    others = {t.split(":")[0] for name, t in COMMANDS.items() if name != "calibrate"}
    assert not modules & others
    # A TCP calibration solves no IK: neither the IK package (which reading a cell's positioner
    # chain used to import for a constant) nor the cell's coupled IK.
    assert not {m for m in modules if m == "robotcell.ik" or m.startswith("robotcell.ik.")}
    assert "robotcell.cell.ik" not in modules
    # scipy: least_squares and Rotation (and what scipy.optimize imports itself); no sparse
    # linear algebra of our own, no integration, interpolation or signal processing.
    assert not modules & {"scipy.integrate", "scipy.interpolate", "scipy.signal", "scipy.ndimage",
                          "scipy.io", "scipy.cluster", "scipy.odr"}


def test_every_public_name_is_importable_as_before():
    from robotcell import errors
    from robotcell.io import poseformats
    from robotcell.kinematics import coupling, transforms
    from robotcell.robot import models as modelfile
    from robotcell.robot import robot

    home = {**{n: errors for n in ("IllPosedError", "InputError", "RobotcellError")},
            **{n: modelfile for n in ("list_robots", "load_robot", "robot_from_dict",
                                      "save_robot")},
            **{n: poseformats for n in ("FORMATS", "pose_from_vendor", "pose_to_vendor")},
            **{n: robot for n in ("Joint", "Robot")}, "Coupling": coupling}
    for name in robotcell.__all__:
        assert getattr(robotcell, name) is getattr(home.get(name, transforms), name), name
    assert set(home) | {n for n in robotcell.__all__ if hasattr(transforms, n)} == set(
        robotcell.__all__)
    assert set(robotcell.__all__) <= set(dir(robotcell))
    with pytest.raises(AttributeError, match="has no attribute 'no_such_name'"):
        robotcell.no_such_name  # noqa: B018


def test_help_lists_each_command_with_its_own_help():
    ctx = click.Context(cli)
    assert cli.list_commands(ctx) == sorted(COMMANDS)
    for name in COMMANDS:
        real = cli.get_command(ctx, name)
        for limit in (45, 80):
            assert _help_command(name).get_short_help_str(limit) == \
                real.get_short_help_str(limit), name


def test_one_pose_of_fk_does_not_load_numba():
    # A command that computes one pose runs the kernels as Python (robotcell.kinematics.jit).
    modules = loaded_after(["fk", "kuka_kr16", "--joints", "10,-80,90,0,45,0"])
    assert "robotcell.cli.fk" in modules
    assert "numba" not in modules


def test_view_loads_plotly_only_to_draw():
    # plotly (about 0.3 s to import) is loaded by the functions that draw, not by the command's
    # module: its --help and a refused input do without it.
    for args in (["view", "--help"], ["view", str(EXAMPLE), "--joints", "1,2", "-o", "x.html"]):
        modules = loaded_after(args)
        assert "robotcell.cli.view" in modules
        assert not {m for m in modules if m == "plotly" or m.startswith("plotly.")}, args
