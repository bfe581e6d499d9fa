"""HTML report of an ISO 9283 acceptance test: one self-contained page.

The verdict against the limits, the figures per pose, distance and path as tables, the measured
points around each commanded pose (magnified) and the path deviations along each path as
figures (PNG ``data:`` URIs, :mod:`robotcell.report.page`), and, given the cell, the 3D scene of
the test cube in the cell with the arm at P1 (:mod:`robotcell.view`).
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.cell import Cell
from robotcell.io.fileio import atomic_write
from robotcell.iso9283 import Iso9283Result
from robotcell.iso9283.cube import cube_corners
from robotcell.report.page import CSS, SCENE_SLOT, SCRIPT, png, scene_figure, table
from robotcell.view.cellscene import cell_scene
from robotcell.view.plot import MAX_PAGE_BYTES
from robotcell.view.pyplot import pyplot
from robotcell.view.scene import Lines, Points, Scene
from robotcell.view.shapes import magnification

__all__ = ["write_iso9283_report"]

_LEVEL_CLASS = {"pass": "good", "fail": "poor", "none": "check"}


def _pose_figure(result: Iso9283Result) -> str:
    """Per pose, the measured points around the command (+): x-y, z as colour, the barycentre
    and the circle of radius RP_l around it in red (mm)."""
    plt = pyplot()
    n = len(result.poses)
    fig, axes = plt.subplots(1, n, figsize=(1.9 * n, 2.5), squeeze=False, layout="constrained")
    dz = np.concatenate([(r.p[:, 2] - r.command[2]) * 1e3 for r in result.poses])
    lim = max(float(np.abs(dz).max()), 1e-6)
    t = np.linspace(0, 2 * np.pi, 60)
    for ax, r in zip(axes[0], result.poses):
        d = (r.p - r.command) * 1e3
        bar, rp = r.figures.AP * 1e3, r.figures.RP_l * 1e3
        sc = ax.scatter(d[:, 0], d[:, 1], c=d[:, 2], s=4, cmap="coolwarm", vmin=-lim, vmax=lim)
        ax.plot([0], [0], "k+", ms=9)
        ax.plot([bar[0]], [bar[1]], "o", ms=4, color="tab:red")
        ax.plot(bar[0] + rp * np.cos(t), bar[1] + rp * np.sin(t), "-", lw=0.8, color="tab:red")
        ax.set_aspect("equal", adjustable="datalim")
        ax.tick_params(labelsize=6)
        ax.set_xlabel("dx [mm]", fontsize=7)
        ax.set_title(r.pose, fontsize=8)
    axes[0, 0].set_ylabel("dy [mm]", fontsize=7)
    fig.colorbar(sc, ax=axes[0].tolist(), shrink=0.8).set_label("dz [mm]", fontsize=7)
    return png(fig)


def _path_figure(result: Iso9283Result) -> str:
    """Per path, the deviation of the barycentre and the repeatability along it (mm)."""
    plt = pyplot()
    fig, axes = plt.subplots(1, len(result.paths), figsize=(3.6 * len(result.paths), 2.3),
                             squeeze=False)
    for ax, r in zip(axes[0], result.paths):
        k = np.arange(1, len(r.names) + 1)
        ax.plot(k, r.figures.deviation * 1e3, "o-", ms=3, label="|barycentre - command|")
        ax.plot(k, r.figures.repeatability * 1e3, "s-", ms=3, label="l + 3 S_l")
        ax.set_xlabel(f"point of the {r.path}", fontsize=7)
        ax.set_ylabel("mm", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.legend(fontsize=6)
    fig.tight_layout()
    return png(fig)


def _edges(corners: NDArray[np.float64]) -> NDArray[np.float64]:
    """The cube's twelve edges as one polyline broken by NaN rows."""
    d = np.linalg.norm(corners[:, None] - corners[None], axis=-1)
    edge = np.min(d[d > 0])
    rows = [np.vstack([corners[i], corners[j], np.full(3, np.nan)])
            for i in range(8) for j in range(i + 1, 8) if abs(d[i, j] - edge) < 1e-6 * edge + 1e-9]
    return np.vstack(rows)


def _scene(result: Iso9283Result, cell: Cell) -> Scene:
    """The cell with the arm at P1, the test cube, the commands and the measurements
    magnified, in the world."""
    plan = result.plan
    track = 0.0 if plan.track is None else plan.track
    table = 0.0 if plan.table is None else plan.table
    sol = cell.ik(plan.poses[0], plan.frame, None if cell.track is None else track, table,
                  plan.tool)
    q = sol.q[np.argmax(sol.valid)] if sol.valid.any() else None
    scene = cell_scene(cell, q, track, table)
    T = cell.frame_pose(plan.frame, track, table)

    def world(p: NDArray[np.float64]) -> NDArray[np.float64]:
        return p @ T[:3, :3].T + T[:3, 3]

    corners = cube_corners(plan.poses[:, :3, 3])
    cmd = np.array([r.command for r in result.poses])
    dev = np.vstack([r.p - r.command for r in result.poses])
    factor = magnification(dev, plan.size, share=0.05)
    scene.items += [
        Lines("test cube", world(_edges(corners)), color="darkorange", width=3.0),
        Lines("test plane", world(np.vstack([corners[:4], corners[:1]])), color="orange",
              width=2.0, dash="dash"),
        Points("commanded poses", world(cmd), color="black", size=5, symbol="cross",
               labels=[r.pose for r in result.poses]),
        Points("measured cycles (magnified)",
               world(np.vstack([r.command + factor * (r.p - r.command) for r in result.poses])),
               color="steelblue", size=2),
        Points("barycentres (magnified)",
               world(np.array([r.command + factor * r.figures.AP for r in result.poses])),
               color="crimson", size=5,
               hover=[f"{r.pose}: AP_p {r.figures.AP_p * 1e3:.3f} mm, RP_l "
                      f"{r.figures.RP_l * 1e3:.3f} mm" for r in result.poses]),
    ]
    for r in result.paths:
        scene.items.append(Lines(f"{r.path}: command", world(r.command), color="gray", width=2.0))
        scene.items.append(Lines(f"{r.path}: barycentre (magnified)",
                                 world(r.command + factor * (r.figures.barycentre - r.command)),
                                 color="crimson", width=2.0))
    scene.notes.append(f"measured points drawn at the command plus {factor:g} x their deviation")
    return scene


def _pose_rows(result: Iso9283Result) -> tuple[list[str], list[list[object]]]:
    oriented = all(r.AP_abc is not None for r in result.poses)
    head = ["pose", "cycles", "AP_p (mm)", "AP_x (mm)", "AP_y (mm)", "AP_z (mm)", "RP_l (mm)"]
    if oriented:
        head += ["AP_a, AP_b, AP_c (deg)", "RP_a, RP_b, RP_c (deg)"]
    head += ["drift dAP_p, dRP_l (mm)"]
    rows = []
    for r in result.poses:
        f = r.figures
        row: list[object] = [r.pose, len(r.p), f.AP_p * 1e3, *(f.AP * 1e3).tolist(), f.RP_l * 1e3]
        if oriented:
            row += [np.degrees(r.AP_abc).tolist(), ["±" + f"{v:.4f}" for v in
                                                    np.degrees(r.RP_abc)]]
        row.append("-" if r.drift is None else [r.drift[0] * 1e3, r.drift[1] * 1e3])
        rows.append(row)
    return head, rows


def write_iso9283_report(path: str | Path, result: Iso9283Result, cell: Cell | None = None
                         ) -> Path:
    """Write the report page (atomically; nothing else is written).

    Parameters
    ----------
    path : str or Path
        The HTML file.
    result : Iso9283Result
    cell : Cell, optional
        The cell tested: its 3D scene with the test cube (none without it).

    Returns
    -------
    Path
    """
    plan, v = result.plan, result.verdict
    where = [f"frame {plan.frame}", f"tool {plan.tool}", f"cube edge {plan.size * 1e3:.1f} mm"]
    if plan.track is not None:
        where.append(f"track {plan.track * 1e3:g} mm")
    if plan.table is not None:
        where.append(f"table {np.degrees(np.atleast_1d(plan.table)).round(3).tolist()} deg")
    head, rows = _pose_rows(result)
    intro = (f"<p>Log {html.escape(result.source)}; {html.escape(', '.join(where))}. Figures as "
             "ISO 9283 defines them (the formulas and their sources: docs/iso9283.md).</p>")
    parts = [intro,
             "<h2>Poses</h2>", table(head, rows),
             f'<figure><img src="{_pose_figure(result)}" alt="measured points per pose"></figure>']
    if result.distances:
        parts += ["<h2>Distances from P1</h2>", table(
            ["to", "cycles", "commanded (mm)", "AD_p (mm)", "RD_p (mm)"],
            [[d.pose, d.cycles, d.D_c * 1e3, d.AD_p * 1e3, "±" + f"{d.RD_p * 1e3:.4f}"]
             for d in result.distances])]
    if result.paths:
        parts += ["<h2>Paths</h2>", table(
            ["path", "cycles", "points", "AT_p (mm)", "RT_p (mm)", "AT_a, AT_b, AT_c (deg)"],
            [[r.path, r.cycles, len(r.names), r.figures.AT_p * 1e3, r.figures.RT_p * 1e3,
              "" if r.AT_abc is None else ", ".join(f"{v:.4f}" for v in np.degrees(r.AT_abc))]
             for r in result.paths]),
            f'<figure><img src="{_path_figure(result)}" alt="path deviations"></figure>']
    j = result.to_json()
    if j["device_frame"] is not None:
        parts.append(f"<p>Device frame fitted: {html.escape(str(j['device_frame']))}.</p>")
    if result.notes:
        parts.append("<ul>" + "".join(f"<li>{html.escape(n)}</li>" for n in result.notes)
                     + "</ul>")
    if cell is not None:
        parts += ["<h2>3D view</h2>", SCENE_SLOT]
    name = html.escape(cell.name if cell is not None else result.source)
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>robotcell ISO 9283: {name}</title>
<style>{CSS}</style><script>{SCRIPT}</script></head>
<body>
<h1>ISO 9283 acceptance test of {name}</h1>
<p class="verdict {_LEVEL_CLASS[v.level]}">{html.escape(v.line())}</p>
{''.join(parts)}
</body></html>
"""
    if cell is not None:
        figure = scene_figure([_scene(result, cell)], MAX_PAGE_BYTES - len(page.encode()),
                              "the test cube, its commands and the measurements")
        page = page.replace(SCENE_SLOT, figure, 1)
    out = Path(path)
    atomic_write(out, page)
    return out
