"""The verdict on a calibration: good, check or poor, and why.

One rule for every procedure, used by the terminal report, the ``--json`` output and the HTML
report, so all three say the same. It reads the result in its JSON form
(:meth:`robotcell.calibration.CalibrationResult.to_json`, millimetres and degrees), so a report
made later from a saved result judges it exactly as the terminal did.

The rule (``docs/calibration.md``, "Verdict"):

- **Accuracy.** The touch accuracy ``s`` is the one stated with ``--sigma``
  (``accuracy_source == "stated"``) or :data:`DEFAULT_TOUCH_SIGMA_MM`. If the touches were that
  accurate, ``chi2`` (``SSR / s^2``, SSR the sum of squared residuals of the touches used, the
  inputs' errors taken out) would be chi-square distributed with the redundancy ``dof`` as
  degrees of freedom. Above its :data:`CHI2_P` quantile the residuals are larger than the
  accuracy explains: *check*; above that quantile for ``POOR_FACTOR * s``: *poor*.
- **Scale** (track): more than :data:`SCALE_CHECK` from 1: *check*; more than
  :data:`SCALE_POOR`: *poor*.
- **Conditioning**: condition number above :data:`CONDITION_GOOD`: *check*; above
  :data:`CONDITION_POOR`: *poor*.
- **Size**: a length in the result (an origin, a TCP, a radius, an offset, a touched point)
  beyond :data:`CELL_EXTENT_MM`: *poor* (no robot cell is that large; a unit or typing error).
- **Redundancy**: without :data:`OUTLIER_REDUNDANCY` redundant coordinates a wrong touch cannot be
  singled out (see :func:`touches_for_outlier_check`): *check*, naming how many touches would
  make the check possible. With no redundancy at all nothing checks the result.
- **Touches.** A touch flagged as an outlier, or left out as one: *check*; one flagged beyond
  3 sigma for ``POOR_FACTOR * s`` that could not be left out, or touches that disagree by that
  much (one is wrong, nothing tells which): *poor*. A touch that alone decides a direction of the
  result (``unchecked``): *check*, naming it.
- Any other warning of the procedure: *check*.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.special import chdtri

from robotcell.errors import term
from robotcell.io.tables import CELL_EXTENT_MM

__all__ = [
    "CELL_EXTENT_MM",
    "CHI2_P",
    "CONDITION_GOOD",
    "CONDITION_POOR",
    "DEFAULT_TOUCH_SIGMA_MM",
    "OUTLIER_REDUNDANCY",
    "POOR_FACTOR",
    "SCALE_CHECK",
    "SCALE_POOR",
    "Verdict",
    "touches_for_outlier_check",
    "verdict",
]

#: Touch-up accuracy assumed when none is stated (mm, 1-sigma per coordinate): a technician
#: touching a sharp reference with a pointed tool by eye; the demo and ``simulate`` use 0.1 mm.
DEFAULT_TOUCH_SIGMA_MM = 0.5
#: Probability of the chi-square bound: good touches exceed it once in a thousand calibrations.
CHI2_P = 0.999
#: Residuals that need a noise more than this many times the accuracy are poor.
POOR_FACTOR = 3.0
#: Condition numbers up to this are a good measurement design (Schroer's threshold, as cited by
#: Nahvi and Hollerbach, ICRA 1996) ...
CONDITION_GOOD = 100.0
#: ... and above this the result is not trustworthy.
CONDITION_POOR = 1000.0
#: Relative deviation of a track scale from 1 that asks for a check of the gear ratio ...
SCALE_CHECK = 0.02
#: ... and that no real track has (a unit error or touches of different points).
SCALE_POOR = 0.10
#: Redundant coordinates left after removing one touch (3 coordinates) needed to single out a
#: wrong touch: with 6, an outlier flagged half the time is at most twice the one flagged with a
#: known noise (the F(3, 6) against the chi-square(3) 3-sigma test); with 3 it is 3.7 times.
OUTLIER_REDUNDANCY = 6

#: JSON keys in mm that are not lengths of the result (residual statistics, uncertainties).
_NOT_LENGTHS = {"residuals_mm", "residuals_xyz_mm", "rms_mm", "max_mm", "mean_mm", "min_mm",
                "noise_sigma_mm", "straightness_mm", "touch_sigma_mm", "residual_sigma_mm"}


@dataclass(frozen=True)
class Verdict:
    """Grade of a calibration result.

    Attributes
    ----------
    level : {"good", "check", "poor"}
    reasons : list of str
        Why, most serious first; for ``good`` what was checked.
    condition : float
        The condition number the verdict used (as printed in the terminal report).
    touch_sigma_mm : float
        Touch accuracy the chi-square bound used (mm, 1-sigma per coordinate).
    accuracy_source : {"stated", "default"}
    chi2 : float or None
        ``SSR / touch_sigma^2``; None without redundancy.
    chi2_bound : float or None
        Its :data:`CHI2_P` quantile for ``dof`` degrees of freedom; None without redundancy.
    touches_needed : int or None
        Number of touches (in all) that would let a wrong touch be singled out, when the
        measurements have too little redundancy; else None.
    """

    level: str
    reasons: list[str] = field(default_factory=list)
    condition: float = float("nan")
    touch_sigma_mm: float = DEFAULT_TOUCH_SIGMA_MM
    accuracy_source: str = "default"
    chi2: float | None = None
    chi2_bound: float | None = None
    touches_needed: int | None = None

    def line(self) -> str:
        """The one-line verdict of the terminal report: ``verdict: POOR: reason; reason``."""
        return f"verdict: {self.level.upper()}: {'; '.join(self.reasons)}"

    def to_json(self) -> dict[str, Any]:
        """The verdict as plain JSON values (NaN becomes None)."""
        def num(v: float | None) -> float | None:
            return None if v is None or not math.isfinite(v) else float(v)
        return {"level": self.level, "reasons": list(self.reasons),
                "condition": num(self.condition), "touch_sigma_mm": self.touch_sigma_mm,
                "accuracy_source": self.accuracy_source, "chi2": num(self.chi2),
                "chi2_bound": num(self.chi2_bound), "touches_needed": self.touches_needed}


def format_condition(condition: float) -> str:
    """The condition number as every report prints it (one decimal)."""
    if math.isnan(condition):
        return "unknown"
    return f"{condition:.1f}" if math.isfinite(condition) else "infinite"


def touches_for_outlier_check(n_touches: int, dof: int) -> int | None:
    """Touches needed so that a wrong touch can be singled out, or None when there are enough.

    Removing one touch removes 3 coordinates; the rest must keep :data:`OUTLIER_REDUNDANCY`
    redundant coordinates. Each further touch of the same point(s) adds 3.

    Parameters
    ----------
    n_touches : int
        Touches (measured points) used.
    dof : int
        Redundancy of the fit (coordinates minus parameters).

    Returns
    -------
    int or None
        Smallest number of touches in all, assuming every added touch adds 3 coordinates and no
        parameter (a repeated touch of a point already touched); None when ``dof`` suffices.
    """
    missing = OUTLIER_REDUNDANCY + 3 - dof
    if missing <= 0:
        return None
    return n_touches + math.ceil(missing / 3)


def _number(v: Any, default: float = float("nan")) -> float:
    """A JSON number as float; ``default`` for null, text or anything else."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return default
    return float(v) if math.isfinite(v) else default


def _floats(v: Any) -> np.ndarray:
    """Numbers of a JSON value as a float array; None (a JSON null for NaN) becomes NaN."""
    a = np.asarray(v, dtype=object)
    return np.where(np.equal(a, None), np.nan, a).astype(float)


def _lengths(result: Mapping[str, Any]) -> list[tuple[str, float]]:
    """(name, largest |value| in mm) of every length in the result."""
    out = []
    for key, v in result.items():
        if key == "matrix" or key == "turntable_matrix":
            try:
                t = _floats(v)[:3, 3]
            except (TypeError, ValueError, IndexError):
                continue
            if not np.any(np.isnan(t)):
                out.append(("origin" if key == "matrix" else "turntable origin",
                            float(np.max(np.abs(t)))))
        elif key == "points_mm" or (key.endswith("_mm") and key not in _NOT_LENGTHS):
            try:
                a = np.abs(_floats(v))
            except (TypeError, ValueError):
                continue
            a = a[~np.isnan(a)]  # null: not determined
            if a.size:
                out.append(("touched points" if key == "points_mm" else key[:-3], float(a.max())))
    return out


def _names(value: Any) -> list[str]:
    """A JSON list of touch labels as strings (empty for anything else)."""
    return [str(v) for v in value] if isinstance(value, list) else []


def _too_few(used: int, left_out: int, dof: int, needed: int) -> str:
    """The reason of a verdict whose touches cannot single out a wrong one.

    Parameters
    ----------
    used : int
        Touches the result was computed from.
    left_out : int
        Touches given but left out as outliers.
    dof : int
        Redundancy of the fit from the touches used.
    needed : int
        Touches to use that would single out a wrong one (:func:`touches_for_outlier_check`).

    Returns
    -------
    str
        E.g. ``"redundancy 5 is too little to single out a wrong touch; take 6 or more
        touches (4 given: 2 more)"``; with touches left out it counts the touches given, left
        out and used, and how many more to take.
    """
    more = needed - used
    take = f"{more} more touch{'es' if more > 1 else ''}"
    if not left_out:
        what = (f"no redundancy: {used} touches determine the result exactly, so nothing checks "
                "it and a wrong touch goes unseen" if dof <= 0 else
                f"redundancy {dof} is too little to single out a wrong touch")
        return f"{what}; take {needed} or more touches ({used} given: {take})"
    counts = (f"of the {used + left_out} touches given, {left_out} left out as "
              f"{'an outlier' if left_out == 1 else 'outliers'} and {used} used")
    what = (f"no redundancy: {counts}, which determine the result exactly, so nothing checks it"
            if dof <= 0 else
            f"redundancy {dof} is too little to single out a wrong touch: {counts}")
    return (f"{what}; take {take} (re-touching one left out counts), so that {needed} or more "
            "are used")


def verdict(result: Mapping[str, Any]) -> Verdict:
    """Grade a calibration result by the rule of this module.

    Parameters
    ----------
    result : mapping
        A calibration result as JSON (mm, deg): the output of ``CalibrationResult.to_json()`` or
        of ``robotcell calibrate ... --json``. Used: ``residuals_xyz_mm`` (or ``residuals_mm``),
        ``dof``, ``noise_source``, ``noise_sigma_mm``, ``condition``, ``warnings``, ``scale``,
        ``matrix``, the lengths ending in ``_mm`` and ``sigma_parts`` (a pose whose 1-sigma
        holds an assumed part gets a reason saying so, whatever the level).

    Returns
    -------
    Verdict
    """
    poor: list[str] = []
    check: list[str] = []
    cond = _number(result.get("condition"))
    dof = int(_number(result.get("dof"), 0.0))
    labels = [str(v) for v in result.get("labels") or []]
    excluded = _names(result.get("excluded"))
    res = result.get("residuals_xyz_mm")
    if res is None:
        res = result.get("residuals_mm") or []
    try:
        r = _floats(res)
    except (TypeError, ValueError):
        r = np.full(1, np.nan)  # unreadable residuals: no bound can hold
    left_out = 0
    if excluded and len(labels) == len(r):
        r = r[[lab not in excluded for lab in labels]]
        left_out = len(labels) - len(r)
    n = len(r) if r.ndim else 0
    ssr = float(np.sum(r**2)) if np.all(np.isfinite(r)) else float("inf")
    if result.get("accuracy_source") in ("stated", "default"):
        stated = _number(result.get("touch_sigma_mm")) if result["accuracy_source"] == "stated" else 0.0
    else:  # a result written before the accuracy had its own field
        stated = _number(result.get("noise_sigma_mm")) if result.get("noise_source") == "prior" else 0.0
    stated = stated if stated > 0 else 0.0
    s = stated or DEFAULT_TOUCH_SIGMA_MM
    source = "stated" if stated else "default"
    what = (f"the stated touch accuracy {s:g} mm" if stated
            else f"the default touch accuracy {s:g} mm (state yours with "
                 f"{term('sigma', 'sigma')})")

    for name, size in _lengths(result):
        if not size <= CELL_EXTENT_MM:
            poor.append(f"{name} of {size:.3g} mm is beyond any real cell "
                        f"({CELL_EXTENT_MM / 1e3:.0f} m): a unit or typing error in the measurements")
    x2, bound = _chi2_checks(result, ssr, n, dof, s, what, poor, check)
    _geometry_checks(result, cond, poor, check)
    _touch_checks(result, excluded, dof, poor, check)
    needed = touches_for_outlier_check(n, dof) if n else None
    if needed is not None:
        check.append(_too_few(n, left_out, dof, needed))
    if poor:
        level, reasons = "poor", poor + check
    elif check:
        level, reasons = "check", check
    else:
        level = "good"
        rms = math.sqrt(ssr / n) if n else 0.0
        reasons = [f"RMS {rms:.3f} mm within {what}, condition number "
                   + f"{format_condition(cond)}, no warnings"]
    reasons += _assumed_parts(result)
    return Verdict(level=level, reasons=reasons, condition=cond, touch_sigma_mm=s,
                   accuracy_source=source, chi2=x2, chi2_bound=bound, touches_needed=needed)


#: An assumed part of a 1-sigma below this share of its own part is left out of the reasons.
NEGLIGIBLE = 0.01


def _assumed_parts(result: Mapping[str, Any]) -> list[str]:
    """A reason per quantity whose 1-sigma holds an assumed part (``sigma_parts``: a pose's
    position, else its rotation; a value's ``sigma`` in its ``unit``), with the part its own
    touches determine: an assumed figure must not read as a measured one. A part under 1 % of
    what the own touches determine (a scalar the assumed input barely moves) is no reason."""
    out = []
    parts = result.get("sigma_parts")
    for key, p in (parts.items() if isinstance(parts, Mapping) else ()):
        try:
            field_, unit = next((f, u) for f, u in (("position_mm", " mm"), ("rotation_deg", " deg"),
                                                    ("sigma", f" {p.get('unit') or ''}".rstrip()))
                                if f in p["assumed"])
            assumed = float(np.nanmax(_floats(p["assumed"][field_])))
            own = float(np.nanmax(_floats(p["own"][field_])))
            names = ", ".join(str(n) for n in p["assumed"]["sources"])
        except (KeyError, TypeError, ValueError, StopIteration, AttributeError):
            continue
        if not assumed > NEGLIGIBLE * own:
            continue
        out.append(f"{key}: up to {assumed:.3g}{unit} of its 1-sigma is ASSUMED ({names}: no "
                   f"recorded uncertainty); its own touches determine it to {own:.3g}{unit} "
                   "relative to what touched")
    return out


def _chi2_checks(result: Mapping[str, Any], ssr: float, n: int, dof: int, s: float, what: str,
                 poor: list[str], check: list[str]) -> tuple[float | None, float | None]:
    """The residuals against the touch accuracy ``s`` (mm; ``what`` names it): a chi-square
    beyond its bound is ``check``, beyond the bound for :data:`POOR_FACTOR` times the accuracy
    ``poor``. Returns the chi-square and its bound (None without redundancy)."""
    x2 = bound = None
    if dof > 0:
        x2 = _number(result.get("chi2"), ssr / s**2)
        if not math.isfinite(ssr):
            x2 = float("inf")
        bound = float(chdtri(dof, 1.0 - CHI2_P))
        rms = math.sqrt(ssr / n) if n else 0.0
        if x2 > bound * POOR_FACTOR**2:
            poor.append(f"RMS {rms:.3f} mm is far beyond {what}: the residuals need a noise of "
                        f"{s * math.sqrt(x2 / dof):.3f} mm per coordinate (chi-square "
                        f"{x2:.3g} > {bound * POOR_FACTOR ** 2:.3g}, the {CHI2_P:.1%} bound "
                        f"for {POOR_FACTOR:g} times the accuracy); look for a wrong row or unit")
        elif x2 > bound:
            check.append(f"RMS {rms:.3f} mm is larger than {what} explains (chi-square "
                         f"{x2:.3g} > {bound:.3g}, the {CHI2_P:.1%} bound for {dof} redundant "
                         "coordinates)")
    return x2, bound


def _geometry_checks(result: Mapping[str, Any], cond: float, poor: list[str],
                     check: list[str]) -> None:
    """A track scale far from 1 and the condition number, into ``poor`` and ``check``."""
    scale = result.get("scale")
    if isinstance(scale, (int, float)):
        if not abs(scale - 1.0) <= SCALE_POOR:
            poor.append(f"track scale {scale:.4f} is more than {SCALE_POOR:.0%} from 1: no real "
                        "track has that gear ratio error; check the e1 column (mm) and that every "
                        "touch is of the same point")
        elif abs(scale - 1.0) > SCALE_CHECK:
            check.append(f"track scale {scale:.4f} is more than {SCALE_CHECK:.0%} from 1")
    if not cond <= CONDITION_POOR and not math.isnan(cond):
        poor.append(f"condition number {format_condition(cond)} > {CONDITION_POOR:.0f}: the "
                    "touches barely determine the result")
    elif cond > CONDITION_GOOD:
        check.append(f"condition number {format_condition(cond)} > {CONDITION_GOOD:.0f}: "
                     "spread the touches")


def _touch_checks(result: Mapping[str, Any], excluded: list[str], dof: int, poor: list[str],
                  check: list[str]) -> None:
    """The touches the result flags (outliers, disagreeing, gross, left out, unchecked) and its
    warnings, into ``poor`` and ``check``."""
    warnings = result.get("warnings") or []
    warnings = list(warnings) if isinstance(warnings, list) else [str(warnings)]
    about_outliers = sum("outlier" in str(w) for w in warnings)
    flagged = _names(result.get("outliers"))
    if "outliers" in result:
        outliers = len(set(flagged) | set(excluded))
    else:  # a result written before the outliers had their own field
        outliers = about_outliers
    disagreeing = _names(result.get("disagreeing"))
    gross = [g for g in _names(result.get("gross_outliers")) if g not in excluded]
    if set(gross) & set(disagreeing):
        poor.append(f"touches {', '.join(disagreeing)} disagree by far more than the touch "
                    "accuracy: one of them is wrong, and the other touches cannot tell which; "
                    "re-touch them")
    elif disagreeing:
        check.append(f"touches {', '.join(disagreeing)} disagree at 3 sigma: one of them may be "
                     "wrong; re-touch them")
    gross = [g for g in gross if g not in disagreeing]
    if gross:
        poor.append(f"touch(es) {', '.join(gross)} lie beyond 3 sigma even for {POOR_FACTOR:g} "
                    "times the touch accuracy, and the result cannot be computed without them: "
                    "re-touch them")
    if excluded:
        check.append(f"touch(es) {', '.join(excluded)} left out as outlier(s): re-touch them")
    if outliers - len(excluded) > 0:
        check.append(f"{outliers - len(excluded)} touch(es) flagged as outlier: re-touch them")
    if len(warnings) > about_outliers:
        check.append(f"{len(warnings) - about_outliers} warning(s), listed below")
    unchecked = _names(result.get("unchecked"))
    if unchecked and dof > 0:
        check.append(f"touch(es) {', '.join(unchecked)} decide part of the result alone (no other "
                     "touch checks them, so an error there goes unseen): repeat them")
