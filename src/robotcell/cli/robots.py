"""``robotcell robots``: list the robot library and show a model's DH table."""

from __future__ import annotations

import math

import click
import numpy as np

from robotcell.cli.common import format_table
from robotcell.cli.files import NAME_OR_FILE, Group
from robotcell.io.poseformats import pose_to_vendor
from robotcell.robot.models import list_robots, load_robot
from robotcell.robot.robot import Robot


@click.group(cls=Group, invoke_without_command=True)
@click.pass_context
def robots(ctx: click.Context) -> None:
    """List the built-in robot library.

    \b
    Examples:
      robotcell robots
      robotcell robots show kuka_kr16
    """
    if ctx.invoked_subcommand is not None:
        return
    rows = []
    for name in list_robots():
        r = load_robot(name)
        kinds = "".join("P" if j.prismatic else "R" for j in r.axes)
        rows.append((name, r.title, kinds, r.convention, coupling_summary(r), "yes" if r.verified else "no"))
    click.echo(format_table(("name", "robot", "axes", "DH", "coupling", "verified"), rows))


def coupling_summary(r: Robot) -> str:
    """``J23 +1`` for a J2/J3 linkage, ``matrix`` for another coupling, ``-`` for none."""
    if r.coupling is None:
        return "-"
    k = r.coupling.j23_factor
    if k is not None:
        return f"J23 {k:+g}"
    passive = len(r.joints) - r.n_joints
    return f"matrix, {passive} passive" if passive else "matrix"


@robots.command()
@click.argument("name", type=NAME_OR_FILE)
def show(name: str) -> None:
    """Print the DH table of a library robot or model file (mm, deg).

    \b
    Example:
      robotcell robots show ur5e
    """
    r = load_robot(name)
    chain = f" ({len(r.joints)} joints in the chain)" if len(r.joints) != r.n_joints else ""
    click.echo(f"{r.title} ({r.name}), {r.convention} DH, {r.n_joints} axes{chain}")
    if r.convention == "standard":
        click.echo("T_{i-1,i} = Trans(z, d) Rot(z, theta) Trans(x, a) Rot(x, alpha)")
        heads = ("joint", "type", "a [mm]", "alpha [deg]", "d [mm]", "theta [deg]")
    else:
        click.echo("T_{i-1,i} = Rot(x, alpha_{i-1}) Trans(x, a_{i-1}) Rot(z, theta) Trans(z, d)")
        heads = ("joint", "type", "a_{i-1} [mm]", "alpha_{i-1} [deg]", "d [mm]", "theta [deg]")
    click.echo("DH variable = sign * q + offset (theta for revolute, d for prismatic joints)")
    beta = any(j.beta for j in r.joints)
    if beta:
        click.echo("beta: Hayati's Rot(y, beta) after Rot(x, alpha) (an identified arm's nearly "
                   "parallel axes)")
    rows = []
    for j in r.joints:
        unit = 1e3 if j.prismatic else 180 / math.pi
        lo = f"{j.lower * unit:.1f}" if math.isfinite(j.lower) else "-inf"
        hi = f"{j.upper * unit:.1f}" if math.isfinite(j.upper) else "inf"
        rows.append((j.name, j.type, j.a * 1e3, math.degrees(j.alpha), j.d * 1e3,
                     math.degrees(j.theta)) + ((math.degrees(j.beta),) if beta else ())
                    + (f"{j.sign:+.0f}", "passive" if j.passive else f"{lo} .. {hi}",
                       "mm" if j.prismatic else "deg"))
    click.echo(format_table(heads + (("beta [deg]",) if beta else ()) + ("sign", "limits", "unit"),
                            rows))
    _show_coupling(r)
    for key, label in (("base", "base   T_R_0"), ("flange", "flange T_n_F"), ("tool", "tool   T_F_TCP")):
        v = pose_to_vendor(getattr(r, key), "kuka")
        click.echo(f"{label}: X {v[0]:.3f} Y {v[1]:.3f} Z {v[2]:.3f} mm, "
                   f"A {v[3]:.3f} B {v[4]:.3f} C {v[5]:.3f} deg")
    if r.home is not None:
        home = [v * (1e3 if j.prismatic else 180 / math.pi) for v, j in zip(r.home, r.axes)]
        click.echo("home (controller values): " + ", ".join(f"{v:g}" for v in home))
    click.echo(f"source: {r.source or 'not given'}")
    click.echo(f"verified: {'yes' if r.verified else 'no'}"
               + (f" ({r.verification})" if r.verification else ""))


def _show_coupling(r: Robot) -> None:
    """Print the coupling ``q_model = C q + offset`` in the file's units (mm, deg)."""
    c = r.coupling
    if c is None:
        click.echo("coupling: none (each joint is its controller axis; limits are on q)")
        return
    names = [j.name for j in r.axes]
    click.echo(f"coupling: q_model = C q + offset ({coupling_summary(r)}); q are the controller "
               "values (pendant), limits are on q")
    s_model = np.array([1e3 if j.prismatic else 180 / math.pi for j in r.joints])
    s_axis = np.array([1e3 if j.prismatic else 180 / math.pi for j in r.axes])
    C = c.matrix * s_model[:, None] / s_axis[None, :]
    rows = [(j.name, *(f"{v:g}" for v in row), f"{o:g}")
            for j, row, o in zip(r.joints, C, c.offset * s_model)]
    click.echo(format_table(("joint", *names, "offset"), rows))
    for a, lo, hi in zip(c.interaction, c.interaction_lower, c.interaction_upper):
        scale = 1e3 if r.axes[int(np.flatnonzero(a)[0])].prismatic else 180 / math.pi
        expr = " ".join(f"{v * s_axis[i] / scale:+g} {names[i]}" for i, v in enumerate(a) if v)
        click.echo(f"interaction limit: {lo * scale:g} <= {expr} <= {hi * scale:g}")
