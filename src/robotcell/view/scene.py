"""What a 3D view shows, in SI units and independent of the plotting library.

A :class:`Scene` is a title, a list of items and, for a view that steps through the points of a
path, a list of :class:`Step` whose items replace each other on a slider. Every item holds its
geometry in metres in the scene's frame (the world of a cell, or the frame a calibration's
touches are in); :mod:`robotcell.view.plot` draws it in millimetres with plotly. The items are

- :class:`Lines`: polylines (links of an arm, a track's travel, a fitted line or circle);
- :class:`Points`: markers, one colour or coloured by a value (touches, a reach map);
- :class:`Arrows`: arrows from origins along vectors (joint axes, residual vectors);
- :class:`Triads`: labelled frames, X red, Y green, Z blue (tools, frames, the world);
- :class:`Mesh`: triangles (a turntable's plate).

Hover texts give poses in the cell's convention (:func:`pose_text`: x, y, z in mm; a, b, c in
deg with ``R = Rz(a) Ry(b) Rx(c)``, as in cell files).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robotcell.errors import InputError
from robotcell.io.poseformats import pose_to_vendor
from robotcell.kinematics.transforms import validate_pose

__all__ = ["AXIS_COLORS", "Arrows", "Item", "Lines", "Mesh", "Points", "Scene", "Step", "Triads",
           "pose_text"]

#: Colours of the X, Y and Z axes of a triad.
AXIS_COLORS = ("red", "green", "blue")


def _points(p: ArrayLike, name: str, nan_ok: bool = False) -> NDArray[np.float64]:
    """``p`` as an array of shape ``(N, 3)``; NaN rows (breaks of a polyline) only if ``nan_ok``."""
    arr = np.asarray(p, dtype=float).reshape(-1, 3) if np.size(p) else np.zeros((0, 3))
    bad = ~np.isfinite(arr)
    if nan_ok:
        bad &= ~np.all(np.isnan(arr), axis=-1, keepdims=True)
    if np.any(bad):
        raise InputError(f"{name} contains NaN or infinite values")
    return arr


def _texts(text: str | Sequence[str] | None, n: int, name: str) -> tuple[str, ...] | None:
    """One hover text per element: a sequence of ``n``, or one string for every element."""
    if text is None:
        return None
    if isinstance(text, str):
        return (text,) * n
    out = tuple(str(t) for t in text)
    if len(out) != n:
        raise InputError(f"{name}: {len(out)} texts for {n} elements")
    return out


@dataclass(frozen=True)
class Lines:
    """Polylines: consecutive points are joined, a row of NaN breaks the line.

    Attributes
    ----------
    name : str
        Legend entry.
    points : ndarray, shape (N, 3)
        Vertices (m); rows of NaN separate polylines.
    color : str
        CSS colour.
    width : float
        Line width (pixels).
    dash : {"solid", "dash", "dot"}
    hover : tuple of str or None
        Hover text per vertex (None: no hover).
    visible : bool
        False: listed in the legend, drawn when clicked there.
    colors : tuple of str or None
        A CSS colour per vertex, instead of ``color`` (a segment between two colours is drawn
        as a gradient; a row of NaN between them keeps each piece in its own colour).
    hover_xyz : bool
        Append each vertex's position (mm, as the browser formats it) to its hover text.
    parts : tuple of (str, int, int)
        Pieces drawn as one line (the moving parts of a cell at a point of a path): name, first
        vertex and one past the last, so that a reader can tell them apart.
    """

    name: str
    points: NDArray[np.float64]
    color: str = "black"
    width: float = 4.0
    dash: str = "solid"
    hover: tuple[str, ...] | None = None
    visible: bool = True
    colors: tuple[str, ...] | None = None
    hover_xyz: bool = False
    parts: tuple[tuple[str, int, int], ...] = ()

    def __post_init__(self) -> None:
        pts = _points(self.points, self.name, nan_ok=True)
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "hover", _texts(self.hover, len(pts), self.name))
        object.__setattr__(self, "colors", _texts(self.colors, len(pts), self.name))
        parts = tuple((str(n), int(a), int(b)) for n, a, b in self.parts)
        if any(not 0 <= a <= b <= len(pts) for _, a, b in parts):
            raise InputError(f"{self.name}: a part refers to vertices that do not exist")
        object.__setattr__(self, "parts", parts)


@dataclass(frozen=True)
class Points:
    """Markers, in one colour or coloured by a value on a colour scale.

    Attributes
    ----------
    name : str
    points : ndarray, shape (N, 3)
        Positions (m).
    color : str
        CSS colour, when ``values`` is None.
    values : ndarray, shape (N,), or None
        A value per point, drawn on the colour scale ``colorscale`` over ``value_range``.
    value_range : (float, float)
    value_title : str
        Title of the colour bar.
    colorscale : str
        A plotly colour scale name (e.g. ``"Viridis"``).
    symbol : str
        Marker symbol: ``circle``, ``diamond``, ``square``, ``x`` or ``cross``.
    size : float
        Marker size (pixels).
    labels : tuple of str or None
        Text drawn beside each point.
    hover : tuple of str or None
        Hover text per point.
    visible : bool
    hover_xyz : bool
        Append each point's position (mm, as the browser formats it) to its hover text.
    """

    name: str
    points: NDArray[np.float64]
    color: str = "black"
    values: NDArray[np.float64] | None = None
    value_range: tuple[float, float] = (0.0, 1.0)
    value_title: str = ""
    colorscale: str = "Viridis"
    symbol: str = "circle"
    size: float = 4.0
    labels: tuple[str, ...] | None = None
    hover: tuple[str, ...] | None = None
    visible: bool = True
    hover_xyz: bool = False

    def __post_init__(self) -> None:
        pts = _points(self.points, self.name)
        object.__setattr__(self, "points", pts)
        if self.values is not None:
            v = np.asarray(self.values, dtype=float).reshape(-1)
            if v.shape != (len(pts),) or not np.all(np.isfinite(v)):
                raise InputError(f"{self.name}: values must be {len(pts)} finite numbers")
            object.__setattr__(self, "values", v)
        object.__setattr__(self, "labels", _texts(self.labels, len(pts), self.name))
        object.__setattr__(self, "hover", _texts(self.hover, len(pts), self.name))


@dataclass(frozen=True)
class Arrows:
    """Arrows from origins along vectors, with a cone as head.

    Attributes
    ----------
    name : str
    origins : ndarray, shape (N, 3)
        Tails (m).
    vectors : ndarray, shape (N, 3)
        Tail to tip (m).
    color : str
    width : float
        Shaft width (pixels).
    head : float
        Length of the heads as a fraction of the longest arrow (at most half their own arrow).
    hover : tuple of str or None
        Hover text per arrow.
    visible : bool
    """

    name: str
    origins: NDArray[np.float64]
    vectors: NDArray[np.float64]
    color: str = "black"
    width: float = 5.0
    head: float = 0.25
    hover: tuple[str, ...] | None = None
    visible: bool = True

    def __post_init__(self) -> None:
        o = _points(self.origins, self.name)
        v = _points(self.vectors, self.name)
        if o.shape != v.shape:
            raise InputError(f"{self.name}: {len(o)} origins for {len(v)} vectors")
        object.__setattr__(self, "origins", o)
        object.__setattr__(self, "vectors", v)
        object.__setattr__(self, "hover", _texts(self.hover, len(o), self.name))

    @property
    def tips(self) -> NDArray[np.float64]:
        """Tips of the arrows, shape ``(N, 3)`` (m)."""
        return self.origins + self.vectors


@dataclass(frozen=True)
class Triads:
    """Frames drawn as three axes, X red, Y green, Z blue, with a label at the origin.

    Attributes
    ----------
    name : str
    poses : ndarray, shape (N, 4, 4)
        Poses of the frames in the scene's frame (m).
    labels : tuple of str
        Label of each frame, drawn at its origin.
    length : float
        Length of each axis (m).
    hover : tuple of str or None
        Hover text per frame (default: its label and pose, :func:`pose_text`).
    visible : bool
    """

    name: str
    poses: NDArray[np.float64]
    labels: tuple[str, ...]
    length: float = 0.1
    hover: tuple[str, ...] | None = None
    visible: bool = True

    def __post_init__(self) -> None:
        T = validate_pose(self.poses, self.name).reshape(-1, 4, 4)
        object.__setattr__(self, "poses", T)
        object.__setattr__(self, "labels", _texts(tuple(self.labels), len(T), self.name))
        if not (np.isfinite(self.length) and self.length > 0):
            raise InputError(f"{self.name}: axis length must be > 0, got {self.length}")
        hover = self.hover
        if hover is None:
            hover = tuple(f"<b>{lab}</b><br>{t}" for lab, t in zip(self.labels, pose_text(T)))
        object.__setattr__(self, "hover", _texts(hover, len(T), self.name))

    def axis_tips(self, k: int) -> NDArray[np.float64]:
        """Tips of axis ``k`` (0: X, 1: Y, 2: Z) of every frame, shape ``(N, 3)`` (m)."""
        return self.poses[:, :3, 3] + self.length * self.poses[:, :3, k]


@dataclass(frozen=True)
class Mesh:
    """Triangles: a surface such as a turntable's plate.

    Attributes
    ----------
    name : str
    vertices : ndarray, shape (N, 3)
        (m).
    faces : ndarray of int, shape (M, 3)
        Vertex indices of each triangle.
    color : str
    opacity : float
    hover : str
        One hover text for the surface.
    visible : bool
    """

    name: str
    vertices: NDArray[np.float64]
    faces: NDArray[np.int_]
    color: str = "lightgray"
    opacity: float = 0.5
    hover: str = ""
    visible: bool = True

    def __post_init__(self) -> None:
        v = _points(self.vertices, self.name)
        f = np.asarray(self.faces, dtype=int).reshape(-1, 3)
        if f.size and (f.min() < 0 or f.max() >= len(v)):
            raise InputError(f"{self.name}: a face refers to a vertex that does not exist")
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)


#: Anything a scene draws.
Item = Lines | Points | Arrows | Triads | Mesh


@dataclass(frozen=True)
class Step:
    """One point of a path: the items drawn while the slider is on it.

    Attributes
    ----------
    label : str
        Name of the point on the slider.
    items : tuple of Item
        The same kinds of item, in the same order, at every step of a scene.
    """

    label: str
    items: tuple[Item, ...]


@dataclass
class Scene:
    """A 3D view: items in one frame (m), a title, and what the reader must know to read it.

    Attributes
    ----------
    title : str
    items : list of Item
        Drawn at every step.
    notes : list of str
        Statements shown under the title, e.g. the magnification of residual vectors.
    steps : list of Step
        Optional: the points of a path, shown one at a time on a slider (the first one first).
    frame : str
        Name of the frame the items are in, for the axis titles.
    decimals : int
        Decimals of the millimetre coordinates a figure holds: 6 (1e-6 mm) reads a cell back
        to its kinematics; fewer keep a page with much data small (a path of hundreds of
        points: 2, i.e. 0.01 mm; touches: 3).
    """

    title: str
    items: list[Item] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    steps: list[Step] = field(default_factory=list)
    frame: str = "world"
    decimals: int = 6

    def __post_init__(self) -> None:
        if not 0 <= self.decimals <= 9:
            raise InputError(f"decimals must be within 0..9, got {self.decimals}")
        kinds = [tuple(type(i) for i in s.items) for s in self.steps]
        if any(k != kinds[0] for k in kinds):
            raise InputError("every step of a scene must hold the same kinds of item in the "
                             "same order")


def pose_text(T: ArrayLike) -> list[str]:
    """Poses in the cell's convention, for hover texts.

    Parameters
    ----------
    T : array_like, shape (..., 4, 4)
        Poses (m).

    Returns
    -------
    list of str
        Per pose ``"x .. y .. z .. mm<br>a .. b .. c .. deg"``: translation in mm and the angles
        of ``R = Rz(a) Ry(b) Rx(c)`` in deg (the KUKA convention of cell files), 3 decimals.
    """
    v = np.atleast_2d(pose_to_vendor(np.asarray(T, dtype=float).reshape(-1, 4, 4), "kuka"))
    v = np.where(np.abs(v) < 5e-4, 0.0, v)  # no "-0.000"
    return [f"x {x:.3f} y {y:.3f} z {z:.3f} mm<br>a {a:.3f} b {b:.3f} c {c:.3f} deg"
            for x, y, z, a, b, c in v]
