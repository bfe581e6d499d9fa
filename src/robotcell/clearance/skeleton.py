"""The links of a serial arm as capsules around the skeleton of its DH model.

Each joint ``i`` of a DH chain moves the frame ``i - 1`` to the frame ``i`` along two straight
pieces: with the standard convention first along ``z_{i-1}`` (the offset ``d_i``) then along
``x_i`` (the length ``a_i``); with the modified convention first along ``x_{i-1}`` (``a_{i-1}``)
then along ``z_i`` (``d_i``). Those pieces, the base offset, the flange offset and the tool (from
the flange to the TCP) are the segments; a link is the capsule of radius ``r`` around its
segments. A real casting is not a capsule: the model is as good as its radius (docs/clearance.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.kinematics.arm import Arm

__all__ = ["LinkModel", "default_radius", "frame_segments", "link_segments"]

#: Default link radius as a share of the arm's reach, and its bounds (m).
RADIUS_SHARE, RADIUS_MIN, RADIUS_MAX = 0.06, 0.03, 0.15
#: Default radius of the tool's capsule (m): a welding torch or a pointer.
TOOL_RADIUS = 0.025


def default_radius(arm: Arm) -> float:
    """A link radius for ``arm`` from its size: 6 % of its reach, within 30-150 mm.

    The reach is the sum of the DH lengths and offsets (``sqrt(a_i^2 + d_i^2)`` per joint), the
    length of the stretched skeleton; 6 % of it gives 136 mm for a KUKA KR 16 and 79 mm for a UR5e, about the radius of
    their upper arms.
    """
    reach = float(sum(np.hypot(j.a, j.d) for j in arm.joints))
    return float(np.clip(RADIUS_SHARE * reach, RADIUS_MIN, RADIUS_MAX))


@dataclass(frozen=True)
class LinkModel:
    """The radii of an arm's capsules (m).

    Parameters
    ----------
    radius : float or None
        Radius of every link's capsule (m); None: the arm's model file's ``link_radius``, else
        :func:`default_radius` of the arm.
    tool_radius : float
        Radius of the tool's capsule from the flange to the TCP (m).
    """

    radius: float | None = None
    tool_radius: float = TOOL_RADIUS

    def __post_init__(self) -> None:
        for name, value in (("radius", self.radius), ("tool_radius", self.tool_radius)):
            if value is not None and not (np.isfinite(value) and value >= 0):
                raise InputError(f"the link model's {name} must be a finite length >= 0 (m), "
                                 f"got {value!r}")

    def radius_of(self, arm: Arm) -> float:
        """The links' radius for ``arm`` (m): this model's, else the arm's ``link_radius``,
        else :func:`default_radius`."""
        if self.radius is not None:
            return float(self.radius)
        return default_radius(arm) if arm.link_radius is None else float(arm.link_radius)


def link_segments(arm: Arm, q: ArrayLike, tool: ArrayLike | None = None
                  ) -> tuple[NDArray[np.float64], tuple[str, ...]]:
    """The segments of an arm's skeleton at joint values ``q``, in its base frame.

    Parameters
    ----------
    arm : Arm
        The arm (its base transform, DH joints, flange).
    q : array_like, shape (..., n)
        Controller axis values (rad, m).
    tool : array_like, shape (4, 4), optional
        ``T_F_TCP`` (m); with it the last segment runs from the flange to the TCP.

    Returns
    -------
    segments : ndarray, shape (..., S, 2, 3)
        End points of each segment in the robot base frame (m).
    names : tuple of str, length S
        The link each segment belongs to: ``base``, ``link1`` .. ``linkN``, ``flange``, ``tool``.
    """
    return frame_segments(arm, arm.frames(q), tool)


def frame_segments(arm: Arm, F: NDArray[np.float64], tool: ArrayLike | None = None
                   ) -> tuple[NDArray[np.float64], tuple[str, ...]]:
    """:func:`link_segments` from the arm's DH frames ``F = arm.frames(q)``, shape
    ``(..., m + 1, 4, 4)``, for a caller that uses the frames too (the flange is
    ``F[..., -1, :, :] @ arm.flange``)."""
    O = F[..., :3, 3]
    segs = [(np.zeros_like(O[..., 0, :]), O[..., 0, :])]
    names = ["base"]
    standard = arm.convention == "standard"
    for i in range(1, F.shape[-3]):
        axis = F[..., i - 1, :3, 2] if standard else F[..., i - 1, :3, 0]
        step = O[..., i, :] - O[..., i - 1, :]
        foot = O[..., i - 1, :] + axis * np.sum(axis * step, axis=-1, keepdims=True)
        segs += [(O[..., i - 1, :], foot), (foot, O[..., i, :])]
        names += [f"link{i}", f"link{i}"]
    T_flange = F[..., -1, :, :] @ arm.flange
    segs.append((O[..., -1, :], T_flange[..., :3, 3]))
    names.append("flange")
    if tool is not None:
        T_tcp = T_flange @ np.asarray(tool, dtype=float)
        segs.append((T_flange[..., :3, 3], T_tcp[..., :3, 3]))
        names.append("tool")
    return np.stack([np.stack(s, axis=-2) for s in segs], axis=-3), tuple(names)
