"""Joint zero offsets of an identification, as corrections for a robot controller.

The identified zero of joint ``i`` is its DH constant (``theta`` for a revolute joint, ``d`` for a
prismatic one): the DH variable is ``sign_i * qm_i + theta_i``. A controller that keeps the
nominal model reaches the real arm's angle when its axis counter reads more by::

    delta = C^-1 (sign * (theta_identified - theta_nominal))

(``C`` the nominal model's joint coupling, or the stated J2/J3 factor; identity without one). A controller sets its axis
counter at the mastering (calibration) position from a stored offset, so ``delta`` is what to
add to that offset: KUKA's ``$MAMES[i]`` "offset between the mechanical zero point (mastering
notch) and the mathematical zero point of the axes in mm (degrees); at the mechanical zero point,
the value of $MAMES is assigned to the axis counter" (KUKA, *KR C2 Machine Data*, Maschinendaten
12.0400 en, section 2.1.7), in degrees (mm for linear axes); for ABB, the arm-side offsets in
radians (metres).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robotcell.identification.result import IdentificationResult

__all__ = ["JointOffset", "joint_offsets"]


@dataclass(frozen=True)
class JointOffset:
    """Correction of one controller axis's zero.

    Attributes
    ----------
    axis : str
        Axis name (``A2``).
    prismatic : bool
    delta : float
        Value to add to the controller's zero offset (rad, or m for a prismatic axis); NaN when
        the measurements cannot determine it.
    sigma : float
        Its 1-sigma (rad, m); NaN when not determined.
    why : str
        Why it is not determined (empty when it is).
    """

    axis: str
    prismatic: bool
    delta: float
    sigma: float
    why: str


def joint_offsets(result: IdentificationResult) -> list[JointOffset]:
    """The identified zero offset of every controller axis, with its 1-sigma.

    Parameters
    ----------
    result : IdentificationResult

    Returns
    -------
    list of JointOffset
        One per controller axis of the nominal model. An axis whose zero constant was held
        (e.g. axis 1, absorbed by the pose of the robot base in the device frame) is NaN with the
        reason, as is every axis a coupling mixes with it.
    """
    nominal = result.nominal
    names = [j.name or f"A{i}" for i, j in enumerate(nominal.joints, start=1)]
    keys = [f"{n}.{'d' if j.prismatic else 'theta'}" for n, j in zip(names, nominal.joints)]
    params = [result.parameter(k) for k in keys]
    signs = np.array([j.sign for j in nominal.joints])
    d_model = signs * np.array([p.value - p.nominal for p in params])
    # Covariance of the free zero constants (the others are undetermined).
    idx = [result.free.index(k) if k in result.free else -1 for k in keys]
    n = len(keys)
    cov = np.zeros((n, n))
    for a, ia in enumerate(idx):
        for b, ib in enumerate(idx):
            if ia >= 0 and ib >= 0:
                cov[a, b] = result.covariance[ia, ib] * signs[a] * signs[b]
    C = np.eye(n)
    if nominal.coupling is not None:
        C = nominal.coupling.matrix
    elif result.j23_factor:  # a stated J2/J3 factor (--j23-factor) is the controller's coupling
        C[2, 1] = result.j23_factor
    Cinv = np.linalg.inv(C)
    delta = Cinv @ d_model
    sig = np.sqrt(np.abs(np.diag(Cinv @ cov @ Cinv.T)))
    out = []
    for i, axis in enumerate(names):
        used = [k for k in np.flatnonzero(np.abs(Cinv[i]) > 1e-12) if not params[k].free]
        why = "; ".join(f"{keys[k]}: {params[k].why}" for k in used)
        ok = not used
        out.append(JointOffset(axis, bool(nominal.joints[i].prismatic),
                               float(delta[i]) if ok else math.nan, float(sig[i]) if ok else math.nan, why))
    return out
