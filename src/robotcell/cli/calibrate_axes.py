"""``robotcell calibrate track | turntable | workpiece``: external-axis calibration from CSV.

Registered in :data:`robotcell.cli.calibrate.REGISTERED`. CSV columns: ``x,y,z`` (mm, TCP in the
robot base) or ``a1..a6`` with ``--robot``/``--tool``; ``e1`` = track position (mm) or table angle
(deg); ``point`` as described per command; with ``--cell``, ``track`` = track position of the
robot at each touch (mm) for the turntable and workpiece.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import click
import numpy as np

from robotcell.calibration.measurements import (
    check_count,
    external_axis,
    point_roles,
    tcp_positions,
)
from robotcell.cli.calibrate import (
    NO_CELL_TRACK,
    POSE_COLUMNS,
    CellTarget,
    cell_option,
    cell_provenance,
    emit,
    gate,
    measurement_options,
    note_repeats,
    refuse_track_column,
    require_name,
    robot_and_tool,
    sigma_m,
)
from robotcell.cli.common import parse_numbers, read_csv, require_columns
from robotcell.errors import InputError
from robotcell.fileio import read_text
from robotcell.transforms import invert, transform_points, validate_pose


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


def _cell_track_axis(target: CellTarget, axis: str | None, references: tuple[str, ...],
                     roll: str | None) -> str:
    """Track axis for ``calibrate track --cell``, refusing what cannot update ``T_L_R0``."""
    tr = target.cell.track
    if tr is None:
        raise InputError(f"{target.path} has no track to calibrate; add a 'track' section to the "
                         "cell file first")
    if tr.axis not in ("x", "z"):
        raise InputError(f"the track of {target.path} moves along its {tr.axis} axis; the track "
                         "calibration supports x and z: describe the track frame with the motion "
                         "along x or z")
    if axis is not None and axis != tr.axis:
        raise InputError(f"--axis {axis} differs from the track axis {tr.axis} of {target.path}; "
                         "drop --axis (it defaults to the cell's) or correct the cell file")
    if not references and roll is None:
        raise InputError("touches of one unknown point do not measure the rotation of the robot "
                         "base about the track axis, so the track's robot_at_zero cannot be "
                         "updated: pass --reference X,Y,Z (a touched point with known "
                         "coordinates in L, mm) or accept the zero-roll convention with --roll "
                         "zero")
    return tr.axis


@click.command("track")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--reference", "references", multiple=True, metavar="X,Y,Z",
              help="Known coordinates (mm) of a touched reference point in the track frame L; "
                   "repeat for several points (column 'point' = 1, 2, ... says which is touched).")
@click.option("--axis", type=click.Choice(["x", "z"]), default=None,
              help="Axis of L along which the carriage moves: x (lecture) or z (KUKA external "
                   "kinematics). Default: the cell's track axis with --cell, else x.")
@click.option("--roll", type=click.Choice(["zero"]), default=None,
              help="Without --reference: return the full rotation L_Q_R with zero roll about the "
                   "track axis (a convention, not a measurement).")
@cell_option
@measurement_options
def track(measurements: str, references: tuple[str, ...], axis: str | None, roll: str | None,
          cell_path: str | None, robot: str | None, tool: str | None, sigma: float | None,
          as_json: bool, accept_poor: bool) -> None:
    """Linear track: direction in the robot base, scale, straightness; rotation when determined.

    \b
    Rows: TCP touches of fixed reference point(s) at different track positions e1 (mm).
    Without --reference the point is unknown and the rotation about the track axis is not
    determined (--roll zero fixes it by convention). One --reference point off the track axis
    gives the rotation (carriage offset taken as zero); two or more also give the offset.
    With --cell the track's robot_at_zero (T_L_R0) and scale are written into the cell file;
    that needs --reference or --roll zero. When the offset is not measured (one --reference,
    or --roll zero) the cell's offset is kept, and a --reference point is taken relative to it.

    \b
    Examples:
      robotcell calibrate track touches.csv --reference 1500,800,300
      robotcell calibrate track touches.csv --cell cell.yaml \\
          --reference 1500,800,300 --reference 2100,-600,100
    """
    from robotcell.calibration.track import calibrate_track

    target = CellTarget.open(cell_path, robot)
    if target is not None:
        axis = _cell_track_axis(target, axis, references, roll)
    model, T_tool = robot_and_tool(robot, tool, target)
    cols = read_csv(measurements, known=POSE_COLUMNS + ["e1", "point", "track"])
    refuse_track_column(cols, measurements, "is not used by 'calibrate track': its track "
                        "positions are column e1")
    f = tcp_positions(cols, measurements, model, T_tool)
    e = external_axis(cols, measurements, "track")
    check_count(len(f), 3, "touches", measurements)
    note_repeats(cols, POSE_COLUMNS + ["e1", "point"], measurements)
    refs = np.array([parse_numbers(r, "--reference", 3) for r in references]).reshape(-1, 3) * 1e-3
    idx = _reference_indices(cols, len(refs), measurements)
    keep_offset = target is not None and len(refs) < 2
    if keep_offset:
        # The fit takes the unmeasured carriage offset as zero; the cell knows it.
        refs = refs - target.cell.track.T_L_R0[:3, 3]
    result = calibrate_track(e, f, references=refs if len(refs) else None, point=idx,
                             axis=axis or "x", roll=roll, labels=_labels(len(f)),
                             prior_sigma=sigma_m(sigma))
    gate(result, as_json, accept_poor)
    if target is not None:
        tr = target.cell.track
        T_L_R0 = result.values["T_L_R"].copy()
        if keep_offset:
            T_L_R0[:3, 3] = tr.T_L_R0[:3, 3]
            offset = ", ".join(f"{v:.3f}" for v in tr.T_L_R0[:3, 3] * 1e3 + 0.0)
            click.echo(f"note: the carriage offset is not measured (two or more --reference "
                       f"points measure it): kept the offset of {target.path} ({offset} mm)",
                       err=True)
        target.cell.update_track(cell_provenance("track", result, len(f), measurements),
                                 T_L_R0=T_L_R0, scale=float(result.values["scale"]))
        target.save(f"track {tr.name!r} (robot_at_zero, scale)")
    emit(result, as_json)


def _cell_turntable(target: CellTarget):
    """The cell's turntable, refusing a cell without one."""
    if target.cell.turntable is None:
        raise InputError(f"{target.path} has no turntable; add a 'turntable' section to the cell "
                         "file first")
    return target.cell.turntable


@click.command("turntable")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--height", type=float, default=0.0, show_default=True, metavar="MM",
              help="Shift of the frame origin along the table axis from the plane of the touched "
                   "point (mm), e.g. -20 when the point is 20 mm above the table top.")
@cell_option
@measurement_options
def turntable(measurements: str, height: float, cell_path: str | None, robot: str | None,
              tool: str | None, sigma: float | None, as_json: bool, accept_poor: bool) -> None:
    """Turntable root frame B (R_T_B) and radius from touches of one point on the table.

    \b
    Rows: TCP touches of one point on the table at different table angles e1 (deg); at least
    3, better 4 or more spread around the full turn. Save --json output for
    'robotcell calibrate workpiece --turntable'.
    With --cell the turntable's frame (T_parent_B) is written into the cell file. For a
    turntable in the world the touches are mapped to the world (result T_world_B); in a cell
    with a track that needs column track (mm, the track position at each touch).

    \b
    Examples:
      robotcell calibrate turntable table.csv --json -o turntable.json
      robotcell calibrate turntable table.csv --cell cell.yaml --tool pointer
    """
    from robotcell.calibration.turntable import calibrate_turntable

    target = CellTarget.open(cell_path, robot)
    parent = _cell_turntable(target).parent if target is not None else None
    model, T_tool = robot_and_tool(robot, tool, target)
    cols = read_csv(measurements, known=POSE_COLUMNS + ["e1", "track"])
    f = tcp_positions(cols, measurements, model, T_tool)
    theta = external_axis(cols, measurements, "table")
    check_count(len(f), 3, "touches", measurements)
    note_repeats(cols, POSE_COLUMNS + ["e1", "track"], measurements)
    if target is None:
        refuse_track_column(cols, measurements, NO_CELL_TRACK)
    elif parent == "world":
        f = transform_points(target.robot_in_world(cols, measurements, len(f)), f)
    else:
        target.track_positions(cols, measurements)
    result = calibrate_turntable(theta, f, height=height * 1e-3, labels=_labels(len(f)),
                                 prior_sigma=sigma_m(sigma))
    gate(result, as_json, accept_poor)
    if target is not None:
        key = "T_R_B"
        if parent == "world":
            key = "T_world_B"
            result = result.renamed("T_R_B", key)
        tt = target.cell.update_turntable(
            cell_provenance("turntable", result, len(f), measurements),
            T_parent_B=result.values[key])
        target.save(f"turntable {tt.name!r} ({key})")
    emit(result, as_json)


def _load_turntable(path: str) -> tuple[np.ndarray, np.ndarray | None, float | None, str]:
    """The turntable pose (m), its 6x6 covariance (SI), the touch noise (m) and its frame.

    Reads the ``--json`` output of ``calibrate turntable``: ``T_R_B`` (frame ``"robot"``), or
    ``T_world_B`` (frame ``"world"``) when it was calibrated with ``--cell`` in the world.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    try:
        data = json.loads(read_text(p))
    except (json.JSONDecodeError, RecursionError) as exc:
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
    sigma = data.get("sigma") if isinstance(data.get("sigma"), dict) else {}
    frame = "world" if any(str(k).startswith("T_world_B") for k in [*data, *sigma]) else "robot"
    key = "T_world_B_covariance_mm_rad" if frame == "world" else "T_R_B_covariance_mm_rad"
    cov = data.get(key)
    if cov is not None:
        cov = _covariance(cov, f"{path}: {key!r}")
        to_si = np.array([1e-3, 1e-3, 1e-3, 1.0, 1.0, 1.0])
        cov = cov * np.outer(to_si, to_si)
    noise = data.get("noise_sigma_mm")
    if noise is not None and (isinstance(noise, bool) or not isinstance(noise, (int, float))
                              or not math.isfinite(noise) or noise < 0):
        raise InputError(f"{path}: 'noise_sigma_mm' must be a number of millimetres >= 0, got "
                         f"{noise!r}; pass the unchanged --json output of 'robotcell calibrate "
                         "turntable'")
    return T, cov, (float(noise) * 1e-3 if noise is not None else None), frame


def _covariance(value: object, where: str) -> np.ndarray:
    """A 6x6 symmetric positive semi-definite covariance (mm, rad) from JSON, or refused."""
    advice = "; pass the unchanged --json output of 'robotcell calibrate turntable'"
    try:
        cov = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{where} must be a 6x6 array of numbers{advice}") from None
    if cov.shape != (6, 6) or not np.all(np.isfinite(cov)):
        raise InputError(f"{where} must be a 6x6 array of finite numbers, got shape "
                         f"{cov.shape}{advice}")
    scale = max(float(np.abs(cov).max()), 1e-300)
    if np.abs(cov - cov.T).max() > 1e-9 * scale or np.linalg.eigvalsh(cov).min() < -1e-9 * scale:
        raise InputError(f"{where} is not a covariance (symmetric, no negative variance)"
                         f"{advice}")
    return cov


#: Largest difference between a turntable file's pose and the cell's that counts as the same
#: calibration (m, rad): far above the cell file's rounding, far below any recalibration.
SAME_POSE = 1e-6


def _workpiece_turntable(turntable_json: str | None, target: CellTarget | None
                         ) -> tuple[np.ndarray, np.ndarray | None, float | None]:
    """Turntable root (m) in the frame of the touches, its covariance and the touch noise."""
    if target is None:
        if turntable_json is None:
            raise InputError("the workpiece needs the turntable: pass --turntable TURNTABLE.json "
                             "(the --json output of 'robotcell calibrate turntable'), or --cell "
                             "CELL.yaml to use the cell's turntable")
        T, cov, noise, frame = _load_turntable(turntable_json)
        if frame != "robot":
            raise InputError(f"{turntable_json} holds the turntable in the world (T_world_B, "
                             "calibrated with --cell), but touches without --cell are in the "
                             "robot base: pass the same --cell CELL.yaml")
        return T, cov, noise
    tt = _cell_turntable(target)
    if turntable_json is None:
        click.echo(f"note: the turntable pose comes from {target.path}, which holds no "
                   "covariance: the 1-sigma of T_B_W does not include the turntable's "
                   "uncertainty (pass --turntable TURNTABLE.json to include it)", err=True)
        return tt.T_parent_B, None, None
    T, cov, noise, frame = _load_turntable(turntable_json)
    if frame != tt.parent:
        raise InputError(f"{turntable_json} holds the turntable in the "
                         f"{'world' if frame == 'world' else 'robot base'}, but the turntable of "
                         f"{target.path} has parent {tt.parent}: calibrate the turntable with "
                         f"--cell {target.path}, or omit --turntable to use the cell's turntable")
    dT = invert(tt.T_parent_B) @ T
    dist = float(np.linalg.norm(dT[:3, 3]))
    angle = float(np.arccos(np.clip((np.trace(dT[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)))
    if max(dist, angle) > SAME_POSE:
        click.echo(f"warning: the turntable of {turntable_json} differs from the one in "
                   f"{target.path} by {dist * 1e3:.3f} mm and {np.degrees(angle):.4f} deg; "
                   f"T_B_W is relative to {turntable_json}'s. Write that turntable into the "
                   "cell (calibrate turntable --cell) so that the two agree", err=True)
    return T, cov, noise


@click.command("workpiece")
@click.argument("measurements", type=click.Path(dir_okay=False))
@click.option("--turntable", "turntable_json", default=None, metavar="TURNTABLE.json",
              type=click.Path(dir_okay=False),
              help="--json output of 'robotcell calibrate turntable'. Optional with --cell (the "
                   "cell's turntable is used, without its uncertainty).")
@click.option("--name", default=None, metavar="FRAME",
              help="With --cell: the frame on the turntable to write (added when new).")
@cell_option
@measurement_options
def workpiece(measurements: str, turntable_json: str | None, name: str | None,
              cell_path: str | None, robot: str | None, tool: str | None, sigma: float | None,
              as_json: bool, accept_poor: bool) -> None:
    """Workpiece frame B_T_W on a calibrated turntable (3-point, or several touches per point).

    \b
    Rows: TCP touches with the table angle e1 (deg, any angle, recorded at every touch) and
    column point = origin, x (a point on +X) or xy (a point in the XY plane with +Y).
    The moving pose is R_T_W(theta) = R_T_B Rz(theta) B_T_W.
    With --cell and --name the frame is written into the cell file with parent turntable.
    For a turntable in the world the touches are mapped to the world; in a cell with a track
    that needs column track (mm, the track position at each touch).

    \b
    Examples:
      robotcell calibrate workpiece wp.csv --turntable turntable.json
      robotcell calibrate workpiece wp.csv --cell cell.yaml --name part --tool pointer
    """
    from robotcell.calibration.workpiece import calibrate_workpiece

    target = CellTarget.open(cell_path, robot)
    require_name(name, target, "frame")
    model, T_tool = robot_and_tool(robot, tool, target)
    T_B, cov, noise = _workpiece_turntable(turntable_json, target)
    cols = read_csv(measurements, known=POSE_COLUMNS + ["e1", "point", "track"])
    f = tcp_positions(cols, measurements, model, T_tool)
    theta = external_axis(cols, measurements, "workpiece")
    roles = point_roles(cols, measurements)
    note_repeats(cols, POSE_COLUMNS + ["e1", "track"], measurements)
    if target is None:
        refuse_track_column(cols, measurements, NO_CELL_TRACK)
    elif _cell_turntable(target).parent == "world":
        f = transform_points(target.robot_in_world(cols, measurements, len(f)), f)
    else:
        target.track_positions(cols, measurements)
    result = calibrate_workpiece(theta, f, roles, T_B, T_R_B_covariance=cov, noise_sigma=noise,
                                 prior_sigma=sigma_m(sigma),
                                 labels=[f"line {i + 2} ({r})" for i, r in enumerate(roles)])
    gate(result, as_json, accept_poor)
    if target is not None and name is not None:
        target.cell.update_frame(name, result.values["T_B_W"],
                                 cell_provenance("workpiece", result, len(f), measurements),
                                 parent="turntable")
        target.save(f"frame {name!r} (parent turntable)")
    emit(result, as_json)
