"""Serial chains from URDF files, and their DH model.

The file is parsed with ``urdf-parser-py`` (the ROS project's parser; optional extra
``robotcell[urdf]``). The chain runs from a base link (default: the root) to a tip link (default:
the single leaf; a branching tree needs ``tip_link``). Fixed joints are merged into the next joint's
origin or into the tip; ``continuous`` joints are revolute joints without limits.

URDF poses: a joint's ``origin`` is the pose of the joint frame in the parent link's frame,
``xyz`` (m) and ``rpy`` = roll, pitch, yaw about the fixed X, Y, Z axes (``Rz(y) Ry(p) Rx(r)``,
scipy's extrinsic ``"xyz"``); the ``axis`` (default ``1 0 0``) is given in the joint frame. The
child link's frame is the joint frame moved by the joint value.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robotcell.dhprocedure.axes import AxisChain
from robotcell.dhprocedure.exactness import check_exact
from robotcell.dhprocedure.procedure import DHDerivation, derive
from robotcell.errors import InputError, RobotcellError
from robotcell.io.fileio import read_text
from robotcell.io.tables import CELL_EXTENT_MM
from robotcell.kinematics.dh import Convention
from robotcell.kinematics.transforms import make_pose

__all__ = ["UrdfChain", "UrdfJoint", "dh_from_urdf", "read_urdf"]

INSTALL_HINT = "reading URDF files needs the optional package urdf-parser-py: pip install 'robotcell[urdf]'"
_MOVABLE = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic"}
#: Largest limit of a revolute joint (rad): 1000 rad, about 160 turns, is more than any joint
#: with limits has; a larger one is a typing error.
MAX_TURN_RAD = 1000.0


@dataclass(frozen=True)
class UrdfJoint:
    """One movable joint of a URDF chain.

    Attributes
    ----------
    name : str
    type : {"revolute", "prismatic"}
        ``continuous`` joints are revolute.
    origin : ndarray, shape (4, 4)
        Pose of the joint frame in the frame of the previous movable joint's child link (or the
        base link), fixed joints in between merged (metres).
    axis : ndarray, shape (3,)
        Unit axis in the joint frame.
    lower, upper : float
        Limits (rad or m); infinite for continuous joints or when the file gives none.
    """

    name: str
    type: str
    origin: NDArray[np.float64]
    axis: NDArray[np.float64]
    lower: float
    upper: float


@dataclass(frozen=True, eq=False)
class UrdfChain:
    """A serial chain read from a URDF file.

    Attributes
    ----------
    name : str
        The URDF robot name.
    base_link, tip_link : str
    joints : tuple of UrdfJoint
    tip : ndarray, shape (4, 4)
        Pose of the tip link in the last joint's child link (fixed joints merged; metres).
    """

    name: str
    base_link: str
    tip_link: str
    joints: tuple[UrdfJoint, ...]
    tip: NDArray[np.float64]

    @property
    def n_joints(self) -> int:
        """Number of movable joints."""
        return len(self.joints)

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """Forward kinematics straight from the URDF joint origins and axes.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Joint values (rad for revolute, m for prismatic joints).

        Returns
        -------
        ndarray, shape (..., 4, 4)
            Pose of the tip link in the base link (metres).
        """
        try:
            arr = np.asarray(q, dtype=float)
        except (TypeError, ValueError) as exc:
            raise InputError(f"q must be numeric: {exc}") from None
        n = self.n_joints
        if arr.ndim == 0 or arr.shape[-1] != n or not np.all(np.isfinite(arr)):
            raise InputError(f"{self.name} has {n} joints; q must be finite with shape (..., {n}), "
                             f"got {arr.shape}")
        T = np.broadcast_to(np.eye(4), arr.shape[:-1] + (4, 4))
        for i, j in enumerate(self.joints):
            motion = np.zeros(arr.shape[:-1] + (4, 4))
            motion[..., 3, 3] = 1.0
            if j.type == "revolute":
                rv = arr[..., i, None] * j.axis
                motion[..., :3, :3] = Rotation.from_rotvec(rv.reshape(-1, 3)).as_matrix().reshape(
                    rv.shape + (3,))
            else:
                motion[..., :3, :3] = np.eye(3)
                motion[..., :3, 3] = arr[..., i, None] * j.axis
            T = T @ j.origin @ motion
        return T @ self.tip

    def axes(self) -> AxisChain:
        """The joint axes at ``q = 0`` in the base link frame, and the tip as the flange.

        Returns
        -------
        AxisChain
        """
        T = np.eye(4)
        points, dirs = [], []
        for j in self.joints:
            T = T @ j.origin
            points.append(T[:3, 3])
            dirs.append(T[:3, :3] @ j.axis)
        return AxisChain(
            points=np.array(points), directions=np.array(dirs),
            types=tuple(j.type for j in self.joints), flange=T @ self.tip,
            names=tuple(j.name for j in self.joints),
            lower=np.array([j.lower for j in self.joints]),
            upper=np.array([j.upper for j in self.joints]),
        )


def read_urdf(
    source: str | Path, base_link: str | None = None, tip_link: str | None = None,
) -> UrdfChain:
    """Read the serial chain from ``base_link`` to ``tip_link`` of a URDF file.

    Parameters
    ----------
    source : str or Path
        Path of a ``.urdf`` file, or the URDF text itself (starting with ``<``).
    base_link : str, optional
        First link of the chain (default: the root link).
    tip_link : str, optional
        Last link (default: the only leaf below ``base_link``; needed when the tree branches).

    Returns
    -------
    UrdfChain

    Raises
    ------
    InputError
        Unreadable file or XML, unknown link, several root links, a branch without ``tip_link``
        (naming the link and its joints), a floating or planar joint (naming it), an origin, axis
        or limit that is not finite, an origin or a prismatic limit beyond 100 m, a revolute
        limit beyond :data:`MAX_TURN_RAD`, an axis of zero length, or no movable joint.
    RobotcellError
        urdf-parser-py is not installed (the message says how to install it).
    """
    try:
        from urdf_parser_py.urdf import URDF
        from urdf_parser_py.xml_reflection.core import ParseError
    except ImportError:
        raise RobotcellError(INSTALL_HINT) from None
    text, origin = _text(source)
    try:
        model = URDF.from_xml_string(text.encode("utf-8"))
    except (ParseError, SyntaxError, ValueError, AssertionError) as exc:
        raise InputError(f"{origin}: not a readable URDF: {exc}") from None
    links = set(model.link_map)
    for label, link in (("base_link", base_link), ("tip_link", tip_link)):
        if link is not None and link not in links:
            raise InputError(f"{origin}: {label} {link!r} is not a link of the file; links: "
                             f"{', '.join(sorted(links))}")
    roots = sorted(link for link in links if link not in model.parent_map)
    if base_link is None and len(roots) != 1:
        raise InputError(f"{origin}: the links do not form one tree (root links: "
                         f"{', '.join(roots)}); give base_link")
    start = base_link or roots[0]
    path = _path(model, start, tip_link, origin)
    joints: list[UrdfJoint] = []
    acc = np.eye(4)
    for j in path:
        acc = acc @ _origin(j, origin)
        if j.type == "fixed":
            continue
        if j.type not in _MOVABLE:
            raise InputError(
                f"{origin}: joint {j.name!r} is {j.type}: a DH chain has revolute, continuous, "
                "prismatic and fixed joints only; end the chain before it with tip_link"
            )
        axis = _finite(j.axis if j.axis is not None else (1.0, 0.0, 0.0), origin, j, "axis xyz")
        axis = axis / max(float(np.abs(axis).max()), 1e-300)  # only the direction counts
        norm = float(np.linalg.norm(axis))
        if norm < 1e-12:
            raise InputError(f"{origin}: joint {j.name!r} has an axis of zero length; give <axis "
                             "xyz=\"0 0 1\"/> or the direction it moves about")
        lo, hi = -np.inf, np.inf
        if j.type != "continuous" and j.limit is not None:
            lo, hi = _finite([j.limit.lower, j.limit.upper], origin, j, "limit lower, upper")
            bound = CELL_EXTENT_MM * 1e-3 if j.type == "prismatic" else MAX_TURN_RAD
            if max(abs(lo), abs(hi)) > bound:
                raise InputError(f"{origin}: joint {j.name!r}: limits [{lo:g}, {hi:g}] reach "
                                 f"beyond {bound:g} {'m' if j.type == 'prismatic' else 'rad'}; "
                                 "give the joint's real limits (a joint without them is "
                                 "'continuous')")
            if not lo < hi:
                lo, hi = -np.inf, np.inf
        joints.append(UrdfJoint(j.name, _MOVABLE[j.type], acc, axis / norm, lo, hi))
        acc = np.eye(4)
    if not joints:
        raise InputError(f"{origin}: no revolute, continuous or prismatic joint between "
                         f"{start!r} and the tip")
    tip = tip_link or (path[-1].child if path else start)
    return UrdfChain(name=model.name or "urdf", base_link=start, tip_link=tip,
                     joints=tuple(joints), tip=acc)


def dh_from_urdf(
    source: str | Path, convention: Convention = "standard", base_link: str | None = None,
    tip_link: str | None = None, signs: Sequence[float] | None = None, tol: float = 1e-12,
) -> DHDerivation:
    """The DH model of a URDF chain, by the DH procedure on its joint axes at zero.

    Parameters
    ----------
    source : str or Path
        URDF file or text.
    convention : {"standard", "modified"}
    base_link, tip_link : str, optional
        See :func:`read_urdf`. The model's base frame R is the base link, its flange the tip link.
    signs : sequence of float, shape (n,), optional
        Sign corrections, see :func:`robotcell.dhprocedure.dh_from_axes`.
    tol : float
        Tolerance (m, rad) of the case tests, see :func:`robotcell.dhprocedure.dh_from_axes`.

    Returns
    -------
    DHDerivation
        ``deviation`` compares the model as written with the URDF's own FK
        (:meth:`UrdfChain.fk`).

    Raises
    ------
    InputError
        See :func:`read_urdf`; and a model whose file form would not reproduce the URDF's FK to
        1e-9 m and rad (the message says by how much, which joints show it and why).
    """
    chain = read_urdf(source, base_link, tip_link)
    where = str(source) if not str(source).lstrip().startswith("<") else "URDF text"
    axes = chain.axes()
    der = derive(
        axes, convention, signs, tol, chain.name, chain.name,
        f"derived by the DH procedure (robotcell dh from-urdf) from {where}, chain "
        f"{chain.base_link} -> {chain.tip_link}",
    )
    return replace(der, deviation=check_exact(der.robot, chain.fk, axes, where, tol))


def _text(source: str | Path) -> tuple[str, str]:
    s = str(source)
    if s.lstrip().startswith("<"):
        return s, "URDF text"
    p = Path(s)
    if not p.is_file():
        raise InputError(f"URDF file {s!r} does not exist")
    return read_text(p, "URDF file"), s


def _path(model: Any, start: str, tip: str | None, origin: str) -> list[Any]:
    """Joints from ``start`` down to ``tip`` (or to the only leaf), in order."""
    if tip is not None:
        out, link = [], tip
        while link != start:
            if link not in model.parent_map:
                raise InputError(f"{origin}: tip_link {tip!r} is not below base_link {start!r}")
            jname, link = model.parent_map[link]
            out.append(model.joint_map[jname])
        return out[::-1]
    out, link = [], start
    while model.child_map.get(link):
        children = model.child_map[link]
        if len(children) > 1:
            names = ", ".join(j for j, _ in children)
            raise InputError(
                f"{origin}: not a serial chain: link {link!r} branches into joints {names}; "
                "choose the end of the arm with tip_link"
            )
        jname, link = children[0]
        out.append(model.joint_map[jname])
    return out


def _finite(values: Any, origin: str, joint: Any, what: str) -> NDArray[np.float64]:
    """``values`` of ``joint`` as finite floats, or an error naming the joint and attribute."""
    try:
        v = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{origin}: joint {joint.name!r}: {what} must be numbers, got "
                         f"{values!r}") from None
    if not np.all(np.isfinite(v)):
        raise InputError(f"{origin}: joint {joint.name!r}: {what} {v.tolist()} must be finite")
    return v


def _origin(joint: Any, origin: str) -> NDArray[np.float64]:
    """The joint's ``<origin>``, refused when not finite or farther than any real robot reaches
    (:data:`~robotcell.io.tables.CELL_EXTENT_MM`)."""
    o = joint.origin
    xyz = _finite(o.xyz if o is not None and o.xyz is not None else (0.0, 0.0, 0.0), origin,
                  joint, "origin xyz")
    rpy = _finite(o.rpy if o is not None and o.rpy is not None else (0.0, 0.0, 0.0), origin,
                  joint, "origin rpy")
    if np.abs(xyz).max() > CELL_EXTENT_MM * 1e-3:
        raise InputError(f"{origin}: joint {joint.name!r}: origin xyz {xyz.tolist()} m is beyond "
                         f"{CELL_EXTENT_MM * 1e-3:g} m, the size of any real robot cell: a "
                         "typing or unit error (URDF lengths are in metres)")
    return make_pose(Rotation.from_euler("xyz", rpy).as_matrix(), xyz)
