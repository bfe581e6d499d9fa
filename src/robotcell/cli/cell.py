"""``robotcell cell``: inspect a cell file (mm, deg) and the versions its updates kept."""

from __future__ import annotations

import json
import math

import click

from robotcell.cell import DEFAULT_ROBOT, Cell, Provenance, Turntable
from robotcell.cell.history import cell_history
from robotcell.cli.common import format_table
from robotcell.cli.files import Group
from robotcell.cli.robotname import robot_name, robot_name_option, robot_of
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
@robot_name_option
def show(path: str) -> None:
    """Print the robot, track, turntable, tools and frames of a cell with their provenance.

    Poses are X, Y, Z (mm), A, B, C (deg) with R = Rz(A) Ry(B) Rx(C), each in its parent. A cell
    of several robots lists each robot (its base or track, and its tools), then the shared
    turntable or positioner and frames; --robot-name NAME lists one robot as it sees the cell.

    \b
    Example:
      robotcell cell show examples/cell_kr16_track_turntable.yaml
    """
    c = Cell.load(path)
    if len(c.robots) > 1 and robot_name() is None:
        click.echo(f"cell {c.name}: {len(c.robots)} robots ({', '.join(c.robots)})")
        for name in c.robot_names:
            base, tools = _show_robot(c.for_robot(name))
            click.echo(format_table(_HEAD, base + tools))
        click.echo("shared by the robots:")
        rows = _axes_rows(c)
        rows += [_row(n, f"frame ({fr.parent})", fr.number, fr.pose, fr.provenance)
                 for n, fr in c.frames.items()]
        click.echo(format_table(_HEAD, rows))
        return
    view = c.for_robot(robot_of(c, path))
    base, tools = _show_robot(view)
    rows = base + _axes_rows(view) + tools
    for name, fr in view.frames.items():
        rows.append(_row(name, f"frame ({fr.parent})", fr.number, fr.pose, fr.provenance))
    click.echo(format_table(_HEAD, rows))


_HEAD = ["name", "what (in parent)", "no.", "X", "Y", "Z", "A", "B", "C", "provenance"]


def _show_robot(c: Cell) -> tuple[list[list[object]], list[list[object]]]:
    """Print a one-robot cell's robot line; the rows of its base or track, and of its tools."""
    rows: list[list[object]] = []
    label = "" if c.robot_name == DEFAULT_ROBOT else f" {c.robot_name}"
    click.echo(f"cell {c.name}: robot{label} {c.nominal_robot.name} ({c.robot_model})")
    if c.identified is not None:
        p = c.identified.provenance
        click.echo(f"identified arm {c.robot.name} ({c.identified.model}): it says where the TCP "
                   f"goes, the nominal model what the controller is told; source {p.source}"
                   + (f", {p.time}" if p.time else "")
                   + (f", RMS {p.rms_mm:g} mm" if p.rms_mm is not None else "")
                   + (f"; {p.note}" if p.note else ""))
    if c.track is not None:
        t = c.track
        rows.append(_row(t.name, "track L (world)", None, t.T_world_L, t.provenance))
        rows.append(_row("", f"robot at 0 (L), axis {t.axis}", None, t.T_L_R0, t.provenance))
        click.echo(f"track {t.name}: {t.lower * 1e3:g} .. {t.upper * 1e3:g} mm, scale {t.scale:g}")
    else:
        rows.append(_row("robot", "robot R (world)", None, c.T_world_R,
                         c.robots[c.robot_name].base_provenance))
    return rows, [_row(name, "tool (flange)", tool.number, tool.T_F_TCP, tool.provenance)
                  for name, tool in c.tools.items()]


def _axes_rows(c: Cell) -> list[list[object]]:
    """Rows of the turntable or positioner (the limits printed as a line)."""
    rows: list[list[object]] = []
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
    return rows


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
