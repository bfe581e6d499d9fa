"""``robotcell cell``: inspect a cell file (mm, deg) and the versions its updates kept."""

from __future__ import annotations

import json
import math

import click

from robotcell.cell import Cell, Provenance, Turntable
from robotcell.cell.history import cell_history
from robotcell.cli.common import format_table
from robotcell.cli.files import Group
from robotcell.io.poseformats import pose_to_vendor


def _prov(p: Provenance) -> str:
    parts = [p.source]
    if p.rms_mm is not None:
        parts.append(f"rms {p.rms_mm:.3f} mm")
    if p.time:
        parts.append(p.time)
    return ", ".join(parts)


def _row(name: str, kind: str, number: object, T, p: Provenance) -> list[object]:
    return [name, kind, "" if number is None else number,
            *(float(v) for v in pose_to_vendor(T, "kuka")), _prov(p)]


@click.group(cls=Group)
def cell() -> None:
    """Inspect cell files and their history.

    \b
    Examples:
      robotcell cell show examples/cell_kr16_track_turntable.yaml
      robotcell cell history cell.yaml
    """


@cell.command()
@click.argument("path", type=click.Path(dir_okay=False))
def show(path: str) -> None:
    """Print the robot, track, turntable, tools and frames of a cell with their provenance.

    Poses are X, Y, Z (mm), A, B, C (deg) with R = Rz(A) Ry(B) Rx(C), each in its parent.

    \b
    Example:
      robotcell cell show examples/cell_kr16_track_turntable.yaml
    """
    c = Cell.load(path)
    click.echo(f"cell {c.name}: robot {c.nominal_robot.name} ({c.robot_model})")
    if c.identified is not None:
        p = c.identified.provenance
        click.echo(f"identified arm {c.robot.name} ({c.identified.model}): it says where the TCP "
                   f"goes, the nominal model what the controller is told; source {p.source}"
                   + (f", {p.time}" if p.time else "")
                   + (f", RMS {p.rms_mm:g} mm" if p.rms_mm is not None else "")
                   + (f"; {p.note}" if p.note else ""))
    head = ["name", "what (in parent)", "no.", "X", "Y", "Z", "A", "B", "C", "provenance"]
    rows: list[list[object]] = []
    if c.track is not None:
        t = c.track
        rows.append(_row(t.name, "track L (world)", None, t.T_world_L, t.provenance))
        rows.append(_row("", f"robot at 0 (L), axis {t.axis}", None, t.T_L_R0, t.provenance))
        click.echo(f"track {t.name}: {t.lower * 1e3:g} .. {t.upper * 1e3:g} mm, scale {t.scale:g}")
    else:
        rows.append(_row("robot", "robot R (world)", None, c.T_world_R, Provenance("nominal")))
    if isinstance(c.turntable, Turntable):
        b = c.turntable
        rows.append(_row(b.name, f"turntable B ({b.parent})", None, b.T_parent_B, b.provenance))
        click.echo(f"turntable {b.name}: {math.degrees(b.lower):g} .. {math.degrees(b.upper):g} deg")
    elif c.turntable is not None:
        p = c.turntable
        rows.append(_row(p.name, f"positioner root ({p.parent})", None, p.T_parent_root,
                         p.provenance))
        limits = ", ".join(f"{j.name} {math.degrees(j.lower):g} .. {math.degrees(j.upper):g}"
                           for j in p.chain.joints)
        click.echo(f"positioner {p.name}: {p.n_axes} axes, {limits} deg")
    for name, tool in c.tools.items():
        rows.append(_row(name, "tool (flange)", tool.number, tool.T_F_TCP, tool.provenance))
    for name, fr in c.frames.items():
        rows.append(_row(name, f"frame ({fr.parent})", fr.number, fr.pose, fr.provenance))
    click.echo(format_table(head, rows))


@cell.command()
@click.argument("path", type=click.Path(dir_okay=False))
@click.option("--json", "as_json", is_flag=True,
              help="Print every version in full as JSON: file, number, when written, the items "
                   "changed, and every item's provenance as written.")
def history(path: str, as_json: bool) -> None:
    """List the versions of a cell file that its updates kept, oldest first.

    Every update (calibrate ... --cell, Cell.save) first copies the file to the next numbered
    backup PATH.N.bak. Each version gets one line: the file, when it was written, and the items
    whose provenance changed from the version before, each with its procedure and residual RMS
    (the first version lists every item). --json gives every provenance field.

    \b
    Example:
      robotcell cell history cell.yaml
    """
    versions = cell_history(path)
    if as_json:
        click.echo(json.dumps({"cell": path, "versions": [v.to_json() for v in versions]},
                              indent=2))
        return
    names = [f"{v.path} (current)" if v.number is None else str(v.path) for v in versions]
    width = max(len(n) for n in names)
    click.echo(f"{len(versions)} version(s) of {path}, oldest first (--json for every "
               "provenance field):")
    for k, (name, v) in enumerate(zip(names, versions)):
        click.echo(f"{name.ljust(width)}  {v.modified}  {v.summary(first=k == 0)}")
