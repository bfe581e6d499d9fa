"""Planning a calibration: which touches give the smallest uncertainty, checked by Monte Carlo.

For a virtual cell (its values taken as the truth) and a touch-up accuracy ``noise``, each
candidate touch design of a procedure (:data:`DESIGNS`: tool tilt, size of the 3-point
triangle, track travel, table angles and radius) is simulated without error, and the
calibration of those exact touches with ``sigma = noise`` gives the *predicted*
uncertainty (first-order propagation, the same covariance every calibration reports). The design
with the smallest predicted uncertainty of the calibrated pose wins. A Monte Carlo run then
repeats simulate-with-error and calibrate ``runs`` times at that design and compares the spread
of the actual errors with the prediction.

The figure of merit of a pose is ``sqrt(|sigma_position|^2 + (LEVER * |sigma_rotation|)^2)``:
the 1-sigma error of a point ``LEVER`` from the frame's origin, in metres.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sized
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from robotcell.calibration.result import CalibrationResult
from robotcell.cell import Cell
from robotcell.cell.calibrate.registry import Planner, having
from robotcell.errors import InputError, RobotcellError
from robotcell.studies.simulate import Touches, check_counts, simulate

__all__ = ["DESIGNS", "LEVER", "NOISE_MIN", "PLANNERS", "POSE_KEY", "Candidate", "MonteCarlo", "Plan",
           "calibrate_touches", "plan", "pose_error", "predicted_sigma"]

#: ``progress(items, label)``: wraps a sized iterable (e.g. in a progress bar) and yields its items.
Progress = Callable[[Sized, str], Iterable[Any]]

#: Distance from the frame origin at which rotation uncertainty is weighed against position (m).
LEVER = 0.5

#: Smallest touch-up accuracy a plan takes (m): 1 um, below any touch-up accuracy. The fits
#: weigh by ``1 / noise**2``, which a far smaller noise (1e-200 m) makes infinite.
NOISE_MIN = 1e-6

#: The procedures that can be planned (those of the registry with a
#: :class:`~robotcell.cell.calibrate.registry.Planner`), by name.
PLANNERS: Mapping[str, Planner] = having(lambda p: p.planner)

#: Candidate designs per procedure: keyword arguments of :func:`robotcell.studies.simulate.simulate`
#: (SI units); the number of touches stays as the user asks.
DESIGNS: Mapping[str, list[dict[str, Any]]] = having(
    lambda p: None if p.planner is None else [dict(d) for d in p.planner.designs])

#: The key of the calibrated pose in each procedure's result values.
POSE_KEY: Mapping[str, str] = having(lambda p: None if p.planner is None else p.planner.pose)


def _design_to_simulation(procedure: str, design: dict[str, Any]) -> dict[str, Any]:
    """Turn a planning design into :func:`simulate` keywords (table spans into angle lists)."""
    return PLANNERS[procedure].simulation(dict(design))


def calibrate_touches(cell: Cell, touches: Touches, sigma: float | None = None
                      ) -> CalibrationResult:
    """Calibrate simulated touches with the library, the cell giving robot, tool and axes.

    TCP positions come from the recorded joint values through the cell's robot and the tool
    that touched. Frame and turntable touches are mapped into the parent frame of what they
    calibrate (world, or the robot base for items carried by it), so the pose in the result is
    expressed in that parent (under the procedure's usual key, e.g. ``T_R_B``). Each procedure
    says how (:attr:`Planner.calibrate <robotcell.cell.calibrate.registry.Planner>`).

    Parameters
    ----------
    cell : Cell
        The cell as known at calibration time (e.g. with an already calibrated tool).
    touches : Touches
    sigma : float, optional
        Touch-up accuracy (m) used for the uncertainties instead of the residuals.

    Returns
    -------
    CalibrationResult
    """
    return PLANNERS[touches.procedure].calibrate(cell, touches, sigma)


def _pose_sigma(result: CalibrationResult, key: str) -> tuple[float, float]:
    """Lengths of the 1-sigma position (m) and rotation (rad) vectors of a pose in a result."""
    sp = np.asarray(result.sigma.get(key + "_position", np.full(3, np.nan)), dtype=float)
    sr = np.asarray(result.sigma.get(key + "_rotation", np.zeros(3)), dtype=float)
    return float(np.linalg.norm(sp)), float(np.linalg.norm(sr))


def predicted_sigma(result: CalibrationResult, procedure: str) -> tuple[float, float, float]:
    """Predicted 1-sigma of the calibrated pose: position (m), rotation (rad), merit (m).

    For a tool calibrated without orientation the TCP position alone counts.
    """
    key = POSE_KEY[procedure]
    if key in result.values:
        sp, sr = _pose_sigma(result, key)
    else:
        sp, sr = float(np.linalg.norm(result.sigma["tcp"])), 0.0
    return sp, sr, math.hypot(sp, LEVER * sr)


def pose_error(T_est: NDArray[np.float64], T_true: NDArray[np.float64]) -> tuple[float, float]:
    """Position (m) and rotation (rad) error of an estimated pose against the truth."""
    dp = float(np.linalg.norm(T_est[:3, 3] - T_true[:3, 3]))
    dr = float(np.linalg.norm(Rotation.from_matrix(T_est[:3, :3] @ T_true[:3, :3].T).as_rotvec()))
    return dp, dr


def _true_pose(touches: Touches) -> NDArray[np.float64]:
    """The truth, in the frame :func:`calibrate_touches` expresses the result in."""
    return touches.truth[PLANNERS[touches.procedure].truth]


@dataclass
class Candidate:
    """One touch design and its predicted uncertainty.

    Attributes
    ----------
    design : dict
        Keywords of the design (SI units), see :data:`DESIGNS`.
    position : float
        Predicted 1-sigma of the calibrated position (m); NaN when the design is not feasible.
    rotation : float
        Predicted 1-sigma of the calibrated rotation (rad).
    merit : float
        ``sqrt(position^2 + (LEVER * rotation)^2)`` (m); infinite when not feasible.
    condition : float
        Condition number of the calibration at this design.
    reason : str
        Why the design is not feasible (unreachable touches, ill-posed geometry), else empty.
    """

    design: dict[str, Any]
    position: float = math.nan
    rotation: float = math.nan
    merit: float = math.inf
    condition: float = math.nan
    reason: str = ""


@dataclass
class MonteCarlo:
    """Monte Carlo check of a design: actual errors over repeated simulated calibrations.

    Attributes
    ----------
    runs : int
    position_rms, rotation_rms : float
        RMS over the runs of the length of the position error (m) and of the rotation error
        (rad) of the calibrated pose against the truth.
    position_predicted, rotation_predicted : float
        Predicted 1-sigma lengths (m, rad); for Gaussian errors the RMS lengths above should be
        close to these.
    failures : int
        Runs whose calibration refused the data (an outlier can make the geometry ill-posed).
    """

    runs: int
    position_rms: float
    rotation_rms: float
    position_predicted: float
    rotation_predicted: float
    failures: int = 0


@dataclass
class Plan:
    """The proposed touches of a procedure, the candidates compared, and the Monte Carlo check.

    Attributes
    ----------
    procedure : str
    noise : float
        Touch-up accuracy assumed (m, 1-sigma per coordinate).
    best : Candidate
    candidates : list of Candidate
    touches : Touches
        The proposed touches (exact, without touch-up error): joint values to teach.
    monte_carlo : MonteCarlo or None
    """

    procedure: str
    noise: float
    best: Candidate
    candidates: list[Candidate]
    touches: Touches
    monte_carlo: MonteCarlo | None = None


def plan(cell: Cell, procedure: str, noise: float = 1e-4, runs: int = 100,
         seed: int | None = 0, progress: Progress | None = None,
         designs: list[dict[str, Any]] | None = None, **common: Any) -> Plan:
    """Propose the touches of a procedure that minimise the predicted uncertainty.

    Parameters
    ----------
    cell : Cell
        Virtual cell whose values are taken as the truth.
    procedure : str
        A procedure of :data:`PLANNERS`: ``"tcp"``, ``"frame"``, ``"track"``, ``"turntable"``,
        ``"workpiece"``, or one registered with a planner.
    noise : float
        Touch-up accuracy, 1-sigma per coordinate (m); at least :data:`NOISE_MIN`.
    runs : int
        Monte Carlo runs at the best design (0: none).
    seed : int, optional
        Seed of the Monte Carlo touch-up errors.
    progress : callable, optional
        ``progress(items, label)`` wraps the candidates and then the Monte Carlo runs, e.g. in
        a progress bar; it must yield the items.
    designs : list of dict, optional
        Candidate designs instead of :data:`DESIGNS`.
    **common
        Keywords of :func:`robotcell.studies.simulate.simulate` fixed for every candidate (``tool``,
        ``frame``, ``track``, ``touches``, ``repeats``, ``references``, ``height``, ...).

    Returns
    -------
    Plan

    Raises
    ------
    InputError
        Unknown procedure, a noise below :data:`NOISE_MIN` or not finite, no feasible design.
    """
    if procedure not in DESIGNS:
        raise InputError(f"unknown procedure {procedure!r}; choose from {', '.join(DESIGNS)}")
    if not (math.isfinite(noise) and noise >= NOISE_MIN):
        raise InputError(f"noise must be a positive number (m) of at least {NOISE_MIN:g} (1 um, "
                         f"below any touch-up accuracy), got {noise}")
    if runs < 0:
        raise InputError(f"runs must be >= 0, got {runs}")
    check_counts(common)
    wrap = progress or (lambda items, label: items)
    candidates = []
    for design in wrap(designs if designs is not None else DESIGNS[procedure],
                       f"predicting {procedure} designs"):
        cand = Candidate(dict(design))
        kw = _design_to_simulation(procedure, {**common, **design})
        try:
            exact = simulate(cell, procedure, noise=0.0, **kw)
            res = calibrate_touches(cell, exact, sigma=noise)
        except RobotcellError as exc:
            cand.reason = str(exc)
        else:
            cand.position, cand.rotation, cand.merit = predicted_sigma(res, procedure)
            cand.condition = res.condition
        candidates.append(cand)
    feasible = [c for c in candidates if math.isfinite(c.merit)]
    if not feasible:
        reasons = "; ".join(sorted({c.reason for c in candidates}))
        raise InputError(f"no candidate {procedure} design can be carried out in this cell: {reasons}")
    best = min(feasible, key=lambda c: c.merit)
    kw = _design_to_simulation(procedure, {**common, **best.design})
    touches = simulate(cell, procedure, noise=0.0, **kw)
    mc = None
    if runs:
        if cell.track is not None and not touches.moves_track:
            kw["track"] = float(touches.track[0])  # where the robot stands, as planned
        mc = _monte_carlo(cell, procedure, noise, runs, seed, progress, kw, best)
    return Plan(procedure, noise, best, candidates, touches, mc)


def _monte_carlo(cell: Cell, procedure: str, noise: float, runs: int, seed: int | None,
                 progress: Progress | None,
                 kw: dict[str, Any], best: Candidate) -> MonteCarlo:
    rng = np.random.default_rng(seed)
    dp, dr = [], []
    failures = 0
    key = POSE_KEY[procedure]
    wrap = progress or (lambda items, label: items)
    for _ in wrap(range(runs), f"Monte Carlo, {runs} runs"):
        t = simulate(cell, procedure, noise=noise, seed=rng, **kw)
        try:
            res = calibrate_touches(cell, t)
        except RobotcellError:
            failures += 1
            continue
        T_true = _true_pose(t)
        if key in res.values:
            p, r = pose_error(res.values[key], T_true)
        else:
            p, r = float(np.linalg.norm(res.values["tcp"] - T_true[:3, 3])), 0.0
        dp.append(p)
        dr.append(r)
    rms = (lambda v: float(np.sqrt(np.mean(np.square(v)))) if v else math.nan)
    return MonteCarlo(runs, rms(dp), rms(dr), best.position, best.rotation, failures)
