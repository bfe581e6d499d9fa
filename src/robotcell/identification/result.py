"""The result of a kinematic identification: model, parameters with uncertainty, residuals."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.stats import chi2

from robotcell.calibration.result import CONDITION_LIMIT, to_jsonable
from robotcell.calibration.sigmaparts import sigma_basis
from robotcell.identification.uncertainty import PredictedError
from robotcell.io.tables import format_table
from robotcell.robot.robot import Robot

#: What every 1-sigma of an identification is relative to: the measuring device's frame
#: (:data:`robotcell.calibration.sigmaparts.FRAMES`).
SIGMA_RELATIVE_TO = "device"
#: What determines it, for :func:`~robotcell.calibration.sigmaparts.sigma_basis`.
OWN_MEASUREMENTS = "its own measurements"

__all__ = ["CV_HELD", "GEOMETRIC_SOURCE", "MAX_CHANGE_ANGLE", "MAX_CHANGE_LENGTH", "OUTLIERS_NAMED",
           "IdentificationResult", "Parameter", "beyond_accuracy"]

#: How far a link constant of a real arm can be from its drawing (m, rad): manufacturing and
#: mastering errors are well under a millimetre and a few tenths of a degree; a constant that
#: moves further says that the nominal model is not this arm's.
MAX_CHANGE_LENGTH = 20e-3
MAX_CHANGE_ANGLE = math.radians(2.0)
#: The reason of a constant held because freeing it predicts held-out rows worse begins so.
CV_HELD = "held by cross-validation"
#: The ``source`` of a start model built by the circle point analysis.
GEOMETRIC_SOURCE = "circle point analysis of the measurements"

#: Outlier rows the verdict's reason names; it counts the others (``and 2 more``), the summary's
#: and the JSON's outlier lists name every one.
OUTLIERS_NAMED = 5


@dataclass(frozen=True)
class Parameter:
    """One model constant.

    Attributes
    ----------
    name : str
        ``base.x``, ``A2.alpha``, ``target1.y``, ``A3.scale``, ``j23_factor``, ...
    value : float
        Identified value (m, rad, or unitless for scale and coupling).
    nominal : float
        Nominal value for link constants (NaN for base and targets, which have none).
    sigma : float
        1-sigma (same unit); NaN when fixed.
    free : bool
        True when identified, False when held at its nominal value.
    why : str
        Why a fixed parameter was held.
    kind : {"length", "angle", "number", "compliance"}
        ``compliance``: rad per N m (shown in urad/Nm).
    """

    name: str
    value: float
    nominal: float
    sigma: float
    free: bool
    why: str
    kind: str

    def vendor(self) -> tuple[float, float, float, str]:
        """Value, nominal and sigma in mm / deg / urad per N m, and the unit."""
        s, unit = {"length": (1e3, "mm"), "angle": (180 / math.pi, "deg"), "number": (1.0, ""),
                   "compliance": (1e6, "urad/Nm")}[self.kind]
        return self.value * s, self.nominal * s, self.sigma * s, unit


@dataclass(eq=False)
class IdentificationResult:
    """Outcome of :func:`robotcell.identification.identify` (SI units).

    Attributes
    ----------
    robot : Robot
        The identified model: the nominal's joints (convention, names, signs, limits) with the
        identified constants, Hayati's ``beta`` at nearly parallel axes, and the nominal's base,
        flange and tool. Its FK takes the controller values: identified scales and J2/J3 factor
        are its ``coupling``; ``ik_seed`` is the nominal model (when that has an analytic IK).
        ``base @ robot.fk(q, tool=target_tool)`` predicts the measurement in the device frame.
    nominal : Robot
    base : ndarray, shape (4, 4)
        ``T_D_R``: the robot base in the device frame (m).
    targets : ndarray, shape (K, 3)
        Reflector positions in the flange frame of the identified model (m); empty for poses.
    target : ndarray, shape (4, 4) or None
        ``T_F_T``: the measured target frame in the flange frame (poses only, m).
    parameters : list of Parameter
    correlation, covariance : ndarray, shape (p, p)
        Over the free parameters, in the order of ``free``.
    free : list of str
    fixed : list of (str, str)
        Name and reason of each parameter held because the data cannot identify it.
    residuals, residuals_before : ndarray, shape (N, K, 3)
        Measured minus model position per row and target, after identification and with the
        nominal links (base and targets fitted) (m).
    rotation_residuals, rotation_residuals_before : ndarray, shape (N, 3) or None
        Rotation vector from the model to the measured orientation (rad).
    condition : float
        Condition number of the weighted Jacobian with unit columns (free parameters).
    dof : int
        Measured coordinates minus free parameters.
    variance_factor : float
        ``s0 = sqrt(chi^2 / dof)``: about 1 when the stated accuracies are right.
    outliers : list of int
        Rows (0-based) whose residual is an outlier at 3 sigma.
    labels : list of str
    scale : ndarray, shape (n,)
        Per-axis scale errors (0 when not identified).
    j23_factor : float
        J2/J3 factor ``k`` (``q3_model = J3 + k J2``).
    touch_sigma, angle_sigma : float
        Accuracies used as weights (m, rad).
    unexplained : float
        Scatter per coordinate (m) of a measured point held out of the fit that no parameter
        explains: from the leave-one-out cross-validated residuals, less the part the
        parameters' uncertainty explains. It holds the measuring error and the model error.
    coupling_check : dict
        Filled by :func:`~robotcell.identification.coupling.coupling_check`: RMS with, without
        and with the fitted J2/J3 coupling, and whether the data support the stated one.
    """

    robot: Robot
    nominal: Robot
    base: NDArray[np.float64]
    targets: NDArray[np.float64]
    target: NDArray[np.float64] | None
    parameters: list[Parameter]
    correlation: NDArray[np.float64]
    covariance: NDArray[np.float64]
    free: list[str]
    fixed: list[tuple[str, str]]
    residuals: NDArray[np.float64]
    rotation_residuals: NDArray[np.float64] | None
    residuals_before: NDArray[np.float64]
    rotation_residuals_before: NDArray[np.float64] | None
    condition: float
    dof: int
    variance_factor: float
    outliers: list[int]
    labels: list[str]
    scale: NDArray[np.float64]
    j23_factor: float
    touch_sigma: float
    angle_sigma: float
    unexplained: float = float("nan")
    _q: Any = None
    _chain: Any = None
    _x: Any = None
    _x_nominal: Any = None
    coupling_check: dict[str, Any] = field(default_factory=dict)

    # -- figures --------------------------------------------------------------------------------
    @staticmethod
    def _rms(r: NDArray[np.float64]) -> float:
        return float(np.sqrt(np.mean(np.sum(r**2, axis=-1)))) if r.size else 0.0

    @property
    def rms_before(self) -> float:
        """RMS position error of the nominal model (base and targets fitted), m."""
        return self._rms(self.residuals_before)

    @property
    def rms_after(self) -> float:
        """RMS position error of the identified model, m."""
        return self._rms(self.residuals)

    @property
    def max_after(self) -> float:
        """Largest position error of the identified model, m."""
        return float(np.linalg.norm(self.residuals, axis=-1).max())

    @property
    def row_errors(self) -> NDArray[np.float64]:
        """Position error per row (largest over its targets), shape (N,), m."""
        return np.linalg.norm(self.residuals, axis=-1).max(axis=1)

    @property
    def target_tool(self) -> NDArray[np.float64]:
        """``T_F_T``: the measured target as a tool on the flange, shape (4, 4) (m).

        The target frame for pose measurements, else the first reflector (identity rotation).
        """
        if self.target is not None:
            return self.target.copy()
        T = np.eye(4)
        if len(self.targets):
            T[:3, 3] = self.targets[0]
        return T

    @property
    def model_error(self) -> float:
        """Scatter per coordinate (m) that the model cannot explain beyond the stated accuracy.

        What the arm does that its geometric model does not (elasticity, temperature, gear
        errors), as the leave-one-out cross-validated residuals show it
        (:func:`beyond_accuracy`); 0 when they are within the stated accuracy.
        """
        return beyond_accuracy(self.unexplained, self.touch_sigma, self.dof)

    def predicted_error(self, q: ArrayLike, measured: bool = False) -> PredictedError:
        """The predicted error of the identified model's position of each target at ``q``.

        Parameters
        ----------
        q : array_like, shape (N, n)
            Controller joint values (rad, m).
        measured : bool
            False: the error of the predicted position against where the target really is
            (the parameters' covariance and the model error). True: against a measurement of
            it (plus the measuring error): what a row held out of the fit shows.

        Returns
        -------
        PredictedError
            Covariance shape (N, K, 3, 3), in the device frame D (m^2): ``J C J^T`` over every
            identified parameter (base, links, targets; ``covariance``, correlations kept) plus
            ``model_error^2`` per coordinate, or ``unexplained^2`` with ``measured``.
        """
        ch, x = self._chain, self._x
        qq = np.atleast_2d(np.asarray(q, dtype=float))
        kept = [ch.index(n) for n in self.free]
        ev = ch.evaluate(x, qq)
        pts, _ = ch.predict(x, qq)
        J = ch.point_jacobian(x, qq, ev, pts)[..., kept]
        u = self.unexplained if math.isfinite(self.unexplained) else self.touch_sigma
        floor = u if measured else self.model_error
        S = J @ self.covariance @ np.swapaxes(J, -1, -2) + floor**2 * np.eye(3)
        return PredictedError(S)

    def error_figures(self) -> dict[str, Any]:
        """The predicted error at the measured rows, in mm (the report's and JSON's figures).

        Returns
        -------
        dict
            ``model_error_mm`` and ``unexplained_mm`` (1-sigma per coordinate); of the
            identified position of a target at the measured configurations (not a measurement
            of it, :meth:`predicted_error`), the medians over rows and targets of ``per_axis_mm``
            (1-sigma along x, y, z of the device frame), ``rms_mm`` (3D RMS) and
            ``radius95_mm`` (95 % radius), and the largest ``rms_max_mm``; ``sigma_relative_to``
            is ``"device"``: every figure is relative to the measuring device's frame, from the
            identification's own measurements only.
        """
        out: dict[str, Any] = {"model_error_mm": self.model_error * 1e3,
                               "unexplained_mm": self.unexplained * 1e3,
                               "sigma_relative_to": SIGMA_RELATIVE_TO}
        if self._q is not None:
            e = self.predicted_error(self._q)
            out.update(per_axis_mm=np.median(e.per_axis.reshape(-1, 3), axis=0) * 1e3,
                       rms_mm=float(np.median(e.rms)) * 1e3,
                       radius95_mm=float(np.median(e.radius())) * 1e3,
                       rms_max_mm=float(e.rms.max()) * 1e3)
        return out

    def parameter(self, name: str) -> Parameter:
        """The parameter called ``name``."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    def model_joints(self, q: ArrayLike) -> NDArray[np.float64]:
        """Model joint values for controller values ``q`` (..., n): scale and coupling applied."""
        arr = np.asarray(q, dtype=float)
        flat = arr.reshape(-1, arr.shape[-1])
        return self._chain.model_joints(self._x, flat).reshape(arr.shape)

    def predict(self, q: ArrayLike, nominal: bool = False) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Predicted targets in the device frame for controller values ``q`` (N, n).

        With ``nominal=True``: the nominal links with the base and targets fitted to them (the
        model behind ``rms_before``).

        Returns
        -------
        points : ndarray, shape (N, K, 3)
            (m); one point per row (the target frame origin) for pose measurements.
        rotations : ndarray, shape (N, 3, 3)
            Orientation of the target frame (meaningful for pose measurements).
        """
        x = self._x_nominal if nominal else self._x
        return self._chain.predict(x, np.atleast_2d(np.asarray(q, dtype=float)))

    def moved_too_far(self) -> list[tuple[Parameter, float]]:
        """Link constants that moved further from the start than a real arm differs from its
        drawing (:data:`MAX_CHANGE_LENGTH`, :data:`MAX_CHANGE_ANGLE`), with their change (m,
        rad; angles on the circle)."""
        out = []
        for p in self.parameters:
            if not (p.free and math.isfinite(p.nominal) and p.kind in ("length", "angle")):
                continue
            change = p.value - p.nominal
            if p.kind == "angle":
                change = math.remainder(change, 2.0 * math.pi)
            if abs(change) > (MAX_CHANGE_LENGTH if p.kind == "length" else MAX_CHANGE_ANGLE):
                out.append((p, change))
        return out

    def _moved_text(self) -> str:
        """The verdict's reason for constants that moved too far."""
        moved = self.moved_too_far()
        names = ", ".join(f"{p.name} {c * (1e3 if p.kind == 'length' else 180 / math.pi):+.1f} "
                          f"{'mm' if p.kind == 'length' else 'deg'}" for p, c in moved[:6])
        more = f" and {len(moved) - 6} more" if len(moved) > 6 else ""
        bound = (f"more than {MAX_CHANGE_LENGTH * 1e3:g} mm or {math.degrees(MAX_CHANGE_ANGLE):g} "
                 "deg, which no real arm is off its drawing")
        if self.nominal.source == GEOMETRIC_SOURCE:
            return (f"constants moved from the geometric start by {names}{more} ({bound}): check "
                    "the rows that move one joint at a time")
        return (f"the data contradict the nominal model {self.nominal.name}: its constants "
                f"moved by {names}{more} ({bound}); it is not this arm's model (another robot?): "
                "give this arm's nominal, or identify without one, from the geometric start of "
                "rows moving one joint at a time (docs/identification.md)")

    @property
    def verdict(self) -> tuple[str, str]:
        """``("good" | "check" | "poor", why)``.

        Poor: a link constant moved further than a real arm differs from its drawing (a nominal
        model of another arm, :meth:`moved_too_far`), the residuals are more than 3 times the
        stated accuracy (``s0 > 3``), or nothing but the base could be identified (unless
        cross-validation held the constants, :data:`CV_HELD`). Check: ``s0`` above the 99 %
        chi-square bound, a condition number above 100, or outlier rows.
        """
        if self.moved_too_far():
            return "poor", self._moved_text()
        s0 = self.variance_factor
        if math.isfinite(s0) and s0 > 3.0:
            return "poor", (f"the residuals are {s0:.1f} times the stated accuracy (RMS "
                            f"{self.rms_after * 1e3:.3f} mm); the model or the joint values do "
                            "not explain the measurements")
        chosen = any(why.startswith(CV_HELD) for _, why in self.fixed)
        if not chosen and not any(p.free and p.kind in ("length", "angle")
                                  and not p.name.startswith(("base.", "target"))
                                  for p in self.parameters):
            return "poor", "no link parameter is identifiable from these measurements"
        reasons = []
        bound = math.sqrt(_chi2_bound(self.dof)) if self.dof > 0 else float("inf")
        if math.isfinite(s0) and s0 > bound:
            reasons.append(f"residuals {s0:.2f} times the stated accuracy (bound {bound:.2f})")
        if self.condition > CONDITION_LIMIT:
            reasons.append(f"condition number {self.condition:.0f} above {CONDITION_LIMIT:.0f}")
        if self.outliers:
            shown = [self.labels[i] for i in self.outliers[:OUTLIERS_NAMED]]
            more = len(self.outliers) - len(shown)
            reasons.append(f"{len(self.outliers)} outlier row(s): " + ", ".join(shown)
                           + (f" and {more} more" if more else ""))
        if reasons:
            return "check", "; ".join(reasons)
        return "good", "residuals consistent with the stated accuracy, well conditioned"

    # -- output ---------------------------------------------------------------------------------
    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict in mm and degrees (the CLI's ``--json``)."""
        base = self.base.copy()
        base[:3, 3] *= 1e3
        out: dict[str, Any] = {
            "robot": self.robot.name,
            "base": base,
            "targets": self.targets * 1e3 if self.target is None else [self.target[:3, 3] * 1e3],
            "rms_before_mm": self.rms_before * 1e3,
            "rms_after_mm": self.rms_after * 1e3,
            "max_after_mm": self.max_after * 1e3,
            "fixed": [n for n, _ in self.fixed],
            "fixed_why": {n: w for n, w in self.fixed},
            "parameters": [
                {"name": p.name, "value": p.vendor()[0], "nominal": p.vendor()[1], "sigma": p.vendor()[2],
                 "unit": p.vendor()[3], "free": p.free}
                for p in self.parameters
            ],
            "condition": self.condition,
            "dof": self.dof,
            "variance_factor": self.variance_factor,
            "outliers": [self.labels[i] for i in self.outliers],
            "residuals_mm": np.linalg.norm(self.residuals, axis=-1) * 1e3,
            "residuals_before_mm": np.linalg.norm(self.residuals_before, axis=-1) * 1e3,
            "labels": self.labels,
            "j23_factor": self.j23_factor,
            "predicted_error": self.error_figures(),
            "sigma_relative_to": SIGMA_RELATIVE_TO,
            "verdict": self.verdict[0],
            "verdict_why": self.verdict[1],
        }
        if self.target is not None:
            T = self.target.copy()
            T[:3, 3] *= 1e3
            out["target"] = T
            out["rotation_rms_before_deg"] = math.degrees(self._rms(self.rotation_residuals_before))
            out["rotation_rms_after_deg"] = math.degrees(self._rms(self.rotation_residuals))
        if self.coupling_check:
            out["coupling_check"] = self.coupling_check
        return to_jsonable(out)

    def summary(self) -> str:
        """Readable report in mm and degrees."""
        orient = " with orientation" if self.target is not None else ""
        lines = [(f"identification of {self.nominal.name}: {len(self.labels)} rows, "
                  f"{self.residuals.shape[1]} target(s){orient}"), ""]
        b = self.base
        lines.append("robot base in the device frame (mm): "
                     + ", ".join(f"{v:.3f}" for v in b[:3, 3] * 1e3))
        for k, t in enumerate(self.targets):
            lines.append(f"target {k + 1} on the flange (mm): " + ", ".join(f"{v:.3f}" for v in t * 1e3))
        rows = []
        for p in self.parameters:
            v, nom, s, unit = p.vendor()
            if p.name.startswith(("base.", "target")):
                continue
            rows.append([p.name, unit, f"{nom:.4f}" if math.isfinite(nom) else "",
                         f"{v:.4f}", f"{v - nom:+.4f}" if math.isfinite(nom) else "",
                         f"{s:.4f}" if p.free else "fixed"])
        lines += ["", f"parameters (1-sigma {sigma_basis(SIGMA_RELATIVE_TO, own=OWN_MEASUREMENTS)}):", format_table(["name", "unit", "nominal", "identified", "change", "1-sigma"], rows)]
        if self.fixed:
            lines += ["", "held at nominal (not identifiable from these measurements):"]
            lines += [f"  - {n}: {w}" for n, w in self.fixed]
        e0 = np.linalg.norm(self.residuals_before, axis=-1) * 1e3
        e1 = np.linalg.norm(self.residuals, axis=-1) * 1e3
        lines += ["", "position error (mm)      mean      RMS      max",
                  f"  nominal model     {e0.mean():9.4f} {self.rms_before * 1e3:8.4f} {e0.max():8.4f}",
                  f"  identified model  {e1.mean():9.4f} {self.rms_after * 1e3:8.4f} {e1.max():8.4f}"]
        for title, e in (("nominal", e0.max(axis=1)), ("identified", self.row_errors * 1e3)):
            lines += [f"rows by position error, {title} model (mm):"] + _histogram(e)
        if self.rotation_residuals is not None:
            lines.append(f"orientation error RMS (deg): nominal "
                         f"{math.degrees(self._rms(self.rotation_residuals_before)):.4f}, identified "
                         f"{math.degrees(self._rms(self.rotation_residuals)):.4f}")
        lines.append(f"condition number {self.condition:.1f}, redundancy {self.dof}, variance factor "
                     f"{self.variance_factor:.3f} (1 when the stated accuracy "
                     f"{self.touch_sigma * 1e3:.3f} mm is right)")
        lines += self.error_lines()
        if self.outliers:
            lines.append("outlier rows (3 sigma): " + ", ".join(self.labels[i] for i in self.outliers))
        if self.coupling_check:
            c = self.coupling_check
            lines.append(f"J2/J3 coupling: {c['verdict']}")
        v, why = self.verdict
        lines += ["", f"verdict: {v} ({why})"]
        return "\n".join(lines)

    def error_lines(self) -> list[str]:
        """The summary's lines on the model error and the predicted error of a position."""
        f = self.error_figures()
        lines = [(f"model error (what the geometric model does not explain): "
                  f"{f['model_error_mm']:.4f} mm per coordinate (the leave-one-out residuals "
                  f"scatter by {f['unexplained_mm']:.4f} mm, the stated accuracy is "
                  f"{self.touch_sigma * 1e3:.4f} mm)")]
        if "rms_mm" in f:
            x, y, z = f["per_axis_mm"]
            lines.append(f"predicted error of a target position (median over the rows; whole "
                         f"covariance and model error): 1-sigma per axis x {x:.4f} y {y:.4f} "
                         f"z {z:.4f} mm, 3D RMS {f['rms_mm']:.4f} mm, 95 % radius "
                         f"{f['radius95_mm']:.4f} mm; "
                         f"{sigma_basis(SIGMA_RELATIVE_TO, own=OWN_MEASUREMENTS)}")
        return lines


def beyond_accuracy(unexplained: float, accuracy: float, dof: int) -> float:
    """The model error: the unexplained scatter beyond the stated accuracy (m per coordinate).

    ``sqrt(max(unexplained^2 - (1 + sqrt(2 / dof)) accuracy^2, 0))``. A variance estimated from
    ``dof`` degrees of freedom scatters by ``sqrt(2 / dof)`` of itself, so measurements exactly
    as accurate as stated show an unexplained scatter above the accuracy half the time; only the
    part beyond one such standard deviation counts (else a model error of a quarter of the
    accuracy would appear on average where there is none, at 100 degrees of freedom).

    Parameters
    ----------
    unexplained : float
        :attr:`IdentificationResult.unexplained` (m).
    accuracy : float
        Stated accuracy of a measured coordinate (m).
    dof : int
        Redundancy of the fit.

    Returns
    -------
    float
        m; 0 when ``unexplained`` is not finite.
    """
    if not math.isfinite(unexplained):
        return 0.0
    floor = 1.0 + math.sqrt(2.0 / max(dof, 1))
    return math.sqrt(max(unexplained**2 - floor * accuracy**2, 0.0))


def _histogram(values: NDArray[np.float64], bins: int = 6, width: int = 40) -> list[str]:
    """Text histogram lines ``  lo - hi  ####  count`` of ``values``."""
    counts, edges = np.histogram(values, bins=bins)
    top = max(int(counts.max()), 1)
    return [f"  {lo:8.4f} - {hi:8.4f}  {'#' * round(width * c / top):<{width}} {c}"
            for lo, hi, c in zip(edges[:-1], edges[1:], counts)]


def _chi2_bound(dof: int) -> float:
    return float(chi2.ppf(0.99, dof) / dof)
