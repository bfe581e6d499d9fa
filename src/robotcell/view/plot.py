"""Draw a :class:`robotcell.view.scene.Scene` with plotly, and write it as one HTML file.

plotly is imported inside the functions, so that the commands that draw nothing do not load
it. Lengths are drawn in millimetres, rounded to ``Scene.decimals`` (1e-6 mm for a cell: the
page reads back to 1e-6 mm and stays small beside plotly.js, about 4.8 MB, inlined so that the
page opens offline; fewer for scenes with much data). A page stays under
:data:`MAX_PAGE_BYTES`.

Each trace carries in ``meta`` what it draws, so that a program (or a test) can read the scene
back from the figure or from the page: ``{"item": NAME, "part": PART}`` with ``PART`` one of
``lines``, ``points``, ``shafts`` and ``heads`` (arrows), ``mesh``, ``origins`` and ``x``, ``y``,
``z`` (triads; these add ``length_mm``, the drawn axis length); lines that merge several pieces
add ``parts``: ``[[NAME, FIRST, END], ...]``, the vertices of each.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from robotcell.io.fileio import atomic_write
from robotcell.view.scene import AXIS_COLORS, Arrows, Item, Lines, Mesh, Points, Scene, Triads

if TYPE_CHECKING:
    import plotly.graph_objects as go

__all__ = ["DECIMALS", "MAX_PAGE_BYTES", "RENDERED", "embed", "embed_within", "page",
           "scene_figure", "write_html"]

#: Decimals of the millimetre coordinates written into the figure of a cell (``Scene.decimals``).
DECIMALS = 6
#: The largest page a view or a report writes (bytes): plotly.js inlined is 4.82 MB of it.
MAX_PAGE_BYTES = 5_000_000
#: Where the camera looks from at first, relative to the scene's centre: from the front right
#: (+x, -y) and above, in units of the scene's size.
CAMERA = {"x": 1.1, "y": -1.3, "z": 0.6}
#: What the page's own script sets on ``<body>`` once plotly has drawn the scene:
#: ``data-scene="rendered"``.
RENDERED = "document.body.dataset.scene = 'rendered';"


def _mm(points: NDArray[np.float64], decimals: int) -> dict[str, list[float | None]]:
    """``x``, ``y``, ``z`` lists in mm, rounded; NaN (a break in a line) becomes None."""
    arr = np.round(np.asarray(points, dtype=float).reshape(-1, 3) * 1e3, decimals)
    return {c: [None if math.isnan(v) else (int(v) if v.is_integer() else v)
                for v in arr[:, k].tolist()]
            for k, c in enumerate("xyz")}


def _segments(starts: NDArray[np.float64], ends: NDArray[np.float64]) -> NDArray[np.float64]:
    """Separate segments as one polyline: start, end, NaN per segment, shape ``(3 N, 3)``."""
    gap = np.full_like(starts, np.nan)
    return np.stack([starts, ends, gap], axis=1).reshape(-1, 3)


def _common(item: Item, part: str, **meta: Any) -> dict[str, Any]:
    return {"name": item.name, "legendgroup": item.name,
            "visible": True if item.visible else "legendonly",
            "meta": {"item": item.name, "part": part, **meta}}


def _hover(hover: tuple[str, ...] | None, xyz: bool = False, decimals: int = 3
           ) -> dict[str, Any]:
    """Hover texts; with ``xyz`` the position follows, formatted by the browser (one template
    for the trace instead of a number per point)."""
    if xyz:
        where = " ".join(f"{c} %{{{c}:.{min(decimals, 3)}f}}" for c in "xyz") + " mm"
        text = {} if hover is None else {"hovertext": list(hover)}
        return {**text, "hovertemplate": ("%{hovertext}<br>" if hover else "") + where
                + "<extra></extra>"}
    if hover is None:
        return {"hoverinfo": "skip"}
    return {"hovertext": list(hover), "hoverinfo": "text"}


def _traces(go: Any, item: Item, decimals: int = DECIMALS) -> list[Any]:
    """The plotly traces of one item (the same number for every item of a kind)."""
    def xyz(points: NDArray[np.float64]) -> dict[str, list[float | None]]:
        return _mm(points, decimals)

    if isinstance(item, Lines):
        parts = {"parts": [list(p) for p in item.parts]} if item.parts else {}
        color: str | list[str] = item.color if item.colors is None else list(item.colors)
        return [go.Scatter3d(mode="lines", **xyz(item.points),
                             **_hover(item.hover, item.hover_xyz, decimals),
                             line={"color": color, "width": item.width, "dash": item.dash},
                             **_common(item, "lines", **parts))]
    if isinstance(item, Points):
        marker: dict[str, Any] = {"size": item.size, "symbol": item.symbol}
        if item.values is None:
            marker["color"] = item.color
        else:
            marker.update(color=np.round(item.values, 6).tolist(), colorscale=item.colorscale,
                          cmin=item.value_range[0], cmax=item.value_range[1],
                          colorbar={"title": {"text": item.value_title}, "len": 0.5, "x": 0.0,
                                    "xanchor": "left"})
        text = {} if item.labels is None else {"text": list(item.labels),
                                                "textposition": "top center"}
        return [go.Scatter3d(mode="markers+text" if text else "markers", **xyz(item.points),
                             marker=marker, **text, **_hover(item.hover, item.hover_xyz, decimals),
                             **_common(item, "points"))]
    if isinstance(item, Arrows):
        norms = np.linalg.norm(item.vectors, axis=1)
        # heads of one size, but at most half their arrow; none on an arrow of length 0
        head = np.minimum(item.head * (float(norms.max()) if norms.size else 0.0), 0.5 * norms)
        some = head > 0
        cone = item.vectors[some] * (head[some] / norms[some])[:, None]
        heads = {k: v for k, v in zip("uvw", xyz(cone).values())}
        shafts = go.Scatter3d(mode="lines", **xyz(_segments(item.origins, item.tips)),
                              line={"color": item.color, "width": item.width},
                              **_hover(None if item.hover is None
                                       else tuple(h for h in item.hover for _ in range(3))),
                              **_common(item, "shafts"))
        cones = go.Cone(**xyz(item.tips[some]), **heads, anchor="tip", sizemode="raw", sizeref=1.0,
                        colorscale=[[0, item.color], [1, item.color]], showscale=False,
                        showlegend=False, hoverinfo="skip", **_common(item, "heads"))
        return [shafts, cones]
    if isinstance(item, Triads):
        o = item.poses[:, :3, 3]
        length_mm = round(item.length * 1e3, decimals)
        axes = [go.Scatter3d(mode="lines", **xyz(_segments(o, item.axis_tips(k))),
                             line={"color": AXIS_COLORS[k], "width": 5}, showlegend=False,
                             hoverinfo="skip", **_common(item, "xyz"[k], length_mm=length_mm))
                for k in range(3)]
        origins = go.Scatter3d(mode="markers+text", **xyz(o), text=list(item.labels),
                               textposition="top right", marker={"size": 3, "color": "black"},
                               **_hover(item.hover), **_common(item, "origins"))
        return [*axes, origins]
    if isinstance(item, Mesh):
        return [go.Mesh3d(**xyz(item.vertices), i=item.faces[:, 0].tolist(),
                          j=item.faces[:, 1].tolist(), k=item.faces[:, 2].tolist(),
                          color=item.color, opacity=item.opacity, flatshading=True,
                          showlegend=True, **_hover((item.hover,) * len(item.vertices)
                                                   if item.hover else None),
                          **_common(item, "mesh"))]
    raise TypeError(f"not a scene item: {type(item).__name__}")


def _frames(go: Any, moving: list[list[Any]], index: list[int]) -> list[Any]:
    """Animation frames of the steps' traces: per trace only the attributes that differ between
    steps (plotly merges a frame into the traces it names; the rest stays as drawn)."""
    steps = [[t.to_plotly_json() for t in traces] for traces in moving]
    keys = [{k for k in first if any(s[j].get(k) != first[k] for s in steps[1:])} | {"type"}
            for j, first in enumerate(steps[0])]
    return [go.Frame(name=str(n), traces=index,
                     data=[{k: v for k, v in t.items() if k in keep} for t, keep in zip(s, keys)])
            for n, s in enumerate(steps)]


def _slider(scene: Scene) -> dict[str, Any]:
    """Layout of the slider and the play button that step through ``scene.steps``.

    A step of the slider names its frame and ``mode: immediate`` only (the frame is shown at
    once, interrupting the one before), so that a step costs about 60 bytes of the page.
    """
    still = {"mode": "immediate", "frame": {"duration": 0, "redraw": True},
             "transition": {"duration": 0}}
    play = {**still, "frame": {"duration": 400, "redraw": True}, "fromcurrent": True}
    step = {"mode": "immediate"}
    return {
        "sliders": [{"active": 0, "currentvalue": {"prefix": "point "}, "pad": {"t": 10},
                     "steps": [{"label": s.label, "method": "animate",
                                "args": [[str(k)], step]} for k, s in enumerate(scene.steps)]}],
        "updatemenus": [{"type": "buttons", "direction": "left", "x": 0, "y": 0,
                         "xanchor": "left", "yanchor": "top", "pad": {"t": 60},
                         "buttons": [{"label": "play", "method": "animate", "args": [None, play]},
                                     {"label": "pause", "method": "animate",
                                      "args": [[None], still]}]}],
    }


def scene_figure(scene: Scene) -> go.Figure:
    """A plotly figure of a scene, lengths in mm.

    Parameters
    ----------
    scene : Scene

    Returns
    -------
    plotly.graph_objects.Figure
        A 3D scene with equal scales on its axes; a legend entry per item (click to hide or
        show it); the notes under the title. With ``scene.steps``, the items of the first step
        are drawn and a slider (and a play button) replaces them by those of the others, as
        animation frames ``"0"``, ``"1"``, ... . In Jupyter the figure shows inline.
    """
    import plotly.graph_objects as go

    data = [t for item in scene.items for t in _traces(go, item, scene.decimals)]
    frames = []
    if scene.steps:
        moving = [[t for item in step.items for t in _traces(go, item, scene.decimals)]
                  for step in scene.steps]
        index = list(range(len(data), len(data) + len(moving[0])))
        data += moving[0]
        frames = _frames(go, moving, index)
    title = html.escape(scene.title)
    if scene.notes:
        title += "<br><sup>" + "<br>".join(html.escape(n) for n in scene.notes) + "</sup>"
    axes = {f"{c}axis": {"title": {"text": f"{c} in {scene.frame} (mm)"}} for c in "xyz"}
    layout: dict[str, Any] = {
        "template": "none", "title": {"text": title, "x": 0.01, "xanchor": "left"},
        "scene": {"aspectmode": "data", "camera": {"eye": CAMERA}, **axes},
        "legend": {"itemsizing": "constant"},
        "margin": {"l": 0, "r": 0, "t": 40 + 18 * len(scene.notes), "b": 0},
        "hoverlabel": {"align": "left"},
    }
    if scene.steps:
        layout.update(_slider(scene))
    return go.Figure(data=data, frames=frames, layout=layout)


def _html(figure: go.Figure | Scene, full_html: bool, height: str) -> str:
    """The figure as HTML with plotly.js inlined, opening on its first step (no autoplay).

    The animation frames are written without their trace ``type`` (plotly merges a frame into
    the trace it names, whose type is known), a few bytes of each frame of a long path.
    """
    import plotly.io as pio

    fig = (scene_figure(figure) if isinstance(figure, Scene) else figure).to_plotly_json()
    for frame in fig.get("frames", []):
        for trace in frame.get("data", []):
            trace.pop("type", None)
    return pio.to_html(fig, include_plotlyjs=True, full_html=full_html, default_height=height,
                       post_script=RENDERED, auto_play=False, validate=False,
                       config={"displaylogo": False, "responsive": True})


def page(figure: go.Figure | Scene, title: str | None = None) -> str:
    """One self-contained HTML page of a figure (or a scene), with plotly.js inlined.

    Parameters
    ----------
    figure : plotly.graph_objects.Figure or Scene
    title : str, optional
        Title of the page (default: the scene's title, or "robotcell view").

    Returns
    -------
    str
        The page: it needs no server and no network, and sets ``data-scene="rendered"`` on its
        ``<body>`` once the scene is drawn (:data:`RENDERED`). A path's animation does not play
        until asked.
    """
    if isinstance(figure, Scene):
        title = title or figure.title
    head = (f"<head><title>{html.escape(title or 'robotcell view')}</title>"
            "<style>body { margin: 0; overflow: hidden; }</style>")
    return _html(figure, True, "100vh").replace("<head>", head, 1)


def embed(figure: go.Figure | Scene, height: str = "600px") -> str:
    """A figure (or a scene) as a fragment of an HTML page: its ``<div>`` and the scripts that
    draw it, plotly.js inlined (include one fragment per page).

    Parameters
    ----------
    figure : plotly.graph_objects.Figure or Scene
    height : str
        CSS height of the figure.

    Returns
    -------
    str
        The fragment; once the scene is drawn it sets ``data-scene="rendered"`` on the page's
        ``<body>`` (:data:`RENDERED`).
    """
    return _html(figure, False, height)


def _light(scene: Scene) -> Scene:
    """The scene without the hover texts of its markers, lines and arrows (a template gives
    the markers' positions) and without arrow heads: about half the bytes of many touches."""
    items = [replace(i, hover=None, head=0.0) if isinstance(i, Arrows)
             else replace(i, hover=None) if isinstance(i, (Lines, Points)) else i
             for i in scene.items]
    notes = [*scene.notes, (f"hover texts and arrow heads left out, to keep the page under "
                            f"{MAX_PAGE_BYTES / 1e6:g} MB")]
    return Scene(scene.title, items, notes, scene.steps, scene.frame, scene.decimals)


def embed_within(scenes: Sequence[Scene], room: int, height: str = "600px"
                 ) -> tuple[str, Scene | None]:
    """The fragment of the first scene (:func:`embed`) that fits in ``room`` bytes of a page.

    Parameters
    ----------
    scenes : sequence of Scene
        The scene, then lighter ones of the same data (e.g. without residual vectors).
    room : int
        Bytes the page has left for the fragment (plotly.js inlined is 4.82 MB of it).
    height : str
        CSS height of the figure.

    Returns
    -------
    fragment : str
        The first of the scenes, each tried as it is and then without its hover texts and
        arrow heads (a note says so), that takes at most ``room`` bytes; empty if none does.
    drawn : Scene or None
        The scene drawn (its notes for the caption), None when nothing fits.
    """
    for scene in scenes:
        for drawn in (scene, _light(scene)):
            text = embed(drawn, height)
            if len(text.encode()) <= room:
                return text, drawn
    return "", None


def write_html(figure: go.Figure | Scene, path: str | Path, title: str | None = None) -> Path:
    """Write :func:`page` to ``path`` atomically (:func:`robotcell.io.fileio.atomic_write`).

    Parameters
    ----------
    figure : plotly.graph_objects.Figure or Scene
    path : str or Path
    title : str, optional

    Returns
    -------
    Path
        The file written.
    """
    atomic_write(path, page(figure, title))
    return Path(path)
