"""Which constants an identification frees: never a model that predicts held-out rows worse.

With few measured configurations, or an arm whose errors the geometric model cannot all
explain (elasticity, gear errors), freeing every identifiable constant fits the noise and the
unexplained error: the identified model then predicts configurations it has not seen worse than
the model it started from. :func:`identify_validated` checks this by K-fold cross-validation
(:func:`~robotcell.identification.validation.cross_validate`: every row predicted by models
fitted without it) and writes:

1. the identification with every identifiable constant free, when its held-out RMS is not above
   that of the start model (the nominal or geometric start, its base and targets fitted on the
   same rows);
2. else the best of: a reduced set, the ``m`` constants the full fit found most significant
   (``|change| / sigma``, for ``m`` an eighth, a quarter, a half and three quarters of them),
   each cross-validated on the same folds; the full set; and the start model itself (every link
   constant held). The chosen one has the lowest held-out RMS, so it is never worse than the
   start. The constants it holds are named with the reason (:data:`CV_HELD`).

Cost: ``K + 1`` fits when the full set wins, up to ``5 (K + 1)`` otherwise; a fit of 36 rows
takes about 0.05 s, one of 300 rows with one reflector about 0.2 s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robotcell.errors import IllPosedError, InputError
from robotcell.identification.engine import identify
from robotcell.identification.measurements import TargetMeasurements
from robotcell.identification.result import CV_HELD, IdentificationResult, Parameter
from robotcell.identification.validation import CrossValidation, cross_validate
from robotcell.robot.robot import Robot

__all__ = ["DEFAULT_FOLDS", "Candidate", "ValidatedIdentification", "identify_validated"]

#: Folds of the cross-validation when none is given.
DEFAULT_FOLDS = 5
#: Fractions of the free constants (the most significant first) tried as reduced sets.
LADDER = (1 / 8, 1 / 4, 1 / 2, 3 / 4)


@dataclass(frozen=True)
class Candidate:
    """One set of free constants and how well it predicts held-out rows.

    Attributes
    ----------
    label : str
        ``start``, ``identified`` (every identifiable constant free) or ``reduced``.
    free : int
        Constants freed beyond the base and targets.
    rms : float
        RMS of the held-out position errors (m).
    """

    label: str
    free: int
    rms: float


@dataclass(frozen=True)
class ValidatedIdentification:
    """The identification to write, with its cross-validation and the sets compared.

    Attributes
    ----------
    result : IdentificationResult
        The chosen identification.
    cross : CrossValidation
        Held-out errors of the start model (``before``) and of ``result`` (``after``).
    candidates : tuple of Candidate
        Every set cross-validated, in the order tried.
    chosen : Candidate
        The one written.
    """

    result: IdentificationResult
    cross: CrossValidation
    candidates: tuple[Candidate, ...]
    chosen: Candidate

    def sentence(self) -> str:
        """Which set was chosen (the model a file receives) and why, in mm (for reports)."""
        c, k = self.chosen, self.cross.folds
        start = next(x for x in self.candidates if x.label == "start").rms * 1e3
        full = next(x for x in self.candidates if x.label == "identified")
        if c.label == "identified":
            return (f"chosen: every identifiable constant free ({c.free}); held-out RMS "
                    f"{c.rms * 1e3:.4f} mm against {start:.4f} mm for the start model "
                    f"({k}-fold cross-validation)")
        what = ("the start model (no link constant moved)" if c.label == "start"
                else f"the {c.free} most significant of {full.free} constants free")
        return (f"chosen: {what}, by {k}-fold cross-validation: held-out RMS "
                f"{c.rms * 1e3:.4f} mm, against {full.rms * 1e3:.4f} mm with every constant "
                f"free and {start:.4f} mm for the start model")


def _rms(e: np.ndarray) -> float:
    return float(math.sqrt(np.mean(e**2)))


def _significance(p: Parameter) -> float:
    """``|change| / sigma`` of a free constant (scales and compliances start at 0)."""
    change = p.value - (p.nominal if math.isfinite(p.nominal) else 0.0)
    return abs(change) / p.sigma if p.sigma > 0 else math.inf


def _link_free(result: IdentificationResult) -> list[str]:
    """The free constants of ``result`` other than the base and targets, most significant first."""
    free = [p for p in result.parameters if p.free and not p.name.startswith(("base.", "target"))]
    return [p.name for p in sorted(free, key=lambda p: -_significance(p))]


def _holding(result: IdentificationResult, keep: list[str], why: str) -> dict[str, str]:
    """Every constant of ``result`` but the base, the targets and ``keep``, held: those it freed
    with ``why``, the others with the reason it gave (a fold's fit must not free them either)."""
    given = dict(result.fixed)
    return {p.name: why if p.free else given.get(p.name, why) for p in result.parameters
            if not p.name.startswith(("base.", "target")) and p.name not in keep}


def _validate(nominal: Robot, meas: TargetMeasurements, folds: int, seed: int, options: dict
              ) -> CrossValidation:
    try:
        return cross_validate(nominal, meas, folds=folds, seed=seed, **options)
    except IllPosedError as exc:
        raise IllPosedError(
            f"the {folds}-fold cross-validation fits {meas.n_rows - -(-meas.n_rows // folds)} "
            f"rows at a time, and: {exc} (give fewer folds, or folds=0 to write the "
            "identification without it)") from None


def identify_validated(nominal: Robot, measurements: TargetMeasurements, *, folds: int = DEFAULT_FOLDS,
                       seed: int = 0, **options) -> ValidatedIdentification:
    """Identify, and free only the constants that predict held-out rows better (see the module).

    Parameters
    ----------
    nominal : Robot
        Start model, as for :func:`~robotcell.identification.identify`.
    measurements : TargetMeasurements
    folds : int
        K of the K-fold cross-validation, from 2 to the number of rows.
    seed : int
        Seed of the rows' shuffle into folds (``np.random.default_rng``).
    **options
        Passed to :func:`~robotcell.identification.identify` (accuracies, ``scale``,
        ``coupling``, ``group_tol``, ...).

    Returns
    -------
    ValidatedIdentification

    Raises
    ------
    InputError
        Folds outside 2 .. rows, or what :func:`~robotcell.identification.identify` refuses.
    IllPosedError
        Too few rows for the identification, or for the fits of the cross-validation.
    """
    if "hold" in options:
        raise InputError("identify_validated chooses what to hold; do not pass hold")
    full = identify(nominal, measurements, **options)
    cv = _validate(nominal, measurements, folds, seed, options)
    ranked = _link_free(full)
    start = Candidate("start", 0, _rms(cv.before))
    best = Candidate("identified", len(ranked), _rms(cv.after))
    candidates = [start, best]
    if best.rms <= start.rms or not ranked:
        return ValidatedIdentification(full, cv, tuple(candidates), best)
    cross = cv
    for m in sorted({max(1, round(len(ranked) * f)) for f in LADDER} - {len(ranked)}):
        hold = _holding(full, ranked[:m], "")
        cv_m = _validate(nominal, measurements, folds, seed, {**options, "hold": hold})
        cand = Candidate("reduced", m, _rms(cv_m.after))
        candidates.append(cand)
        if cand.rms < best.rms:
            best, cross = cand, cv_m
    if start.rms <= best.rms:
        best, cross = start, CrossValidation(folds, cv.before, cv.before, cv.fold)
    if best.label == "identified":
        return ValidatedIdentification(full, cv, tuple(candidates), best)
    why = (f"{CV_HELD}: the model with it free predicts held-out rows worse ({folds}-fold: "
           f"held-out RMS {best.rms * 1e3:.4f} mm without it, {_rms(cv.after) * 1e3:.4f} mm "
           "with every constant free)")
    result = identify(nominal, measurements, hold=_holding(full, ranked[:best.free], why),
                      **options)
    return ValidatedIdentification(result, cross, tuple(candidates), best)
