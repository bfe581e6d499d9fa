"""The covariance of a model's identified constants: how well an identification knows them.

An identified model (``robotcell identify``) carries the covariance of the constants it moved:
link constants named after their joint (``A2.a``, ``A2.alpha``, ``A2.d``, ``A2.theta``,
``A2.beta``), a scale error (``A2.scale``) and the J2/J3 factor (``j23_factor``), in SI units
(m, rad; scale and factor unitless). Propagated through the model's FK it gives the 1-sigma of a
TCP position (:func:`robotcell.identification.uncertainty.position_sigma`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError

__all__ = ["ParameterCovariance", "parameter_kind"]

_NAME = re.compile(r"^(?:(.+)\.(a|alpha|d|theta|beta|scale)|j23_factor)$")


def parameter_kind(name: str) -> str:
    """``length``, ``angle`` or ``number`` for a parameter name (``A2.d``, ``A3.beta``, ...).

    Raises
    ------
    InputError
        A name that is not ``<joint>.<a|alpha|d|theta|beta|scale>`` or ``j23_factor``.
    """
    m = _NAME.match(name)
    if m is None:
        raise InputError(f"parameter {name!r} is not <joint>.<a|alpha|d|theta|beta|scale> or "
                         "j23_factor")
    key = m.group(2)
    if key in ("a", "d"):
        return "length"
    if key in ("alpha", "theta", "beta"):
        return "angle"
    return "number"


@dataclass(frozen=True, eq=False)
class ParameterCovariance:
    """Covariance of named model constants.

    Attributes
    ----------
    names : tuple of str
        Parameter names (:func:`parameter_kind`), one per row.
    matrix : ndarray, shape (p, p)
        Symmetric covariance in SI units (m, rad, unitless).
    """

    names: tuple[str, ...]
    matrix: NDArray[np.float64]

    def __post_init__(self) -> None:
        names = tuple(str(n) for n in self.names)
        for n in names:
            parameter_kind(n)
        if len(set(names)) != len(names):
            raise InputError("covariance: a parameter is named twice")
        M = np.array(self.matrix, dtype=float)
        if M.shape != (len(names), len(names)):
            raise InputError(f"covariance: the matrix must be {len(names)} x {len(names)} (one row "
                             f"and column per parameter), got shape {M.shape}")
        if not np.all(np.isfinite(M)):
            raise InputError("covariance: the matrix has NaN or infinite values")
        scale = math.sqrt(max(float(np.abs(np.diag(M)).max(initial=0.0)), 1e-300))
        if np.abs(M - M.T).max(initial=0.0) > 1e-6 * scale**2 or np.any(np.diag(M) < 0):
            raise InputError("covariance: the matrix must be symmetric with a diagonal >= 0 "
                             "(variances)")
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "matrix", (M + M.T) / 2)

    @property
    def sigma(self) -> NDArray[np.float64]:
        """1-sigma of each parameter, shape ``(p,)`` (m, rad, unitless)."""
        return np.sqrt(np.diag(self.matrix))
