"""The whole cell in one fit: every calibrated item re-estimated from all the touches behind it.

Each calibration of a cell records its touch file (with its checksum), its options and the items it
used (:class:`~robotcell.cell.Provenance`). :func:`calibrate_one_robot` repeats every recorded
calibration on the cell as it stands and combines them into one maximum-likelihood fit of all the
items at once: a tool is then estimated from its own touches *and* from the turntable, track and
frame touches taken with it, and every item measured with it follows it.

The combination is exact to first order and needs no model beyond the procedures' own. Around the
current values, calibration ``s`` (own item ``u_s``, inputs ``v_s``) contributes

* its estimate: ``u_s - G_s v_s = u_hat_s`` (the procedure's result given the inputs, ``G_s`` how
  it follows them), with the covariance of its own touch noise, in the directions its touches
  determine;
* what its residuals say about the inputs: the part of the inputs' effect on the touches that its
  own item cannot absorb, ``J_v^T (I - H) J_v / s^2`` (``Fit.input_information``).

Minimising the sum over all calibrations (Gauss-Newton, repeated with every calibration re-run at
the new values until the step is below 1e-4 of its 1-sigma) is the maximum-likelihood fit of all
the touches together. Items no calibration measures (a nominal tool, a track's roll about its
axis) keep their values and enter with their recorded uncertainty (or the nominal accuracy). The
covariance of the result is the inverse of the combined information plus the share of those kept
values; it is written back as error sources, so later calibrations chain on it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from robotcell.calibration.result import to_jsonable
from robotcell.calibration.sigmaparts import sigma_basis
from robotcell.calibration.uncertainty import OWN, Sources, factor_of
from robotcell.calibration.verdict import Verdict
from robotcell.cell import Cell, Positioner, Provenance
from robotcell.cell.calibrate.chain import (
    NOMINAL_ACCURACY,
    NominalAccuracy,
    item_pose,
    item_sources,
    perturbed,
)
from robotcell.cell.calibrate.common import CellCalibration, copied, touch_file_problem
from robotcell.cell.calibrate.context import CalibrationContext
from robotcell.cell.calibrate.registry import having, procedure
from robotcell.errors import InputError, term
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.io.tables import format_table

__all__ = ["CellRecalibration", "ItemChange", "calibrate_one_robot", "touch_files"]

#: Gauss-Newton steps at most, and the step (in units of each parameter's 1-sigma) below which
#: the fit has converged.
MAX_ITERATIONS = 20
CONVERGED = 1e-4

#: The procedures that ``calibrate cell`` repeats, by name (those a cell records).
_PROCEDURES = having(lambda p: p.repeat)
_LEVELS = ("good", "check", "poor")
#: What an item's 1-sigma in the whole-cell fit comes from, for :func:`sigma_basis`.
_OWN = "its own touches, with the cell's other calibrations,"


@dataclass(frozen=True)
class ItemChange:
    """What the whole-cell fit changed in one item.

    Attributes
    ----------
    key : str
        ``tools.NAME``, ``frames.NAME``, ``track`` or ``turntable``.
    before, after : ndarray, shape (4, 4)
        The item's pose (m) in the cell given and in the fit.
    change : ndarray, shape (6,) or (7,)
        ``after`` relative to ``before``: origin (m), rotation vector (rad, about the parent's
        axes), and for the track the scale.
    sigma : ndarray, shape (6,) or (7,)
        1-sigma of ``after`` in the same parameters (the whole-cell fit's).
    sigma_before : ndarray, shape (6,) or (7,)
        1-sigma of ``before`` as the cell recorded it (its sequential calibration).
    robot : str or None
        In a cell of several robots, the robot whose calibration the item is (its tool or track,
        a shared item it touched, a base it placed); None in a one-robot cell.
    """

    key: str
    before: NDArray[np.float64]
    after: NDArray[np.float64]
    change: NDArray[np.float64]
    sigma: NDArray[np.float64]
    sigma_before: NDArray[np.float64]
    robot: str | None = None

    @property
    def change_sigmas(self) -> NDArray[np.float64]:
        """``change / sigma`` per parameter."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.sigma > 0, self.change / self.sigma, 0.0)


@dataclass(frozen=True)
class CellRecalibration:
    """Outcome of :func:`robotcell.cell.calibrate.calibrate_cell`.

    Attributes
    ----------
    cell : Cell
        The cell with every re-estimated item written in (a new cell).
    changes : tuple of ItemChange
        Per estimated item, in the order of ``items``.
    steps : tuple of CellCalibration
        Every recorded calibration, repeated at the fitted values (residuals per touch, verdict).
    items : tuple of str
        The estimated items.
    covariance : ndarray
        Joint covariance of the items' parameters (SI), in the order of ``items``.
    iterations : int
        Gauss-Newton steps taken.
    notes : tuple of str
        Items taken at their recorded or nominal accuracy.
    relative : dict of str to str
        The frame each item's 1-sigma is relative to, where the cell does not say it by the
        item's key (the items of a cell of several robots, labelled by their robot).
    """

    cell: Cell
    changes: tuple[ItemChange, ...]
    steps: tuple[CellCalibration, ...]
    items: tuple[str, ...]
    covariance: NDArray[np.float64]
    iterations: int
    notes: tuple[str, ...] = ()
    relative: dict[str, str] = field(default_factory=dict)

    @property
    def verdict(self) -> Verdict:
        """The worst verdict of the calibrations, with the reasons of each that is not good."""
        verdicts = [(s.key or s.result.procedure, s.result.verdict) for s in self.steps]
        level = max((v.level for _, v in verdicts), key=_LEVELS.index, default="good")
        reasons = [f"{k}: {'; '.join(v.reasons)}" for k, v in verdicts if v.level == level]
        return Verdict(level=level, reasons=reasons)

    def relative_to(self, key: str) -> str:
        """The frame the 1-sigma of item ``key`` is relative to: its parent (``F`` the flange for
        a tool, ``L`` for the track, ``B`` or ``P`` for a frame on the turntable or positioner,
        ``R`` for the robot base, ``world``)."""
        if key in self.relative:
            return self.relative[key]
        if key.startswith("tools."):
            return "F"
        if key == "track":
            return "L"
        if key == "turntable":
            parent = self.cell.turntable.parent if self.cell.turntable is not None else "world"
        else:
            parent = self.cell.frames[key.split(".", 1)[1]].parent
        table = "P" if isinstance(self.cell.turntable, Positioner) else "B"
        return {"robot": "R", "turntable": table}.get(parent, parent)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (mm, deg): ``items`` with their change, 1-sigma and change in
        sigmas, ``steps`` (each calibration's result), ``verdict``."""
        items = []
        for c in self.changes:
            to_mm = np.r_[np.full(3, 1e3), np.full(3, 180.0 / math.pi), np.ones(len(c.change) - 6)]
            entry = {"item": c.key, "before_xyzabc": pose_to_vendor(c.before, "kuka"),
                     "after_xyzabc": pose_to_vendor(c.after, "kuka"),
                     "change_mm_deg": c.change * to_mm, "sigma_mm_deg": c.sigma * to_mm,
                     "sigma_before_mm_deg": c.sigma_before * to_mm,
                     "change_sigmas": c.change_sigmas,
                     "sigma_relative_to": self.relative_to(c.key)}
            if c.robot is not None:
                entry["robot"] = c.robot
            items.append(entry)
        v = self.verdict
        return to_jsonable({"procedure": "cell", "iterations": self.iterations, "items": items,
                            "steps": [{"item": s.key, **s.result.to_json()} for s in self.steps],
                            "notes": list(self.notes),
                            "verdict": {"level": v.level, "reasons": v.reasons}})

    def summary(self) -> str:
        """Readable report: per item the change and its 1-sigma, per calibration its verdict."""
        rows = []
        for c in self.changes:
            d = c.change
            rows.append([c.key, float(np.linalg.norm(d[:3]) * 1e3),
                         float(np.degrees(np.linalg.norm(d[3:6]))),
                         float(np.linalg.norm(c.sigma[:3]) * 1e3),
                         float(np.degrees(np.linalg.norm(c.sigma[3:6]))),
                         float(np.max(np.abs(c.change_sigmas))),
                         float(np.linalg.norm(c.sigma_before[:3]) * 1e3)])
        n = len(self.steps)
        fitted = "1 calibration fitted" if n == 1 else f"{n} calibrations fitted together"
        robots = list(dict.fromkeys(c.robot for c in self.changes if c.robot is not None))
        if robots:
            fitted = (f"{n} calibration(s) of {len(robots)} robot(s) ({', '.join(robots)}), "
                      "fitted robot by robot, placements repeated")
        lines = [f"calibration: the whole cell, {fitted} ({self.iterations} iterations)", "",
                 ("changes (|position| mm, |rotation| deg; largest change in 1-sigma; 1-sigma "
                  "before):"),
                 format_table(["item", "moved mm", "turned deg", "1-sigma mm", "1-sigma deg",
                               "max |change|/sigma", "1-sigma before mm"], rows), "",
                 "each 1-sigma:"]
        lines += [f"  {c.key}: {sigma_basis(self.relative_to(c.key), (), _OWN)}"
                  for c in self.changes]
        lines += ["", "calibrations (at the fitted values):"]
        for s in self.steps:
            r = s.result
            lines.append(f"  {s.key or r.procedure}: RMS {r.rms * 1e3:.3f} mm over "
                         f"{len(r.used_norms)} touches, {r.verdict.line()}")
        if self.notes:
            lines += ["", "notes:"] + [f"  - {n}" for n in self.notes]
        v = self.verdict
        lines += ["", f"verdict: {v.level.upper()}: " + ("; ".join(v.reasons) or "every "
                                                             "calibration is good")]
        return "\n".join(lines)


def _calibrated(cell: Cell, owned: Callable[[str], bool] | None = None
                ) -> list[tuple[str, Provenance]]:
    """Items whose provenance records a touch file of a procedure :func:`calibrate_one_robot`
    repeats, with that provenance (of those ``owned(key)`` accepts, when given)."""
    items: list[tuple[str, Any]] = [(f"tools.{n}", t) for n, t in cell.tools.items()]
    items += [(f"frames.{n}", f) for n, f in cell.frames.items()]
    items += [("track", cell.track), ("turntable", cell.turntable)]
    return [(key, owner.provenance) for key, owner in items
            if owner is not None and owner.provenance.measurements is not None
            and owner.provenance.source in _PROCEDURES and (owned is None or owned(key))]


def touch_files(cell: Cell, owned: Callable[[str], bool] | None = None
                ) -> list[tuple[str, Path]]:
    """The touch files :func:`calibrate_one_robot` reads: those the cell's calibrations recorded.

    Parameters
    ----------
    cell : Cell
        A cell of one robot (or one robot's view of a cell of several).
    owned : callable, optional
        ``owned(key)``: whether the item is refitted (see :func:`calibrate_one_robot`).

    Returns
    -------
    list of (str, Path)
        Item (``tools.torch``, ``track``, ...) and its touch file, in the order of the cell.
    """
    return [(key, Path(prov.measurements)) for key, prov in _calibrated(cell, owned)]


def _recorded(cell: Cell, label: str, owned: Callable[[str], bool] | None
              ) -> list[tuple[str, Provenance]]:
    """Items with a recorded touch file, refusing missing or changed files (all named)."""
    out, problems = [], []
    for key, prov in _calibrated(cell, owned):
        problem = touch_file_problem(key, Path(prov.measurements), prov.sha256)
        if problem is None:
            out.append((key, prov))
        else:
            problems.append(problem)
    if problems:
        raise InputError(f"{label}: cannot repeat the calibrations: " + "; ".join(problems)
                         + ". Restore the files, or calibrate those items again")
    if not out:
        raise InputError(f"{label} records no calibration with its touch file: calibrate its "
                         f"items {term('cell:into', 'into the cell')} first (each calibration "
                         "then records its file)")
    return out


def _tool(option: Any) -> str | NDArray[np.float64] | None:
    if option is None or isinstance(option, str):
        return option
    return pose_from_vendor(np.asarray(option, dtype=float), "kuka")


def _run(cell: Cell, key: str, prov: Provenance, nominal: NominalAccuracy, time: str | None
         ) -> CellCalibration:
    """Repeat one recorded calibration on ``cell``."""
    o = prov.options
    name = key.partition(".")[2] or None
    context = CalibrationContext(tool=_tool(o.get("tool")),
                                 sigma=o["sigma_mm"] * 1e-3 if "sigma_mm" in o else None,
                                 time=time, file=prov.measurements, nominal=nominal)
    repeat = procedure(prov.source).repeat
    assert repeat is not None  # _recorded keeps the calibrations that are repeated
    return repeat(cell, prov.measurements, name, o, context)


def _size(key: str) -> int:
    return 7 if key == "track" else 6


def _values(cell: Cell, key: str) -> tuple[NDArray[np.float64], float]:
    """An item's pose and (track) scale."""
    T = item_pose(cell, key)[0]
    return T, cell.track.scale if key == "track" else 1.0


def _difference(T: NDArray[np.float64], scale: float, T0: NDArray[np.float64],
                scale0: float, size: int) -> NDArray[np.float64]:
    """Item parameters of ``(T, scale)`` relative to ``(T0, scale0)``."""
    d = np.r_[T[:3, 3] - T0[:3, 3], Rotation.from_matrix(T[:3, :3] @ T0[:3, :3].T).as_rotvec()]
    return np.r_[d, scale - scale0] if size == 7 else d


def _estimate_value(run: CellCalibration, cell: Cell
                    ) -> tuple[NDArray[np.float64], float]:
    """The pose (and scale) a calibration estimates for its item; unmeasured parts as they are."""
    r = run.result
    T, scale = _values(cell, run.key)
    if run.value in r.values:
        T = r.values[run.value]
    elif "tcp" in r.values:  # a TCP without orientation
        T = T.copy()
        T[:3, 3] = r.values["tcp"]
    return T, float(r.values.get("scale", scale))


def _moved(cell: Cell, key: str, d: NDArray[np.float64], prov: Provenance) -> None:
    """Write item ``key`` of ``cell`` moved by parameters ``d``, with provenance ``prov``."""
    kind, _, name = key.partition(".")
    if kind == "tools":
        cell.set_tool(name, perturbed(cell.tools[name].T_F_TCP, d), prov)
    elif kind == "frames":
        cell.update_frame(name, perturbed(cell.frames[name].pose, d), prov)
    elif key == "track":
        cell.update_track(prov, T_L_R0=perturbed(cell.track.T_L_R0, d[:6]),
                          scale=cell.track.scale + float(d[6]))
    else:
        cell.update_turntable(prov, T_parent_B=perturbed(cell.turntable.T_parent_B, d))


def item_difference(T: NDArray[np.float64], T0: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 6 parameters of pose ``T`` relative to ``T0``: origin (m) and rotation vector (rad,
    about the parent's axes), as an item's change."""
    return _difference(T, 1.0, T0, 1.0, 6)


def rebased(change: ItemChange, first: ItemChange) -> ItemChange:
    """``change``, made by a second fit of an item, taken relative to the values before the
    first fit (``first``), with the 1-sigma they had."""
    size = len(change.change)
    scale = 1.0 + first.change[6] + change.change[6] if size == 7 else 1.0
    delta = _difference(change.after, scale, first.before, 1.0, size)
    return replace(change, before=first.before, change=delta, sigma_before=first.sigma_before)


class _System:
    """The normal equations of all calibrations over the estimated items and the kept ones."""

    def __init__(self, estimated: list[str], kept: dict[str, Sources]):
        self.slices: dict[str, slice] = {}
        n = 0
        for key in estimated + list(kept):
            self.slices[key] = slice(n, n + _size(key))
            n += _size(key)
        self.nu = sum(_size(k) for k in estimated)
        self.kept = kept
        self.N = np.zeros((n, n))
        self.b = np.zeros(n)
        self.shares: list[tuple[NDArray[np.float64], dict[str, NDArray[np.float64]]]] = []

    def add(self, cols: list[int], H: NDArray[np.float64], W: NDArray[np.float64],
            y: NDArray[np.float64], errors: dict[str, NDArray[np.float64]]) -> None:
        """Equations ``H w[cols] = y + e``, ``cov(e) = W^-1``, ``e = sum_k F_k z_k`` by source.

        Equations added under one source name are independent parts of its error (the
        estimate and the residuals of one calibration).
        """
        idx = np.asarray(cols, dtype=int)
        HtW = H.T @ W
        self.N[np.ix_(idx, idx)] += HtW @ H
        self.b[idx] += HtW @ y
        gain = np.zeros((len(self.b), H.shape[0]))
        gain[idx] = HtW
        self.shares.append((gain, errors))

    def solve(self) -> tuple[NDArray[np.float64], Sources]:
        """The step of the estimated items and their error sources."""
        nu = self.nu
        Ninv = np.linalg.inv(self.N[:nu, :nu])
        step = Ninv @ self.b[:nu]
        factors: dict[str, NDArray[np.float64]] = {}
        for gain, errors in self.shares:
            for name, F in errors.items():
                f = Ninv @ gain[:nu] @ F
                factors[name] = np.hstack([factors[name], f]) if name in factors else f
        kept_widths: dict[str, int] = {}
        if self.kept:
            K = -Ninv @ self.N[:nu, nu:]
            for name, F in Sources.stack(list(self.kept.values())).map(K).factors.items():
                if name in factors and factors[name].shape == F.shape:
                    factors[name] = factors[name] + F
                else:  # the same source reached by another route: its parts side by side
                    factors[name] = np.hstack([factors[name], F]) if name in factors else F
                kept_widths[name] = F.shape[1]
        # A source of an item kept out of the fit keeps its columns (the item's parameters),
        # so that the item's own uncertainty and this fit's share of it stay one error.
        return step, Sources(nu, {k: f if kept_widths.get(k) == f.shape[1] else _compact(f)
                                  for k, f in factors.items()})


def calibrate_one_robot(cell: Cell, *, cell_label: str | None = None,
                        nominal: NominalAccuracy = NOMINAL_ACCURACY, time: str | None = None,
                        on_note: Callable[[str], None] | None = None,
                        owned: Callable[[str], bool] | None = None) -> CellRecalibration:
    """Re-estimate every calibrated item of a one-robot cell from all the touch files its
    calibrations used (:func:`robotcell.cell.calibrate.calibrate_cell` calls it, once per robot
    in a cell of several).

    Parameters
    ----------
    cell : Cell
        A cell of one robot (or one robot's view, :meth:`~robotcell.cell.Cell.for_robot`) whose
        items carry the provenance of calibrations into it (touch file, checksum, options: what
        ``calibrate ... --cell`` records).
    cell_label : str, optional
        Name of the cell in messages (its file).
    nominal : NominalAccuracy
        Accuracy of the items the calibrations used that have no recorded uncertainty.
    time : str, optional
        ISO 8601 time of the new provenance; default now.
    on_note : callable, optional
        Receives each note as it arises.
    owned : callable, optional
        ``owned(key)``: whether the item is refitted here (in a robot's view of a cell of
        several robots: its own items and the shared ones it calibrated); default every item.

    Returns
    -------
    CellRecalibration

    Raises
    ------
    InputError
        A recorded touch file is missing or changed (each is named), or the cell records no
        calibration with its file.
    """
    label = cell_label or f"cell {cell.name!r}"
    recorded = _recorded(cell, label, owned)
    notes: list[str] = []

    def note(text: str) -> None:
        if text not in notes:
            notes.append(text)
            if on_note is not None:
                on_note(text)

    original = {k: _values(cell, k) for k, _ in recorded if k != "turntable"
                or not isinstance(cell.turntable, Positioner)}
    estimated = [k for k, p in recorded if p.source != "positioner"]
    current = copied(cell)
    prior = {k: item_sources(cell, k, nominal)[0] for k in estimated}
    for it in range(1, MAX_ITERATIONS + 1):
        runs = [_run(current, k, p, nominal, time) for k, p in recorded]
        kept: dict[str, Sources] = {}
        for run in runs:
            for key in run.inputs:
                if key not in estimated and key not in kept:
                    kept[key], text = _input_sources(current, key, nominal)
                    if text:
                        note(text)
        system = _System(estimated, kept)
        for run, (key, prov) in zip(runs, recorded):
            _equations(system, run, current, prov.id or key, original.get(key), prior.get(key))
        step, sources = system.solve()
        sigma = np.sqrt(np.diag(sources.covariance))
        for key in estimated:
            _moved(current, key, step[system.slices[key]], item_pose(current, key)[1].provenance)
        if np.max(np.abs(step) / np.maximum(sigma, 1e-15)) < CONVERGED:
            break
    runs = [_run(current, k, p, nominal, time) for k, p in recorded]
    stamp = time or Provenance.now("cell").time
    new = copied(cell)
    changes = []
    for (key, prov), run in zip(recorded, runs):
        if key not in estimated:  # the positioner chain: its calibration at the fitted values
            new.update_positioner(run.provenance, run.cell.turntable.chain)
            continue
        rows = system.slices[key]
        item = sources.select(np.arange(rows.start, rows.stop))
        T, scale = _values(current, key)
        T0, scale0 = original[key]
        delta = _difference(T, scale, T0, scale0, _size(key))
        _moved(new, key, delta, replace(prov, time=stamp, sources=item.factors,
                                        rms_mm=run.result.rms * 1e3,
                                        note=fitted_note(prov.note)))
        changes.append(ItemChange(key, T0, T, delta, item.sigma, prior[key].sigma))
    return CellRecalibration(new, tuple(changes), tuple(runs), tuple(estimated),
                             sources.covariance, it, tuple(notes))


#: Directions of an error source's factor kept when it is written (relative to the largest,
#: every parameter's row scaled to length 1).
RANK_TOL = 1e-5

#: What the note of an item fitted with the whole cell ends with.
FITTED = "; fitted with the whole cell"


def fitted_note(note: str) -> str:
    """The note of an item after a whole-cell fit: said once, however often the cell is fitted."""
    return note if note.endswith(FITTED) else note + FITTED


def _compact(F: NDArray[np.float64]) -> NDArray[np.float64]:
    """A factor with the same ``F F^T`` and as few columns as its rank (every item's rows at
    once, so the correlations between items stay).

    The rank is taken with every row scaled to length 1 (parameters in m, rad and the track's
    scale differ by orders of magnitude), dropping the directions below :data:`RANK_TOL` of the
    largest: they change no parameter's variance by more than 1e-10 of it, far below the 6
    digits a cell file keeps, and would otherwise come and go from one fit of the same cell to
    the next. Each column's largest entry is positive, so that fitting the same cell again
    writes the same factor (the SVD's signs are arbitrary)."""
    lengths = np.linalg.norm(F, axis=1)
    lengths = np.where(lengths > 0, lengths, 1.0)
    U, S, _ = np.linalg.svd(F / lengths[:, None], full_matrices=False)
    keep = S > S[0] * RANK_TOL if S.size and S[0] > 0 else np.zeros(S.shape, dtype=bool)
    C = lengths[:, None] * U[:, keep] * S[keep]
    peak = C[np.argmax(np.abs(C), axis=0), np.arange(C.shape[1])]
    return C * np.where(peak < 0, -1.0, 1.0)


def _input_sources(cell: Cell, key: str, nominal: NominalAccuracy) -> tuple[Sources, str | None]:
    """Sources of an input that is not estimated: a kept cell item, or a tool given as a pose."""
    try:
        return item_sources(cell, key, nominal)
    except InputError:
        return Sources(6, {f"{key} nominal": np.diag(nominal.sigma(6))}), None


def _equations(system: _System, run: CellCalibration, cell: Cell, name: str,
               original: tuple[NDArray[np.float64], float] | None, prior: Sources | None) -> None:
    """The equations of one calibration (its touch noise is the error source ``name``).

    What its residuals say about its inputs, ``L^T dv = y`` with ``L L^T`` the input information
    and ``L y = -score`` (the normal equations of ``|r + J dv|^2 / s^2``); its estimate of its
    item in the directions its touches determine; and, for the other directions of the item,
    its values before the fit with their recorded uncertainty (``original``, ``prior``).
    """
    fit = run.result.fit
    cols_in = [i for key in run.inputs for i in range(system.slices[key].start,
                                                      system.slices[key].stop)]
    s2 = fit.noise_sigma ** 2
    if run.inputs:
        L = factor_of(fit.input_information / s2)
        y = np.linalg.lstsq(L, -fit.input_score / s2, rcond=None)[0]
        system.add(cols_in, L.T, np.eye(L.shape[1]), y, {name: np.eye(L.shape[1])})
    est = run.result.estimates.get(run.value)
    if est is None or original is None or prior is None:
        return
    size = _size(run.key)
    own_cols = list(range(system.slices[run.key].start, system.slices[run.key].stop))
    D = est.determined
    own = D.T @ est.sources.factors[OWN]
    T, scale = _estimate_value(run, cell)
    Tc, scale_c = _values(cell, run.key)
    y = D.T @ _difference(T, scale, Tc, scale_c, size)
    H = np.hstack([D.T, -D.T @ est.gain]) if run.inputs else D.T
    system.add(own_cols + cols_in, H, np.linalg.inv(own @ own.T), y, {name: own})
    if D.shape[1] < size:
        Nb = np.linalg.svd(np.eye(size) - D @ D.T)[0][:, :size - D.shape[1]]
        errors = prior.map(Nb.T).factors
        C = sum(f @ f.T for f in errors.values())
        y = Nb.T @ _difference(*original, Tc, scale_c, size)
        system.add(own_cols, Nb.T, np.linalg.pinv(C), y, errors)
