"""``robotcell calibrate track | turntable | workpiece``: external-axis calibration from CSV.

Registered in :data:`robotcell.cli.calibrate.REGISTERED`. CSV columns: ``x,y,z`` (mm, TCP in the
robot base) or ``a1..a6`` with ``--robot``/``--tool``; ``e1`` = track position (mm) or table angle
(deg); ``point`` as described per command.
"""

from __future__ import annotations

import json
from pathlib import Path

import click
import numpy as np

from robotcell.calibration.measurements import (
    check_count,
    check_no_repeats,
    external_axis,
    point_roles,
    tcp_positions,
)
from robotcell.cli.calibrate import (
    POSE_COLUMNS,
    emit,
    measurement_options,
    raw_rows,
    robot_and_tool,
    sigma_m,
)
from robotcell.cli.common import parse_numbers, read_csv, require_columns
from robotcell.errors import InputError
from robotcell.transforms import validate_pose


def _labels(n: int) -> list[str]:
    return [f"line {i + 2}" for i in range(n)]


def _reference_indices(cols: dict, n_refs: int, path: str) -> np.ndarray | None:
    """0-based reference index per touch from column ``point`` (1-based in the CSV)."""
    if "point" not in cols:
        if n_refs > 1:
            raise InputError(f"{path}: {n_refs} --reference points given; add a column 'point' "
                             f"saying which one (1..{n_refs}) each touch is")
        return None
    if n_refs == 0:
        raise InputError(f"{path}: column 'point' names reference points, but no --reference "
                         "was given")
    idx = require_columns(cols, ["point"], path)[:, 0]
    if not np.all(idx == np.round(idx)) or idx.min() < 1 or idx.max() > n_refs:
        raise InputError(f"{path}: column 'point' must hold reference numbers 1..{n_refs} "
                         "(in the order of the --reference options)")
    return idx.astype(int) - 1


@click.command("track")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--reference", "references", multiple=True, metavar="X,Y,Z",
              help="Known coordinates (mm) of a touched reference point in the track frame L; "
                   "repeat for several points (column 'point' = 1, 2, ... says which is touched).")
@click.option("--axis", type=click.Choice(["x", "z"]), default="x", show_default=True,
              help="Axis of L along which the carriage moves: x (lecture) or z (KUKA external "
                   "kinematics).")
@click.option("--roll", type=click.Choice(["zero"]), default=None,
              help="Without --reference: return the full rotation L_Q_R with zero roll about the "
                   "track axis (a convention, not a measurement).")
@measurement_options
def track(measurements: str, references: tuple[str, ...], axis: str, roll: str | None,
          robot: str | None, tool: str | None, sigma: float | None, as_json: bool) -> None:
    """Linear track: direction in the robot base, scale, straightness; rotation when determined.

    \b
    Rows: TCP touches of fixed reference point(s) at different track positions e1 (mm).
    Without --reference the point is unknown and the rotation about the track axis is not
    determined (--roll zero fixes it by convention). One --reference point off the track axis
    gives the rotation (carriage offset taken as zero); two or more also give the offset.
    """
    from robotcell.calibration.track import calibrate_track

    model, T_tool = robot_and_tool(robot, tool)
    cols = read_csv(measurements)
    f = tcp_positions(cols, measurements, model, T_tool)
    e = external_axis(cols, measurements, "track")
    check_count(len(f), 3, "touches", measurements)
    check_no_repeats(raw_rows(cols, POSE_COLUMNS + ["e1", "point"]), measurements)
    refs = np.array([parse_numbers(r, "--reference", 3) for r in references]) * 1e-3
    idx = _reference_indices(cols, len(refs), measurements)
    result = calibrate_track(e, f, references=refs if len(refs) else None, point=idx, axis=axis,
                             roll=roll, labels=_labels(len(f)), prior_sigma=sigma_m(sigma))
    emit(result, as_json)


@click.command("turntable")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--height", type=float, default=0.0, show_default=True, metavar="MM",
              help="Shift of the frame origin along the table axis from the plane of the touched "
                   "point (mm), e.g. -20 when the point is 20 mm above the table top.")
@measurement_options
def turntable(measurements: str, height: float, robot: str | None, tool: str | None,
              sigma: float | None, as_json: bool) -> None:
    """Turntable root frame B (R_T_B) and radius from touches of one point on the table.

    \b
    Rows: TCP touches of one point on the table at different table angles e1 (deg); at least
    3, better 4 or more spread around the full turn. Save --json output for
    'robotcell calibrate workpiece --turntable'.
    """
    from robotcell.calibration.turntable import calibrate_turntable

    model, T_tool = robot_and_tool(robot, tool)
    cols = read_csv(measurements)
    f = tcp_positions(cols, measurements, model, T_tool)
    theta = external_axis(cols, measurements, "table")
    check_count(len(f), 3, "touches", measurements)
    check_no_repeats(raw_rows(cols, POSE_COLUMNS + ["e1"]), measurements)
    result = calibrate_turntable(theta, f, height=height * 1e-3, labels=_labels(len(f)),
                                 prior_sigma=sigma_m(sigma))
    emit(result, as_json)


def _load_turntable(path: str) -> tuple[np.ndarray, np.ndarray | None, float | None]:
    """``T_R_B`` (m), its 6x6 covariance (SI) and the touch noise (m) from turntable JSON."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not JSON ({exc}); pass the --json output of "
                         "'robotcell calibrate turntable'") from None
    if not isinstance(data, dict) or data.get("procedure") != "turntable" or "matrix" not in data:
        raise InputError(f"{path}: not a turntable result; pass the --json output of "
                         "'robotcell calibrate turntable'")
    try:
        T = np.array(data["matrix"], dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{path}: 'matrix' must be a 4x4 array of numbers") from None
    if T.shape != (4, 4):
        raise InputError(f"{path}: 'matrix' must be 4x4, got shape {T.shape}")
    T[:3, 3] *= 1e-3
    T = validate_pose(T, f"{path}: matrix")
    cov = data.get("T_R_B_covariance_mm_rad")
    if cov is not None:
        cov = np.array(cov, dtype=float)
        if cov.shape != (6, 6) or not np.all(np.isfinite(cov)):
            cov = None
        else:
            to_si = np.array([1e-3, 1e-3, 1e-3, 1.0, 1.0, 1.0])
            cov = cov * np.outer(to_si, to_si)
    noise = data.get("noise_sigma_mm")
    return T, cov, (float(noise) * 1e-3 if noise is not None else None)


@click.command("workpiece")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--turntable", "turntable_json", required=True, metavar="TURNTABLE.json",
              type=click.Path(dir_okay=False),
              help="--json output of 'robotcell calibrate turntable'.")
@measurement_options
def workpiece(measurements: str, turntable_json: str, robot: str | None, tool: str | None,
              sigma: float | None, as_json: bool) -> None:
    """Workpiece frame B_T_W on a calibrated turntable (3-point, or several touches per point).

    \b
    Rows: TCP touches with the table angle e1 (deg, any angle, recorded at every touch) and
    column point = origin, x (a point on +X) or xy (a point in the XY plane with +Y).
    The moving pose is R_T_W(theta) = R_T_B Rz(theta) B_T_W.
    """
    from robotcell.calibration.workpiece import calibrate_workpiece

    model, T_tool = robot_and_tool(robot, tool)
    T_R_B, cov, noise = _load_turntable(turntable_json)
    cols = read_csv(measurements)
    f = tcp_positions(cols, measurements, model, T_tool)
    theta = np.radians(require_columns(cols, ["e1"], measurements)[:, 0])
    roles = point_roles(cols, measurements)
    check_no_repeats(raw_rows(cols, POSE_COLUMNS + ["e1"]), measurements)
    result = calibrate_workpiece(theta, f, roles, T_R_B, T_R_B_covariance=cov, noise_sigma=noise,
                                 prior_sigma=sigma_m(sigma),
                                 labels=[f"line {i + 2} ({r})" for i, r in enumerate(roles)])
    emit(result, as_json)
