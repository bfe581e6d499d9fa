"""The smallest distance between two groups of shapes, sample by sample.

The exact distance of a pair is the collision library's (coal's GJK/EPA distance, exact for
capsules, spheres and boxes, to its tolerance for cylinders). Which pairs to ask it about is
decided here: every pair's distance is at least the distance of their bounding spheres less
their radii, computed for all pairs and samples at once; at each sample the pairs are asked in
the order of that bound until the bound passes the smallest distance found, so the answer is
the exact minimum over all pairs while coal sees one to three pairs per sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robotcell.errors import InputError

__all__ = ["Clearance", "Shapes", "smallest_distances"]


def _coal() -> Any:
    try:
        import coal  # the collision library; an optional dependency
    except ImportError:
        raise InputError("clearance needs the collision library coal: "
                         "pip install 'robotcell[clearance]'") from None
    return coal


@lru_cache(maxsize=4096)
def _geometry(shape: str, size: tuple[float, ...]) -> Any:
    coal = _coal()
    if shape == "box":
        return coal.Box(*size)
    if shape == "sphere":
        return coal.Sphere(size[0])
    if shape == "cylinder":
        return coal.Cylinder(*size)
    return coal.Capsule(*size)


@dataclass(frozen=True)
class Shapes:
    """A group of shapes over ``P`` samples.

    Parameters
    ----------
    names : tuple of str
        Name of each shape (the link or part), length K.
    kinds : tuple of str
        ``box``, ``sphere``, ``cylinder`` or ``capsule`` per shape.
    sizes : tuple of tuple of float
        Each shape's size (m), as :class:`robotcell.clearance.bodies.Body` takes it; a capsule's
        length may change from sample to sample (``lengths``).
    poses : ndarray, shape (P, K, 4, 4)
        ``T_world_shape`` at each sample (m).
    radii : ndarray, shape (P, K)
        Bounding radius of each shape at each sample (m).
    lengths : ndarray, shape (P, K), optional
        For the capsules of an arm's links: the length of each at each sample (m), which a
        prismatic joint changes; NaN for a shape of fixed size.
    """

    names: tuple[str, ...]
    kinds: tuple[str, ...]
    sizes: tuple[tuple[float, ...], ...]
    poses: NDArray[np.float64]
    radii: NDArray[np.float64]
    lengths: NDArray[np.float64] | None = None

    @classmethod
    def capsules(cls, names: tuple[str, ...], segments: NDArray[np.float64],
                 radius: NDArray[np.float64]) -> Shapes:
        """Capsules around ``segments`` ``(P, K, 2, 3)`` (m) of radius ``radius`` ``(K,)``."""
        a, b = segments[..., 0, :], segments[..., 1, :]
        axis = b - a
        length = np.linalg.norm(axis, axis=-1)
        z = np.where(length[..., None] > 1e-12, axis / np.maximum(length, 1e-300)[..., None],
                     np.array([0.0, 0.0, 1.0]))
        helper = np.where(np.abs(z[..., :1]) < 0.9, np.array([1.0, 0, 0]), np.array([0, 1.0, 0]))
        x = np.cross(helper, z)
        x /= np.linalg.norm(x, axis=-1, keepdims=True)
        T = np.zeros(segments.shape[:-2] + (4, 4))
        T[..., :3, 0], T[..., :3, 1], T[..., :3, 2] = x, np.cross(z, x), z
        T[..., :3, 3], T[..., 3, 3] = 0.5 * (a + b), 1.0
        sizes = tuple((float(r), float(L)) for r, L in zip(radius, length.max(axis=0)))
        return cls(names, ("capsule",) * len(names), sizes, T, radius + 0.5 * length, length)

    def geometry(self, p: int, k: int) -> Any:
        """The collision object of shape ``k`` at sample ``p``."""
        if self.lengths is None or not np.isfinite(self.lengths[p, k]):
            return _geometry(self.kinds[k], self.sizes[k])
        return _geometry("capsule", (self.sizes[k][0], round(float(self.lengths[p, k]), 12)))


@dataclass(frozen=True)
class Clearance:
    """The smallest distance between the robot and the rest at each sample of a motion.

    Attributes
    ----------
    distance : ndarray, shape (P,)
        Smallest distance at each sample (m); negative where coal finds the shapes overlap
        (the depth it estimates), ``inf`` where no pair is checked.
    pair : tuple of tuple of str
        The two shapes at that distance, per sample.
    nearest : ndarray, shape (P, 2, 3)
        The nearest point on each of the two shapes, in the world (m).
    position : ndarray, shape (P,)
        Where the sample lies along the program: ``i + f`` is the fraction ``f`` of the way
        from point ``i`` to point ``i + 1`` (points counted from 0).
    """

    distance: NDArray[np.float64]
    pair: tuple[tuple[str, str], ...]
    nearest: NDArray[np.float64]
    position: NDArray[np.float64]

    @property
    def minimum(self) -> float:
        """The smallest distance over the whole motion (m)."""
        return float(self.distance.min()) if self.distance.size else math.inf

    def below(self, limit: float) -> NDArray[np.intp]:
        """Indices of the samples closer than ``limit`` (m)."""
        return np.flatnonzero(self.distance < limit)

    def per_point(self) -> NDArray[np.float64]:
        """Smallest distance at each program point itself (m), shape (N,)."""
        exact = np.isclose(self.position, np.round(self.position))
        points = np.round(self.position[exact]).astype(int)
        out = np.full(points.max() + 1 if points.size else 0, np.inf)
        np.minimum.at(out, points, self.distance[exact])
        return out

    def per_segment(self) -> NDArray[np.float64]:
        """Smallest distance along each segment ``i -> i + 1``, its ends included (m), (N-1,)."""
        n = int(np.floor(self.position.max())) if self.position.size else 0
        out = np.full(n, np.inf)
        lo = np.minimum(np.floor(self.position).astype(int), n - 1)
        np.minimum.at(out, lo, self.distance)
        ends = np.isclose(self.position, np.round(self.position)) & (self.position >= 1)
        np.minimum.at(out, np.round(self.position[ends]).astype(int) - 1, self.distance[ends])
        return out


def smallest_distances(a: Shapes, b: Shapes, pairs: NDArray[np.intp], position: NDArray[np.float64]
                       ) -> Clearance:
    """The exact smallest distance between shapes of ``a`` and ``b`` at each sample.

    Parameters
    ----------
    a, b : Shapes
        Two groups over the same ``P`` samples.
    pairs : ndarray, shape (M, 2)
        The pairs to check: index into ``a``, index into ``b``.
    position : ndarray, shape (P,)
        Each sample's place along the program (:attr:`Clearance.position`).
    """
    coal = _coal()
    P = a.poses.shape[0]
    dist = np.full(P, np.inf)
    near = np.full((P, 2, 3), np.nan)
    best_pair: list[tuple[str, str]] = [("", "")] * P
    if len(pairs) == 0:
        return Clearance(dist, tuple(best_pair), near, position)
    ca, cb = a.poses[:, :, :3, 3][:, pairs[:, 0]], b.poses[:, :, :3, 3][:, pairs[:, 1]]
    bound = (np.linalg.norm(ca - cb, axis=-1) - a.radii[:, pairs[:, 0]]
             - b.radii[:, pairs[:, 1]])
    order = np.argsort(bound, axis=1)
    request = coal.DistanceRequest()
    for p in range(P):
        best, hit = math.inf, None
        for m in order[p]:
            if bound[p, m] >= best:
                break
            i, j = pairs[m]
            result = coal.DistanceResult()
            d = coal.distance(a.geometry(p, i), _transform(coal, a.poses[p, i]),
                              b.geometry(p, j), _transform(coal, b.poses[p, j]), request, result)
            if d < best:
                best, hit = d, (i, j, result.getNearestPoint1(), result.getNearestPoint2())
        if hit is not None:
            i, j, p1, p2 = hit
            dist[p], near[p], best_pair[p] = best, (p1, p2), (a.names[i], b.names[j])
    return Clearance(dist, tuple(best_pair), near, position)


def _transform(coal: Any, T: NDArray[np.float64]) -> Any:
    return coal.Transform3s(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))
