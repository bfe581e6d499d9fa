"""The covariance of a model's identified constants: how well an identification knows them.

An identified model (``robotcell identify``) carries the covariance of the constants it moved:
the pose of its robot base in the measuring device's frame (``base.x``, ``base.y``, ``base.z``,
``base.rx``, ``base.ry``, ``base.rz``: a small translation along and rotation about the axes of
R), link constants named after their joint (``A2.a``, ``A2.alpha``, ``A2.d``, ``A2.theta``,
``A2.beta``), a scale error (``A2.scale``) and the J2/J3 factor (``j23_factor``), in SI units
(m, rad; scale and factor unitless), and the model error: the scatter of a position that no
constant explains (m, 1-sigma per coordinate). Propagated through the model's FK they give the
error of a TCP position (:func:`robotcell.identification.uncertainty.position_error`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError

__all__ = ["ParameterCovariance", "is_base_parameter", "parameter_kind"]

_NAME = re.compile(r"^(?:(.+)\.(a|alpha|d|theta|beta|scale)|j23_factor)$")
_BASE = re.compile(r"^base\.(x|y|z|rx|ry|rz)$")


def is_base_parameter(name: str) -> bool:
    """True for the robot base's pose parameters ``base.x`` .. ``base.rz``."""
    return _BASE.match(name) is not None


def parameter_kind(name: str) -> str:
    """``length``, ``angle`` or ``number`` for a parameter name (``A2.d``, ``A3.beta``, ...).

    Raises
    ------
    InputError
        A name that is not ``<joint>.<a|alpha|d|theta|beta|scale>``, ``j23_factor`` or
        ``base.<x|y|z|rx|ry|rz>``.
    """
    b = _BASE.match(name)
    if b is not None:
        return "length" if b.group(1) in ("x", "y", "z") else "angle"
    m = _NAME.match(name)
    if m is None:
        raise InputError(f"parameter {name!r} is not <joint>.<a|alpha|d|theta|beta|scale>, "
                         "j23_factor or base.<x|y|z|rx|ry|rz>")
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
    model_error : float
        1-sigma per coordinate (m) of the position error that no constant explains (what the
        identification's cross-validated residuals show beyond the measuring accuracy); 0 when
        not known.
    """

    names: tuple[str, ...]
    matrix: NDArray[np.float64]
    model_error: float = 0.0

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
        if not (math.isfinite(self.model_error) and self.model_error >= 0):
            raise InputError(f"covariance: the model error must be a length >= 0, got "
                             f"{self.model_error}")
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "matrix", (M + M.T) / 2)
        object.__setattr__(self, "model_error", float(self.model_error))

    @property
    def sigma(self) -> NDArray[np.float64]:
        """1-sigma of each parameter, shape ``(p,)`` (m, rad, unitless)."""
        return np.sqrt(np.diag(self.matrix))
