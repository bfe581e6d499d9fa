"""Uncertainty through the chain of calibrations of a cell.

A calibration in a cell rests on what was calibrated before it: the tool that touched (every
touched point moves with the tool's error), the track the robot stood on (the touches are mapped
to the world through it), the turntable a workpiece sits on. This module gives a calibration
those earlier items as :class:`~robotcell.calibration.uncertainty.Inputs` (the derivative of each
touched point with respect to their parameters, and their error sources as the cell file keeps
them), and turns a result into the error sources written with the calibrated item.

An item's parameters are those of its pose (origin in m, rotation vector in rad about the
parent's axes; ``R_true = exp([d]x) R``), and for the track also its scale:

========================  ==========================================================
item                      parameters
========================  ==========================================================
``tools.NAME``            ``T_F_TCP``: 6
``frames.NAME``           the frame's pose in its parent: 6
``turntable``             ``T_parent_B``: 6
``turntable`` (chain)     a positioner of n axes: the root pose ``T_parent_0``, then
                          ``a``, ``alpha``, ``d``, ``theta`` of each axis: 6 + 4 n
``track``                 ``T_L_R0`` and ``scale``: 7
``base``                  ``T_world_R`` of a robot without a track: 6 (an input only,
                          where the cell records its uncertainty: a base placed by a
                          robot-to-robot or shared-positioner calibration)
========================  ==========================================================

An item with no recorded uncertainty (a nominal or typed-in value, or one calibrated before
uncertainties were recorded) has the :class:`NominalAccuracy` the caller states, by default
:data:`NOMINAL_ACCURACY`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.calibration.fitting import perturb_pose
from robotcell.calibration.propagate import jacobian
from robotcell.calibration.uncertainty import OWN, Estimate, Inputs, Sources, joined
from robotcell.cell import Cell
from robotcell.cell.parts import Positioner
from robotcell.errors import InputError, term
from robotcell.kinematics.transforms import invert, transform_points

__all__ = ["NOMINAL_ACCURACY", "NominalAccuracy", "base_inputs", "item_pose", "item_size",
           "item_sources", "perturbed", "plate_inputs", "touch_inputs", "written_sources"]


@dataclass(frozen=True)
class NominalAccuracy:
    """Accuracy assumed for a cell item that has no recorded uncertainty (1-sigma per axis).

    Attributes
    ----------
    position : float
        Of each coordinate of an origin (m).
    rotation : float
        Of each component of the rotation vector (rad).
    scale : float
        Of a track's scale (dimensionless).
    """

    position: float = 1e-3
    rotation: float = math.radians(0.5)
    scale: float = 1e-3

    def __post_init__(self) -> None:
        for name in ("position", "rotation", "scale"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"nominal accuracy {name} must be a positive number, got {v!r}")

    def sigma(self, size: int) -> NDArray[np.float64]:
        """1-sigma of each parameter of an item with ``size`` parameters (6, 7 for a track, or
        6 + 4 n for a positioner of n axes: ``a``, ``alpha``, ``d``, ``theta`` of each)."""
        pose = np.r_[np.full(3, self.position), np.full(3, self.rotation)]
        if size == 7:
            return np.r_[pose, self.scale]
        axis = [self.position, self.rotation, self.position, self.rotation]
        return np.r_[pose, np.tile(axis, (size - 6) // 4)]


#: The default: a tool from its drawing, a frame or an axis from the cell layout, a track's gear
#: ratio from the machine data. State your own where you know better (in the cell file, as
#: ``covariance_mm_rad`` of the item's provenance, or with ``--nominal-accuracy``).
NOMINAL_ACCURACY = NominalAccuracy()


def item_pose(cell: Cell, key: str) -> tuple[NDArray[np.float64], Any]:
    """The pose of an item (``T_F_TCP``, ``T_parent_W``, ``T_parent_B``, ``T_L_R0``) and its owner."""
    kind, _, name = key.partition(".")
    if kind == "tools" and name in cell.tools:
        return cell.tools[name].T_F_TCP, cell.tools[name]
    if kind == "frames" and name in cell.frames:
        return cell.frames[name].pose, cell.frames[name]
    if key == "track" and cell.track is not None:
        return cell.track.T_L_R0, cell.track
    if key == "turntable" and cell.turntable is not None:
        return cell.turntable.T_parent_root, cell.turntable
    if key == "base" and len(cell.robots) == 1 and cell.track is None:
        return cell.T_world_R, cell.robots[cell.robot_name]
    raise InputError(f"the cell has no item {key!r}")


def item_sources(cell: Cell, key: str, nominal: NominalAccuracy = NOMINAL_ACCURACY
                 ) -> tuple[Sources, str | None]:
    """Error sources of a cell item, and a note when it has none recorded (nominal accuracy).

    Parameters
    ----------
    cell : Cell
    key : str
        ``tools.NAME``, ``frames.NAME``, ``track`` or ``turntable``.
    nominal : NominalAccuracy
        Assumed where the cell records no uncertainty.
    """
    _, owner = item_pose(cell, key)
    size = item_size(cell, key)
    prov = owner.base_provenance if key == "base" else owner.provenance
    if prov.sources:
        return Sources(size, dict(prov.sources)), None
    what = "a nominal value" if prov.source in ("nominal", "manual") else (
        "calibrated without a recorded uncertainty")
    shown = key if size < 10 else (f"positioner {owner.name!r} (root pose and the constants "
                                   "of each axis)")
    note = (f"note: {shown} is {what}: its accuracy is taken as {nominal.position * 1e3:g} mm "
            f"and {math.degrees(nominal.rotation):g} deg per axis"
            + (f" and {nominal.scale:g} in scale" if size == 7 else "")
            + " (state it as covariance_mm_rad in the cell file's provenance, or with "
              f"{term('nominal', 'nominal (NominalAccuracy)')})")
    return Sources(size, {f"{key} nominal": np.diag(nominal.sigma(size))}), note


def item_size(cell: Cell, key: str) -> int:
    """Number of parameters of an item (see the module): 7 for the track, 6 + 4 n for a
    positioner chain of n axes, else 6 (a pose)."""
    if key == "track":
        return 7
    if key == "turntable" and isinstance(cell.turntable, Positioner):
        from robotcell.identification.positioner import AXIS_CONSTANTS

        return 6 + len(AXIS_CONSTANTS) * cell.turntable.n_axes
    return 6


def perturbed(T: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
    """The pose ``T`` moved by 6 parameters: origin ``+ v[:3]``, rotation ``exp([v[3:]]x) R``."""
    T = np.asarray(T, dtype=float)
    v = np.asarray(v, dtype=float)
    return perturb_pose(T, np.r_[T[:3, 3] + v[:3], v[3:6]])


def _track_mapped(cell: Cell, e: NDArray[np.float64], points_R: NDArray[np.float64]):
    """``v -> T_world_R(e; T_L_R0 + v[:6], scale + v[6]) p_R``: the touches through the track."""
    tr = cell.track

    def mapped(v: NDArray[np.float64]) -> NDArray[np.float64]:
        T_L_R = perturbed(tr.T_L_R0, v[:6])
        T = tr.T_world_L @ np.broadcast_to(T_L_R, e.shape + (4, 4)).copy()
        T[:, :3, 3] += (tr.T_world_L[:3, :3] @ tr.direction * (tr.scale + v[6])) * e[:, None]
        return np.einsum("nij,nj->ni", T[:, :3, :3], points_R) + T[:, :3, 3]
    return mapped


@dataclass(frozen=True)
class Chained:
    """The earlier items a calibration's touches rest on.

    Attributes
    ----------
    inputs : Inputs or None
        Derivative of each touched point (in the frame the calibration works in) with respect
        to the items' parameters, and their error sources; None when there are none.
    keys : tuple of str
        The items, in the order of their parameters.
    notes : tuple of str
        Items taken at the nominal accuracy, and inputs left out (touches given as x, y, z).
    """

    inputs: Inputs | None = None
    keys: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()


def touch_inputs(cell: Cell, points_R: ArrayLike, *, flange: ArrayLike | None = None,
                 tool: str | ArrayLike | None = None, track: ArrayLike | None = None,
                 nominal: NominalAccuracy = NOMINAL_ACCURACY) -> Chained:
    """The tool and track that touched points rest on, as inputs of their calibration.

    Parameters
    ----------
    cell : Cell
    points_R : array_like, shape (N, 3)
        The touched points in the robot base (m).
    flange : array_like, shape (N, 4, 4), optional
        The flange poses of the touches (joint values through the robot model): the tool's
        error moves each point by ``R_R_F`` times it. None: the points came as x, y, z from the
        controller, which applied its own tool, and the tool's error is left out (a note says
        so).
    tool : str or array_like, optional
        The tool of the cell that touched, by name (its recorded uncertainty is used); a tool
        given as a pose ``T_F_TCP``, or None for the robot model's tool, is taken at the
        nominal accuracy.
    track : array_like, shape (N,), optional
        Track positions (m) when the touches are mapped to the world: through the cell's track,
        or (zeros) through the base of a robot without one. The robot base's recorded
        uncertainty (:func:`base_inputs`) then joins the inputs.
    nominal : NominalAccuracy
        Accuracy of items with none recorded.

    Returns
    -------
    Chained
        Sensitivities of the points in the world when ``track`` is given, else in the robot base.
    """
    p = np.asarray(points_R, dtype=float).reshape(-1, 3)
    n = len(p)
    inputs, keys, notes = None, [], []
    if flange is not None:
        R = np.asarray(flange, dtype=float)[:, :3, :3]
        if isinstance(tool, str):
            key = f"tools.{tool}"
            sources, note = item_sources(cell, key, nominal)
        else:
            key = "tool given as a pose" if tool is not None else "tool of the robot model"
            sources = Sources(6, {f"{key} nominal": np.diag(nominal.sigma(6))})
            note = (f"note: the {key} is taken at the nominal accuracy "
                    f"{nominal.position * 1e3:g} mm and {math.degrees(nominal.rotation):g} deg")
        sens = np.concatenate([R, np.zeros((n, 3, 3))], axis=2)
        inputs = joined(None, sens, sources, [f"{key} {c}" for c in _POSE_NAMES])
        keys.append(key)
        notes += [note] if note else []
    elif cell.tools:
        notes.append("note: the touches are TCP positions x, y, z (the controller applied its "
                     "tool): the uncertainty of that tool is not included; record joint values "
                     f"a1..a6 with {term('tool', 'tool')} to include it")
    if track is not None and cell.track is not None:
        e = np.asarray(track, dtype=float).reshape(n)
        mapped = _track_mapped(cell, e, p)
        if inputs is not None:  # the tool's share is turned into the world as well
            T_wR = cell.frame_pose("robot", track=e)
            inputs = inputs.rotated(T_wR[:, :3, :3])
        sources, note = item_sources(cell, "track", nominal)
        sens = jacobian(mapped, np.zeros(7)).reshape(n, 3, 7)
        inputs = joined(inputs, sens, sources, [f"track {c}" for c in _POSE_NAMES + ("scale",)])
        keys.append("track")
        notes += [note] if note else []
    elif track is not None:
        inputs, base = base_inputs(cell, p, inputs)
        keys += base
    return Chained(inputs, tuple(keys), tuple(notes))


def base_inputs(cell: Cell, points_R: NDArray[np.float64], inputs: Inputs | None
                ) -> tuple[Inputs | None, list[str]]:
    """Inputs of touches mapped to the world through the base of a robot without a track.

    The inputs so far (the tool's, in the robot base) are turned into the world, and the
    base ``T_world_R`` joins them (key ``base``) where the cell records its uncertainty (a base
    placed by a robot-to-robot or shared-positioner calibration); a base without one is the
    world's definition, and exact.

    Parameters
    ----------
    cell : Cell
        A cell of one robot without a track (or one robot's view of a cell of several).
    points_R : ndarray, shape (N, 3)
        The touched points in the robot base (m).
    inputs : Inputs or None
        The inputs in the robot base.

    Returns
    -------
    inputs : Inputs or None
        In the world, with the base's parameters appended.
    keys : list of str
        ``["base"]`` when the base joined, else empty.
    """
    T_wR = cell.frame_pose("robot")
    if inputs is not None:
        inputs = inputs.rotated(T_wR[:3, :3])
    if not cell.robots[cell.robot_name].base_provenance.sources:
        return inputs, []
    sources, _ = item_sources(cell, "base")

    def mapped(v: NDArray[np.float64]) -> NDArray[np.float64]:
        return transform_points(perturbed(T_wR, v), points_R)

    sens = jacobian(mapped, np.zeros(6)).reshape(len(points_R), 3, 6)
    return joined(inputs, sens, sources, [f"base {c}" for c in _POSE_NAMES]), ["base"]


_POSE_NAMES = ("x", "y", "z", "rx", "ry", "rz")


def plate_inputs(cell: Cell, values: ArrayLike, points: ArrayLike, chained: Chained,
                 nominal: NominalAccuracy = NOMINAL_ACCURACY
                 ) -> tuple[NDArray[np.float64], Chained]:
    """Touches carried into the plate frame P of a positioner chain, and the items they rest on.

    Each point goes into P through the chain at its axis values, so the positioner's error moves
    it: the derivative with respect to the chain's parameters (root pose and the constants of
    each axis, :func:`robotcell.identification.positioner.perturbed_chain`; central
    differences, over all touches at once) joins the inputs, with the positioner's recorded
    error sources (or the nominal accuracy, said in a note).

    Parameters
    ----------
    cell : Cell
        A cell whose ``turntable`` is a :class:`~robotcell.cell.Positioner`.
    values : array_like, shape (N, n)
        Axis values of the touches (rad).
    points : array_like, shape (N, 3)
        The touched points in the positioner's parent frame (m).
    chained : Chained
        The tool and track the touches rest on, in the parent frame.
    nominal : NominalAccuracy
        Accuracy of items with none recorded.

    Returns
    -------
    points_P : ndarray, shape (N, 3)
        The touches in P (m).
    Chained
        The inputs turned into P, with the positioner (key ``turntable``) appended.
    """
    from robotcell.identification.positioner import AXIS_CONSTANTS, perturbed_chain

    pos = cell.turntable
    v = pos.axis_values(values)
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    size = item_size(cell, "turntable")

    def carried(w: NDArray[np.float64]) -> NDArray[np.float64]:
        return transform_points(invert(perturbed_chain(pos.chain, w).fk(v, np.eye(4))), p)

    T_P_parent = invert(pos.T_parent_root @ pos.T_root_P(v))
    inputs = None if chained.inputs is None else chained.inputs.rotated(T_P_parent[:, :3, :3])
    sources, note = item_sources(cell, "turntable", nominal)
    names = [f"turntable {c}" for c in _POSE_NAMES] + [
        f"turntable {j.name or k + 1} {c}" for k, j in enumerate(pos.chain.joints)
        for c in AXIS_CONSTANTS]
    sens = jacobian(carried, np.zeros(size)).reshape(len(p), 3, size)
    inputs = joined(inputs, sens, sources, names)
    return transform_points(T_P_parent, p), Chained(
        inputs, chained.keys + ("turntable",), chained.notes + ((note,) if note else ()))


def written_sources(est: Estimate, old: Sources, name: str) -> dict[str, NDArray[np.float64]]:
    """Error sources of a calibrated item as the cell file keeps them.

    The directions the touches determine take the calibration's sources (its own touch noise
    under ``name``, and what it inherits from its inputs); the others keep the item's previous
    sources (a tool orientation a TCP-only calibration keeps, the roll of a track touched
    without reference points).

    Parameters
    ----------
    est : Estimate
        The calibration's estimate of the item.
    old : Sources
        The item's sources before (recorded, or the nominal accuracy).
    name : str
        Name of this calibration as an error source.

    Returns
    -------
    dict of str to ndarray
        Per source a factor over the item's parameters (SI).
    """
    D = est.determined
    P = D @ D.T
    new = est.sources.renamed(OWN, name).map(P)
    kept = old.map(np.eye(old.size) - P)
    out = dict(new.factors)
    for k, f in kept.factors.items():
        if not np.any(f):
            continue
        if k in out and out[k].shape == f.shape:
            out[k] = out[k] + f
        elif k in out:  # the same source by two routes of different width: kept side by side
            out[k] = np.hstack([out[k], f])
        else:
            out[k] = f
    return out
