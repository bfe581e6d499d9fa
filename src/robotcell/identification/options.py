"""How an identification weighs its measurements and what it may free: :class:`IdentifyOptions`.

:func:`robotcell.identification.identify` takes them as one object (``options=``) or keyword
by keyword (``identify(nominal, measurements, sigma=2e-5, scale=True)``); the functions over it
(cross-validation, the choice of constants, the J2/J3 check, ``studies.identify.identify_file``)
pass them on unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

from numpy.typing import ArrayLike

__all__ = ["ANGLE_SIGMA", "MAX_SIGMA_ANGLE", "MAX_SIGMA_LENGTH", "SIGMA", "IdentifyOptions"]

#: Default measurement accuracies: a laser tracker (m per coordinate) and a 6D probe (rad).
SIGMA = 0.05e-3
ANGLE_SIGMA = math.radians(0.02)
#: Largest 1-sigma of a free link length (m) and angle (rad): several times what the link
#: constants of an industrial arm can plausibly be off by (well under 1 mm and 0.5 deg).
MAX_SIGMA_LENGTH = 5e-3
MAX_SIGMA_ANGLE = math.radians(2.0)


@dataclass(frozen=True)
class IdentifyOptions:
    """The options of an identification.

    Attributes
    ----------
    sigma : float
        Accuracy of a measured coordinate (m, 1-sigma per coordinate); weights the point
        residuals. Default 0.05 mm (a laser tracker).
    angle_sigma : float
        Accuracy of a measured orientation (rad per axis, 1-sigma); weights the rotation
        residuals. Default 0.02 deg.
    scale : bool
        Also identify a scale error per axis (gear ratio): ``qm = (1 + scale) q``.
    compliance : bool
        Also identify the gravity compliance of axes 2 and 3 (rad per N m), multiplied by the
        gravity torque of the nominal link masses (``Joint.mass``, ``Joint.com``).
    j23_factor : float, optional
        J2/J3 coupling factor ``k`` with ``q3_model = J3 + k J2`` (0: none). Held unless
        ``fit_j23_factor``. Default: the nominal model's ``j23_factor`` (0 without a coupling).
    fit_j23_factor : bool
        Identify ``k`` too (starting at ``j23_factor``).
    rank_tol : float
        A scaled Jacobian column closer than this (sine of the angle) to the span of the columns
        kept before it is fixed as not identifiable.
    max_sigma_length, max_sigma_angle : float
        A link constant whose 1-sigma exceeds this (m, rad; default 5 mm and 2 deg, several
        times any plausible manufacturing error) is held at its nominal value and named in
        ``fixed``: the measurements see it too weakly to move it (``math.inf``: never).
    group_tol : float or array_like, shape (n,), optional
        Joint values within this of each other are the same commanded value, for the count of
        distinct configurations that the redundancy check rests on: one number (rad, a
        prismatic joint taking as many mm as that is deg) or one per joint (rad, m); default
        derived from the data (:func:`robotcell.calibration.grouping.resolution`).
    """

    sigma: float = SIGMA
    angle_sigma: float = ANGLE_SIGMA
    scale: bool = False
    compliance: bool = False
    j23_factor: float | None = None
    fit_j23_factor: bool = False
    rank_tol: float = 1e-6
    max_sigma_length: float = MAX_SIGMA_LENGTH
    max_sigma_angle: float = MAX_SIGMA_ANGLE
    group_tol: ArrayLike | None = None

    @classmethod
    def of(cls, options: IdentifyOptions | None = None, **keywords: Any) -> IdentifyOptions:
        """``options`` (default: every field at its default) with the fields in ``keywords``.

        Raises
        ------
        TypeError
            A keyword that is no field, as for a call with an unknown keyword.
        """
        unknown = sorted(set(keywords) - {f.name for f in fields(cls)})
        if unknown:
            raise TypeError(f"unexpected keyword argument {unknown[0]!r} (an identification "
                            f"takes {', '.join(f.name for f in fields(cls))}, name and hold)")
        base = cls() if options is None else options
        return replace(base, **keywords) if keywords else base
