"""The result every calibration procedure returns: estimate, uncertainty, residuals, advice.

Everything inside :class:`CalibrationResult` is in SI units (metres, radians). Millimetres and
degrees appear only in :meth:`CalibrationResult.to_json` (keys ending in ``_mm`` / ``_deg``, plus
the vendor fields a procedure adds) and in :meth:`CalibrationResult.summary`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.calibration.fitting import Fit
from robotcell.calibration.resultcheck import REQUIRED, TOUCH_LISTS, malformed
from robotcell.calibration.sigmaparts import (
    DECIMALS,
    PARTS,
    part_lines,
    pose_parts,
    sigma_basis,
    value_parts,
)
from robotcell.calibration.sigmaparts import numbers as _fmt
from robotcell.calibration.uncertainty import OWN, Estimate, Sources
from robotcell.calibration.verdict import (
    CONDITION_GOOD,
    CONDITION_POOR,
    Verdict,
    format_condition,
)
from robotcell.calibration.verdict import verdict as judge
from robotcell.errors import InputError, term
from robotcell.io.poseformats import pose_to_vendor
from robotcell.io.tables import format_table

__all__ = ["CalibrationResult", "fit_fields", "pose_covariance", "pose_fields",
           "result_json", "to_jsonable"]

#: A key of a result's pose ``T_a_b`` in its JSON (its sigma or covariance), giving ``T_a_b``.
_POSE_KEY = re.compile(r"(T_[A-Za-z]+_[A-Za-z0-9]+?)_(?:position_mm|rotation_deg|covariance_mm_rad)")

#: The JSON's lists of touches (labels) and the fields of a result that hold their indices.
_TOUCH_LISTS = dict(zip(TOUCH_LISTS, ("excluded", "unchecked", "outliers", "disagreeing", "gross"),
                        strict=True))

#: Conditioning figure above which a result is flagged: Schroer's threshold of about 100 for
#: a trustworthy identification, as cited by Nahvi and Hollerbach (ICRA 1996).
CONDITION_LIMIT = CONDITION_GOOD


def to_jsonable(value: Any) -> Any:
    """Convert numpy values (recursively) to plain Python for :func:`json.dumps`.

    Parameters
    ----------
    value : Any
        Scalar, array, list, tuple or dict. NaN and infinity become None (JSON null).

    Returns
    -------
    Any
        Lists, dicts, floats, ints, strings, booleans and None only.
    """
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else None
    return value


def pose_fields(T: NDArray[np.float64]) -> dict[str, Any]:
    """Vendor fields of a pose for JSON: ``matrix`` (4x4, translation in mm) and ``xyzabc`` (KUKA).

    Parameters
    ----------
    T : ndarray, shape (4, 4)
        Pose (metres).

    Returns
    -------
    dict
        ``{"matrix": 4x4 nested list, translation in mm, "xyzabc": [X, Y, Z, A, B, C] mm/deg}``.
    """
    M = np.array(T, dtype=float)
    M[:3, 3] *= 1000.0
    return {"matrix": M.tolist(), "xyzabc": pose_to_vendor(T, "kuka").tolist()}


#: Scale from SI and unit of a value in the JSON and the terminal, by its kind.
_UNITS = {"length": (1e3, "mm"), "angle": (180 / math.pi, "deg"), "number": (1.0, "")}


@dataclass
class CalibrationResult:
    """Outcome of one calibration procedure.

    Attributes
    ----------
    procedure : str
        Procedure name, e.g. ``"tcp"``, ``"frame-3point"``, ``"turntable"``.
    values : dict of str to Any
        Estimated quantities in SI units: poses as ``(4, 4)`` arrays (metres), points as ``(3,)``
        arrays (metres), lengths as floats (metres), angles (radians), unitless numbers.
    sigma : dict of str to Any
        1-sigma uncertainty of the estimated quantities, SI. For a pose ``values[key]``
        (= ``T_a_b``) it holds ``key + "_position"``: shape (3,), metres, standard deviation of
        the origin of b along the axes of a; and ``key + "_rotation"``: shape (3,), radians,
        standard deviation of the small rotation vector ``d`` with
        ``R_true = exp([d]x) R_estimated``, i.e. rotation about the axes of frame a. For any other
        quantity ``sigma[key]`` has the shape of ``values[key]``. A quantity fixed by the
        procedure (not estimated) has no sigma. NaN when no noise level is available.
    residuals : ndarray, shape (N, 3)
        Per measurement: measured point minus the point the fitted model predicts (metres, robot
        base axes unless the procedure says otherwise).
    condition : float
        Conditioning figure: the 2-norm condition number of the Jacobian of the maximum-likelihood
        problem after scaling each column to unit length (see :func:`robotcell.calibration.fit`).
        Below about 100 the measurement design is good; large values mean some combination of the
        estimated quantities is poorly determined by where the touches were taken.
    dof : int
        Redundancy: number of scalar measurements minus number of estimated parameters.
    noise_sigma : float
        Touch noise (metres, per coordinate) behind ``sigma``: the stated touch accuracy
        (``noise_source == "prior"``), the default (``"default"``), or, when the residuals are
        larger than the accuracy explains (chi-square test), the noise they need
        (``"residuals"``). Never less than the accuracy.
    noise_source : {"prior", "default", "residuals"}
    labels : list of str
        Name of each measurement for reports (e.g. ``"row 3 (xy)"``); length N.
    undetermined : list of str
        Quantities the measurements do not determine (and which the result therefore omits or
        fixes by a stated convention).
    warnings : list of str
    next_step : str
        What the technician should do next.
    kinds : dict of str to str
        How :meth:`summary` prints a value: ``"pose"``, ``"length"`` (m, printed in mm),
        ``"angle"`` (rad, printed in deg) or ``"number"``. Missing keys: ``"pose"`` for 4x4 arrays,
        else ``"length"``.
    json_fields : dict of str to Any
        Procedure-specific fields merged into :meth:`to_json` (vendor units, e.g. ``tcp_mm``,
        ``matrix``, ``xyzabc``).
    covariance : ndarray, shape (p, p) or None
        Covariance of the fitted parameter vector (SI) for propagation, with names in
        ``parameter_names``.
    parameter_names : list of str
    points : ndarray, shape (N, 3) or None
        The measured points behind ``residuals`` (metres, same axes), for reports; None when the
        procedure has no single point per measurement.
    touch_sigma : float
        The touch accuracy the residuals are tested against (metres per coordinate): stated, or
        the default.
    accuracy_source : {"stated", "default"}
    residual_sigma : float
        Noise estimated from the residuals (metres per coordinate), a check against
        ``touch_sigma``; NaN without redundancy.
    chi2 : float or None
        Residuals against the touch accuracy and the inputs' errors; chi-square with ``dof``
        degrees of freedom for good touches. None without redundancy.
    excluded : list of int
        Touches left out of the result (a gross error singled out by the others).
    unchecked : list of int
        Touches that no other touch checks in some direction they decide.
    outliers : list of int
        Touches used by the result whose residual is an outlier at 3 sigma.
    disagreeing : list of int
        Touches that disagree beyond 3 sigma, one of them wrong, with nothing to tell which.
    gross : list of int
        Outliers beyond 3 sigma even for three times the touch accuracy.
    estimates : dict of str to Estimate
        For the calibrated quantities a later calibration can use (a tool, an axis, a frame):
        their error sources and how they follow the inputs of this calibration.
    fit : Fit or None
        The least-squares fit behind the result (its linearisation, for a fit of several
        calibrations together).
    value_sources : dict of str to Sources
        Error sources of the values that are not poses (a scale, a radius, an axis; the
        elements of ``values[key]`` flattened, SI), for the split of their 1-sigma into own,
        recorded and assumed parts (:mod:`robotcell.calibration.sigmaparts`).
    frames : dict of str to str
        The frame a value that is not a pose is expressed in, which its 1-sigma is relative to
        (e.g. ``{"tcp": "F", "pivot": "R"}``); by default the frame ``a`` of the result's first
        pose ``T_a_b`` (see :meth:`relative_to`).
    """

    procedure: str
    values: dict[str, Any]
    sigma: dict[str, Any]
    residuals: NDArray[np.float64]
    condition: float
    dof: int
    noise_sigma: float
    noise_source: str
    labels: list[str] = field(default_factory=list)
    undetermined: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    next_step: str = ""
    kinds: dict[str, str] = field(default_factory=dict)
    json_fields: dict[str, Any] = field(default_factory=dict)
    covariance: NDArray[np.float64] | None = None
    parameter_names: list[str] = field(default_factory=list)
    points: NDArray[np.float64] | None = None
    touch_sigma: float = float("nan")
    accuracy_source: str = "default"
    residual_sigma: float = float("nan")
    chi2: float | None = None
    excluded: list[int] = field(default_factory=list)
    unchecked: list[int] = field(default_factory=list)
    outliers: list[int] = field(default_factory=list)
    disagreeing: list[int] = field(default_factory=list)
    gross: list[int] = field(default_factory=list)
    estimates: dict[str, Estimate] = field(default_factory=dict)
    fit: Fit | None = None
    value_sources: dict[str, Sources] = field(default_factory=dict)
    frames: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.residuals = np.asarray(self.residuals, dtype=float).reshape(-1, 3)
        if not self.labels:
            self.labels = [f"{i + 1}" for i in range(len(self.residuals))]

    @property
    def residual_norms(self) -> NDArray[np.float64]:
        """Length of each residual, shape (N,), metres."""
        return np.linalg.norm(self.residuals, axis=1)

    @property
    def used_norms(self) -> NDArray[np.float64]:
        """Residual lengths of the touches the result uses (not those left out), metres."""
        keep = np.ones(len(self.residuals), dtype=bool)
        keep[self.excluded] = False
        return self.residual_norms[keep]

    @property
    def rms(self) -> float:
        """Root mean square of the residual lengths of the touches used (metres)."""
        n = self.used_norms
        return float(np.sqrt(np.mean(n**2))) if n.size else 0.0

    @property
    def max(self) -> float:
        """Largest residual length of the touches used (metres)."""
        n = self.used_norms
        return float(n.max()) if n.size else 0.0

    def renamed(self, old_key: str, new_key: str) -> CalibrationResult:
        """The same result with one estimated quantity under another name.

        Used when the touches were expressed in another frame than the procedure's names say,
        e.g. ``T_R_B`` -> ``T_world_B`` for a turntable calibrated from touches mapped to the
        world. The value itself is not changed.

        Parameters
        ----------
        old_key : str
            Key of ``values`` to rename.
        new_key : str
            Its new name; must not be another key of ``values``.

        Returns
        -------
        CalibrationResult
            A new result (arrays shared with this one) in which ``values[old_key]`` becomes
            ``values[new_key]`` at the same place, its sigma keys follow (``old_key``,
            ``old_key + "_position"``, ``old_key + "_rotation"``), ``kinds[old_key]`` too, and
            every ``json_fields`` key starting with ``old_key + "_"`` (e.g.
            ``T_R_B_covariance_mm_rad``). Other JSON fields, ``matrix`` and ``xyzabc`` among
            them, are kept. Mentions of ``old_key`` as a whole word in ``next_step``,
            ``warnings`` and ``undetermined`` are renamed as well.

        Raises
        ------
        InputError
            ``old_key`` is not a value of the result, or ``new_key`` already is.
        """
        if old_key not in self.values:
            raise InputError(f"the {self.procedure} result has no value {old_key!r} to rename "
                             f"(it has: {', '.join(self.values)})")
        if new_key != old_key and new_key in self.values:
            raise InputError(f"the {self.procedure} result already has a value {new_key!r}")

        def swap(d: dict[str, Any], names: dict[str, str]) -> dict[str, Any]:
            return {names.get(k, k): v for k, v in d.items()}

        word = re.compile(rf"\b{re.escape(old_key)}\b")

        def text(t: str) -> str:
            return word.sub(new_key, t)

        sigma_names = {old_key + s: new_key + s for s in ("", "_position", "_rotation")}
        json_names = {k: new_key + k[len(old_key):] for k in self.json_fields
                      if k.startswith(old_key + "_")}
        return replace(self, values=swap(self.values, {old_key: new_key}),
                       estimates=swap(self.estimates, {old_key: new_key}),
                       value_sources=swap(self.value_sources, {old_key: new_key}),
                       frames=swap(self.frames, {old_key: new_key}),
                       sigma=swap(self.sigma, sigma_names),
                       kinds=swap(self.kinds, {old_key: new_key}),
                       json_fields=swap(self.json_fields, json_names),
                       next_step=text(self.next_step),
                       warnings=[text(w) for w in self.warnings],
                       undetermined=[text(u) for u in self.undetermined])

    def _kind(self, key: str) -> str:
        if key in self.kinds:
            return self.kinds[key]
        v = np.asarray(self.values[key])
        return "pose" if v.shape == (4, 4) else "length"

    def _sigma_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key in self.values:
            kind = self._kind(key)
            if kind == "pose":
                if key + "_position" in self.sigma:
                    out[key + "_position_mm"] = np.asarray(self.sigma[key + "_position"]) * 1e3
                if key + "_rotation" in self.sigma:
                    out[key + "_rotation_deg"] = np.degrees(self.sigma[key + "_rotation"])
            elif key in self.sigma:
                s = np.asarray(self.sigma[key], dtype=float)
                if kind == "length":
                    out[key + "_mm"] = s * 1e3
                elif kind == "angle":
                    out[key + "_deg"] = np.degrees(s)
                else:
                    out[key] = s
        return out

    def relative_to(self, key: str) -> str:
        """The frame the 1-sigma of value ``key`` is relative to: ``a`` of a pose ``T_a_b``; for
        another value its entry of :attr:`frames`, else the frame of the result's first pose
        (the robot base ``"R"`` without one)."""
        if self._kind(key) == "pose":
            return key.split("_")[1]
        if key in self.frames:
            return self.frames[key]
        pose = next((k for k in self.values if self._kind(k) == "pose"), None)
        return "R" if pose is None else pose.split("_")[1]

    def _has_sigma(self, key: str) -> bool:
        """Whether value ``key`` has a 1-sigma (a pose: of its position or rotation)."""
        if self._kind(key) == "pose":
            return key + "_position" in self.sigma or key + "_rotation" in self.sigma
        return key in self.sigma

    def _parts_of(self, key: str) -> dict[str, Any] | None:
        """The parts of the 1-sigma of value ``key`` (JSON units), or None when not known: from
        its error sources, or all its own when the fit inherits nothing."""
        kind = self._kind(key)
        est = self.estimates.get(key)
        own_only = self.fit is not None and set(self.fit.sources.factors) <= {OWN}
        if kind == "pose":
            if est is not None and est.sources.size >= 6:
                parts: dict[str, Any] = pose_parts(est.sources)
            elif own_only:
                sp = self.sigma.get(key + "_position", np.full(3, np.nan))
                sr = self.sigma.get(key + "_rotation", np.full(3, np.nan))
                parts = {"own": {"position_mm": np.asarray(sp) * 1e3,
                                 "rotation_deg": np.degrees(sr), "sources": []}}
            else:
                return None
            if key + "_position" not in self.sigma:  # not determined: no figure to split
                parts = {k: {n: v for n, v in p.items() if n != "position_mm"}
                         for k, p in parts.items()}
            return parts
        scale, unit = _UNITS[kind]
        src = self.value_sources.get(key)
        if src is not None:
            split = value_parts(src)
        elif own_only:
            split = {"own": {"sigma": np.ravel(self.sigma[key]), "sources": []}}
        else:
            return None
        one = np.ndim(self.values[key]) == 0
        return {"unit": unit, **{k: {"sigma": float(p["sigma"][0]) * scale if one
                                     else p["sigma"] * scale, "sources": p["sources"]}
                                 for k, p in split.items()}}

    def _sigma_parts(self) -> dict[str, Any]:
        """The 1-sigma of each value split into its parts (:mod:`robotcell.calibration.sigmaparts`),
        with the frame it is relative to; values whose split is not known are left out."""
        out: dict[str, Any] = {}
        for key in self.values:
            if self._has_sigma(key) and (parts := self._parts_of(key)) is not None:
                out[key] = {"relative_to": self.relative_to(key), **parts}
        return out

    def _basis(self, key: str, parts: dict[str, Any]) -> tuple[str, list[str]]:
        """What the 1-sigma of ``key`` is relative to and made of (:func:`sigma_basis`), and the
        lines of its parts when it inherits any (``parts``: :meth:`_sigma_parts`)."""
        mine = parts.get(key)
        present = [] if mine is None else [p for p in PARTS if p in mine]
        detail = part_lines(mine) if mine is not None and set(present) - {"own"} else []
        return sigma_basis(self.relative_to(key), present), detail

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict in vendor units (mm, deg).

        Returns
        -------
        dict
            ``procedure``, ``residuals_mm`` (length of each residual), ``residuals_xyz_mm``
            (N x 3), ``labels``, ``rms_mm``, ``max_mm``, ``condition``, ``dof``,
            ``noise_sigma_mm`` and ``noise_source`` (the noise behind the 1-sigma),
            ``touch_sigma_mm`` and ``accuracy_source`` (the accuracy the residuals are tested
            against), ``residual_sigma_mm`` (the residuals' estimate) and ``chi2``, the touches
            ``excluded``, ``unchecked``, ``outliers`` and ``gross_outliers`` (labels), ``sigma`` (1-sigma of each estimated
            quantity, keys with units), ``sigma_relative_to`` (per quantity with a 1-sigma, the
            frame it is relative to: ``F`` the flange, ``R`` the robot base, ``L`` the track
            frame, ``B`` the turntable frame, ``world``, or a frame's name), ``sigma_parts`` (per
            quantity whose split is known: that frame, and the parts ``own``, ``recorded`` and
            ``assumed`` of its 1-sigma, see :mod:`robotcell.calibration.sigmaparts`), ``undetermined``,
            ``warnings``, ``next_step``,
            ``points_mm`` (N x 3, when the procedure records its measured points), then the
            procedure's own fields (``json_fields``), and ``verdict`` (level, reasons, the
            condition number and the chi-square figures it used; see :attr:`verdict`).
        """
        out: dict[str, Any] = {
            "procedure": self.procedure,
            "residuals_mm": self.residual_norms * 1e3,
            "residuals_xyz_mm": self.residuals * 1e3,
            "labels": list(self.labels),
            "rms_mm": self.rms * 1e3,
            "max_mm": self.max * 1e3,
            "condition": self.condition,
            "dof": self.dof,
            "noise_sigma_mm": self.noise_sigma * 1e3,
            "noise_source": self.noise_source,
            "touch_sigma_mm": self.touch_sigma * 1e3,
            "accuracy_source": self.accuracy_source,
            "residual_sigma_mm": self.residual_sigma * 1e3,
            "chi2": self.chi2,
            "excluded": [self.labels[i] for i in self.excluded],
            "unchecked": [self.labels[i] for i in self.unchecked],
            "outliers": [self.labels[i] for i in self.outliers],
            "disagreeing": [self.labels[i] for i in self.disagreeing],
            "gross_outliers": [self.labels[i] for i in self.gross],
            "sigma": self._sigma_json(),
            "sigma_relative_to": {k: self.relative_to(k) for k in self.values if self._has_sigma(k)},
            "sigma_parts": self._sigma_parts(),
            "undetermined": list(self.undetermined),
            "warnings": list(self.warnings),
            "next_step": self.next_step,
        }
        if self.points is not None:
            out["points_mm"] = np.asarray(self.points, dtype=float).reshape(-1, 3) * 1e3
        out.update(self.json_fields)
        out = to_jsonable(out)
        out["verdict"] = judge(out).to_json()
        return out

    @classmethod
    def from_json(cls, data: Any, source: str = "the result", procedure: str | None = None,
                  required: tuple[str, ...] = REQUIRED) -> CalibrationResult:
        """A result from its JSON (:meth:`to_json`, mm and deg), checked; ``to_json`` of it
        gives that JSON back.

        The quantities come back in SI: the residuals and the measured points, the noise and
        accuracy figures, the touches named in ``excluded`` and the other lists, the 1-sigma
        (``sigma``, keys without their unit), and the result's pose ``T_a_b`` (``matrix``, the
        pose its sigma or covariance names) in ``values`` with its 6x6 covariance
        ``T_a_b_covariance_mm_rad`` as ``covariance`` (origin in m, rotation vector in rad).
        Every field read is kept in ``json_fields`` as it was, so that :meth:`to_json` writes
        what was read (its verdict judged again). A file is read by
        :func:`robotcell.report.load_result` or :meth:`TurntablePose.load
        <robotcell.cell.calibrate.TurntablePose.load>`.

        Parameters
        ----------
        data : dict
            The result as JSON.
        source : str
            Its name in messages (the file).
        procedure : str, optional
            The procedure the result must come from (e.g. ``"turntable"``).
        required : tuple of str
            The fields it must have: by default those of every result
            (:data:`~robotcell.calibration.resultcheck.REQUIRED`); a reader that uses only its
            pose asks for ``("procedure", "matrix")``.

        Returns
        -------
        CalibrationResult

        Raises
        ------
        InputError
            Not a result of ``procedure``, a field missing or malformed
            (:func:`~robotcell.calibration.resultcheck.malformed`), or a covariance that is not
            a 6x6 symmetric positive semi-definite matrix of finite numbers.
        """
        given = result_json()
        if procedure is not None and (not isinstance(data, dict)
                                      or data.get("procedure") != procedure):
            raise InputError(f"{source}: not a {procedure} result; pass the {given}")
        missing = [k for k in required if not isinstance(data, dict) or k not in data]
        if missing:
            raise InputError(f"{source}: not a calibration result (missing {', '.join(missing)}); "
                             f"give the {given}")
        bad = malformed(data)
        if bad:
            raise InputError(f"{source}: not a calibration result: {bad}; give the unchanged "
                             f"{given}")
        mm = np.array(data.get("residuals_xyz_mm") or
                      [[r, 0.0, 0.0] for r in data.get("residuals_mm", [])],
                      dtype=float).reshape(-1, 3)
        labels = [str(v) for v in data.get("labels") or range(1, len(mm) + 1)]

        def si(key: str, default: float = float("nan")) -> float:
            v = data.get(key)
            return default if v is None else float(v) * 1e-3

        def touches(key: str) -> list[int]:
            return [labels.index(str(v)) for v in data.get(key) or [] if str(v) in labels]

        sigma = _sigma_si(data.get("sigma") or {})
        values, covariance = _pose_si(data, source)
        points = data.get("points_mm")
        return cls(
            str(data["procedure"]), values, sigma, mm * 1e-3,
            condition=float(data["condition"]) if data.get("condition") is not None
            else float("nan"), dof=int(data.get("dof") or 0),
            noise_sigma=si("noise_sigma_mm"), noise_source=str(data.get("noise_source", "")),
            labels=labels, undetermined=list(data.get("undetermined") or []),
            warnings=list(data.get("warnings", [])), next_step=str(data.get("next_step", "")),
            kinds={k: "pose" for k in values},
            json_fields={k: v for k, v in data.items() if k != "verdict"},
            covariance=covariance, parameter_names=list(values),
            points=None if points is None else np.array(points, dtype=float) * 1e-3,
            touch_sigma=si("touch_sigma_mm"),
            accuracy_source=str(data.get("accuracy_source", "default")),
            residual_sigma=si("residual_sigma_mm"), chi2=data.get("chi2"),
            **{field_: touches(key) for key, field_ in _TOUCH_LISTS.items()})

    @property
    def verdict(self) -> Verdict:
        """The verdict (good / check / poor, and why): :func:`robotcell.calibration.verdict.verdict`
        on :meth:`to_json`, so the terminal, the JSON and the HTML report agree."""
        return judge(self.to_json())

    def _value_lines(self) -> list[str]:
        lines = []
        parts = self._sigma_parts()
        for key, v in self.values.items():
            kind = self._kind(key)
            basis, detail = self._basis(key, parts)
            if kind == "pose":
                xyzabc = pose_to_vendor(v, "kuka")
                lines.append(f"  {key} (KUKA X,Y,Z mm, A,B,C deg): {_fmt(xyzabc, 3)}")
                sp = self.sigma.get(key + "_position")
                sr = self.sigma.get(key + "_rotation")
                if sp is not None:
                    lines.append(f"    1-sigma position (mm):      {_fmt(np.asarray(sp) * 1e3, 3)}")
                if sr is not None:
                    lines.append(f"    1-sigma rotation (deg):     {_fmt(np.degrees(sr), 4)}")
                if self._has_sigma(key):
                    lines.append(f"    the 1-sigma above is {basis}"
                                 + (f"; {detail[0]}" if detail else ""))
                    lines += [f"      {d}" for d in detail[1:]]
                continue
            scale, unit = _UNITS[kind]
            dec = DECIMALS[unit]
            text = _fmt(np.asarray(v, dtype=float) * scale, dec)
            s = self.sigma.get(key)
            if s is not None:
                text += f"  (1-sigma {_fmt(np.asarray(s, dtype=float) * scale, dec)}, {basis})"
            lines.append(f"  {key}{unit and ' (' + unit + ')'}: {text}")
            if detail:
                lines.append(f"    {detail[0]}")
                lines += [f"      {d}" for d in detail[1:]]
        return lines

    def _noise_line(self) -> str:
        """The touch accuracy, the residuals' check against it and the noise the 1-sigma uses."""
        s = self.touch_sigma * 1e3
        given = term("sigma", "sigma")
        text = (f"{s:.3f} mm per coordinate, as given ({given})" if self.accuracy_source == "stated"
                else f"{s:.3f} mm per coordinate, the default (state yours with {given})")
        if self.chi2 is None or not math.isfinite(self.residual_sigma):
            return text + "; no redundant touches check it"
        text += (f"; the residuals need {self.residual_sigma * 1e3:.3f} mm (chi-square "
                 f"{self.chi2:.3g} for {self.dof} redundant coordinates)")
        if self.noise_source == "residuals":
            text += ": more than the accuracy explains, so the 1-sigma uses that"
        return text

    def summary(self) -> str:
        """Readable report for the terminal, in millimetres and degrees.

        Returns
        -------
        str
            The estimate with 1-sigma uncertainties, a table of residuals per measurement, RMS,
            max, conditioning, undetermined quantities, warnings, the next step and, last, the
            one-line verdict (``verdict: GOOD|CHECK|POOR: why``).
        """
        r = self.residuals * 1e3
        rows = [[lab, float(a), float(b), float(c), float(n)]
                for lab, (a, b, c), n in zip(self.labels, r, self.residual_norms * 1e3)]
        noise = self._noise_line()
        v = self.verdict
        lines = [f"calibration: {self.procedure}", "", "result:"]
        lines += self._value_lines()
        lines += ["", "residuals (measured - model, mm):",
                  format_table(["touch", "dx", "dy", "dz", "|r|"], rows), "",
                  (f"RMS {self.rms * 1e3:.3f} mm, max {self.max * 1e3:.3f} mm "
                   f"over {len(self.used_norms)} measurements, redundancy {self.dof}"),
                  f"touch accuracy: {noise}",
                  (f"condition number: {format_condition(v.condition)} (below "
                   f"{CONDITION_GOOD:.0f} is good, above {CONDITION_POOR:.0f} poor)")]
        if self.excluded:
            lines += ["", "left out of the result (outliers; see the warnings): "
                      + ", ".join(self.labels[i] for i in self.excluded)]
        if self.undetermined:
            lines += ["", "not determined by these measurements:"]
            lines += [f"  - {u}" for u in self.undetermined]
        if self.warnings:
            lines += ["", "warnings:"]
            lines += [f"  - {w}" for w in self.warnings]
        if self.next_step:
            lines += ["", f"next step: {self.next_step}"]
        lines += ["", v.line()]
        return "\n".join(lines)


def fit_fields(res: Fit) -> dict[str, Any]:
    """The fields of a :class:`CalibrationResult` that come from its fit, as keyword arguments.

    Parameters
    ----------
    res : Fit

    Returns
    -------
    dict
        ``residuals``, ``condition``, ``dof``, ``noise_sigma``, ``noise_source``,
        ``touch_sigma``, ``accuracy_source``, ``residual_sigma``, ``chi2``, ``excluded``,
        ``unchecked``, ``outliers``, ``disagreeing``, ``gross`` and ``fit``.
    """
    return {"residuals": res.residuals, "condition": res.condition, "dof": res.dof,
            "noise_sigma": res.noise_sigma, "noise_source": res.noise_source,
            "touch_sigma": res.touch_sigma, "accuracy_source": res.accuracy_source,
            "residual_sigma": res.residual_sigma, "chi2": res.chi2,
            "excluded": list(res.excluded), "unchecked": list(res.unchecked),
            "outliers": res.outliers, "disagreeing": res.disagreeing, "gross": list(res.gross),
            "fit": res}


def result_json() -> str:
    """What a result given as JSON must be, for messages: the output of :meth:`to_json
    <CalibrationResult.to_json>` (on the command line: of ``calibrate ... --json``)."""
    return term("result=json", "output of CalibrationResult.to_json()")


def pose_covariance(value: object, where: str) -> NDArray[np.float64]:
    """A pose's 6x6 covariance read from JSON: symmetric, positive semi-definite, finite.

    Parameters
    ----------
    value : object
        The JSON value (nested lists).
    where : str
        What it is, for messages (file and key).

    Returns
    -------
    ndarray, shape (6, 6)
        As given (units unchanged).

    Raises
    ------
    InputError
        Not a 6x6 array of finite numbers, or not a covariance.
    """
    advice = f"; pass the unchanged {result_json()}"
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


def _sigma_si(sigma_json: dict[str, Any]) -> dict[str, Any]:
    """The 1-sigma of a result as JSON in SI, keyed without their unit (``_mm``, ``_deg``)."""
    sigma: dict[str, Any] = {}
    for key, v in sigma_json.items():
        for unit, scale in (("_mm", 1e-3), ("_deg", math.pi / 180)):
            if key.endswith(unit):
                sigma[key[:-len(unit)]] = np.asarray(v, dtype=float) * scale
                break
        else:
            sigma[key] = np.asarray(v, dtype=float)
    return sigma


def _pose_si(data: dict[str, Any], source: str
             ) -> tuple[dict[str, Any], NDArray[np.float64] | None]:
    """The pose ``T_a_b`` of a result as JSON (``matrix``, the one pose its fields or sigma
    name) in SI, and its covariance ``T_a_b_covariance_mm_rad`` (origin in m, rotation vector in
    rad; None when not given)."""
    sigma_json = data.get("sigma") or {}
    values: dict[str, Any] = {}
    covariance = None
    poses = {m.group(1) for m in map(_POSE_KEY.fullmatch, [*data, *sigma_json]) if m}
    if data.get("matrix") is not None and len(poses) == 1:
        key = poses.pop()
        T = np.array(data["matrix"], dtype=float)
        T[:3, 3] *= 1e-3
        values[key] = T
        cov = data.get(f"{key}_covariance_mm_rad")
        if cov is not None:
            to_si = np.array([1e-3, 1e-3, 1e-3, 1.0, 1.0, 1.0])
            covariance = (pose_covariance(cov, f"{source}: '{key}_covariance_mm_rad'")
                          * np.outer(to_si, to_si))
    return values, covariance
