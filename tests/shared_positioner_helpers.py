"""The two-robot demo's folder and the ``calibrate shared-positioner`` command line on it, for
the tests of the shared positioner's command and of its ``--update-cell``."""

from pathlib import Path

from robotcell.demo.tworobots import run_two_robot_demo


def demo_folder(folder: Path) -> Path:
    """``folder`` filled by the two-robot demo (seed 3): the calibrated cell, the true cell and
    every touch file."""
    run_two_robot_demo(folder, seed=3, echo=lambda line: None)
    return folder


def shared_args(d: Path, cell: str = "cell.yaml", *extra: str) -> list:
    """``robotcell calibrate shared-positioner`` on the demo's files in ``d`` (KUKA reference
    at track 1000 mm, both torches, 0.1 mm touches, 0.13 mm tools), then ``extra``."""
    return ["calibrate", "shared-positioner", d / "positioner_kuka.csv",
            d / "positioner_abb.csv", "--common", d / "robot_to_robot_kuka.csv",
            d / "robot_to_robot_abb.csv", "--cell", d / cell, "--reference", "kuka",
            "--robot", "abb", "--tool-ref", "torch", "--tool-other", "torch", "--track-ref",
            "1000", "--sigma", "0.1", "--tool-sigma", "0.13", *extra]
