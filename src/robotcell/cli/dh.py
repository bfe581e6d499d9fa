"""``robotcell dh``: the Denavit-Hartenberg procedure from the command line.

Terminal output and model files are in millimetres and degrees (see docs/dh-procedure.md).
"""

from __future__ import annotations

import math

import click

from robotcell.cli.common import as_flags, format_table, output_of, parse_numbers
from robotcell.cli.files import NAME_OR_FILE, OUTPUT, Group
from robotcell.dhprocedure import (
    AxisChain,
    DHDerivation,
    convert_convention,
    dh_from_axes,
    dh_from_urdf,
    symbolic_arm,
)
from robotcell.dhprocedure.exactness import EXACT_TOL
from robotcell.io.poseformats import pose_to_vendor
from robotcell.robot.models import load_robot, save_robot
from robotcell.robot.robot import Joint, Robot

_CONVENTION = click.Choice(["standard", "modified"])


@click.group(cls=Group)
def dh() -> None:
    """Denavit-Hartenberg procedure: DH tables from URDF, conversions, explanations, algebra.

    \b
    Examples:
      robotcell dh from-urdf arm.urdf -o arm.yaml
      robotcell dh convert kuka_kr16 --to modified
      robotcell dh explain ur5e
      robotcell dh symbolic puma560 --latex
    """


@dh.command("from-urdf")
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--convention", type=_CONVENTION, default="standard", show_default=True,
              help="DH convention of the model.")
@click.option("--base-link", default=None, help="First link of the chain (default: the root).")
@click.option("--tip-link", default=None,
              help="Last link (default: the only leaf; needed when the tree branches).")
@click.option("--signs", default=None,
              help="Sign corrections, one +1/-1 per joint: -1 points Z against the URDF axis.")
@click.option("-o", "--output", type=OUTPUT, default=None,
              callback=output_of("YAML", "the model file"),
              help="Write the model file (YAML, mm/deg) here, atomically.")
def from_urdf(file: str, convention: str, base_link: str | None, tip_link: str | None,
              signs: str | None, output: str | None) -> None:
    """Derive the DH model of the serial chain in a URDF FILE.

    Needs the optional URDF parser: pip install 'robotcell[urdf]'. Fixed joints are merged;
    the model's base frame is the base link, its flange the tip link. Prints the table and,
    frame by frame, which case of the procedure applied.

    \b
    Example:
      robotcell dh from-urdf ur5e.urdf --convention modified -o ur5e_mdh.yaml
      robotcell dh from-urdf kr6.urdf --tip-link flange --signs=-1,1,1,-1,1,-1
    """
    sign_list = parse_numbers(signs, "--signs") if signs is not None else None
    with as_flags({"give base_link": "give base_link (--base-link)",
                   "with tip_link": "with tip_link (--tip-link)"}):
        der = dh_from_urdf(file, convention, base_link=base_link, tip_link=tip_link,
                           signs=sign_list)
    click.echo(_report(der))
    if output:
        save_robot(der.robot, output)
        click.echo(f"model written to {output}")


@dh.command()
@click.argument("model", type=NAME_OR_FILE)
@click.option("--to", "target", type=_CONVENTION, required=True, help="Target convention.")
@click.option("-o", "--output", type=OUTPUT, default=None,
              callback=output_of("YAML", "the model file"),
              help="Write the converted model file (YAML, mm/deg) here, atomically.")
def convert(model: str, target: str, output: str | None) -> None:
    """Convert MODEL (library name or model file) between standard and modified DH.

    Exact: the converted model has the same forward kinematics for every joint value. theta
    and d stay in their rows, a and alpha move by one row, base or flange absorb the rest.

    \b
    Example:
      robotcell dh convert kuka_kr16 --to modified -o kr16_mdh.yaml
    """
    robot = load_robot(model)
    out = convert_convention(robot, target)
    click.echo(_table(out))
    if output:
        save_robot(out, output)
        click.echo(f"model written to {output}")


@dh.command()
@click.argument("model", type=NAME_OR_FILE)
@click.option("--convention", type=_CONVENTION, default=None,
              help="Convention of the derivation (default: the model's; standard for URDF).")
def explain(model: str, convention: str | None) -> None:
    """Derive MODEL's DH frames by the procedure and explain each frame.

    MODEL is a library name, a model file or a URDF file. The procedure runs on the joint axes
    of the model at zero (with the model's sign corrections), says which case applied to every
    frame and why, and compares the derived table with the model's own.

    \b
    Example:
      robotcell dh explain kuka_kr6_r700_sixx
      robotcell dh explain arm.urdf --convention modified
    """
    if model.lower().endswith(".urdf"):
        click.echo(_report(dh_from_urdf(model, convention or "standard")))
        return
    robot = load_robot(model)
    der = dh_from_axes(AxisChain.from_robot(robot), convention or robot.convention,
                       signs=[j.sign for j in robot.joints], name=robot.name, title=robot.title)
    click.echo(_report(der))
    if der.robot.convention != robot.convention:
        return
    same = [_same_row(a, b) for a, b in zip(der.robot.joints, robot.joints)]
    if all(same):
        click.echo(f"\nThe derived table equals the table of {robot.name}.")
    else:
        rows = ", ".join(str(i) for i, s in enumerate(same, 1) if not s)
        click.echo(f"\nRow(s) {rows} differ from the table of {robot.name}: the model made other "
                   "free choices (X direction, origin on parallel axes, frames 0 and n); both "
                   f"describe the same robot. The table of {robot.name}:")
        click.echo(_table(robot))


@dh.command()
@click.argument("model", type=NAME_OR_FILE)
@click.option("--latex", is_flag=True, help="Print LaTeX instead of text.")
@click.option("--numeric", is_flag=True,
              help="Substitute the lengths (mm) and angles instead of keeping a_i, d_i symbols.")
def symbolic(model: str, latex: bool, numeric: bool) -> None:
    """Adjacent transforms T_{i-1,i} and the arm matrix T_0_n of MODEL, symbolically.

    Needs sympy: pip install 'robotcell[symbolic]'. The joint variables are the DH variables
    theta_i (revolute) and d_i (prismatic); base and flange transforms are not included.

    \b
    Example:
      robotcell dh symbolic ur5e
      robotcell dh symbolic puma560 --numeric --latex
    """
    sym = symbolic_arm(load_robot(model), numeric=numeric, unit="mm")
    click.echo(sym.to_latex() if latex else sym.to_text())


def _same_row(a: Joint, b: Joint, tol: float = 1e-9) -> bool:
    """Whether two joints have the same DH row (angles compared modulo 2 pi)."""
    def ang(x: float, y: float) -> bool:
        return abs(math.remainder(x - y, 2 * math.pi)) < tol
    return (abs(a.a - b.a) < tol and abs(a.d - b.d) < tol and ang(a.alpha, b.alpha)
            and ang(a.theta, b.theta) and ang(a.beta, b.beta) and a.sign == b.sign)


def _table(robot: Robot) -> str:
    """The DH table, base and flange of ``robot`` in mm and degrees (a beta column if any)."""
    beta = any(j.beta for j in robot.joints)
    ry = " Rot(y, beta)" if beta else ""
    if robot.convention == "standard":
        lines = [f"standard DH: T_{{i-1,i}} = Trans(z, d) Rot(z, theta) Trans(x, a) Rot(x, alpha){ry}"]
        heads = ("i", "joint", "type", "a [mm]", "alpha [deg]", "d [mm]", "theta [deg]")
    else:
        lines = [(f"modified DH: T_{{i-1,i}} = Rot(x, alpha_{{i-1}}){ry} Trans(x, a_{{i-1}}) "
                  "Rot(z, theta) Trans(z, d)")]
        heads = ("i", "joint", "type", "a_{i-1} [mm]", "alpha_{i-1} [deg]", "d [mm]",
                 "theta [deg]")
    heads += ("beta [deg]",) * beta + ("sign",)
    # beta with its significant digits: a tilt of 1e-7 deg is what makes the model exact
    rows = [(i, j.name, j.type, _z(j.a * 1e3), _z(math.degrees(j.alpha)), _z(j.d * 1e3),
             _z(math.degrees(j.theta))) + (f"{math.degrees(j.beta):.6g}",) * beta
            + (f"{j.sign:+.0f}",) for i, j in enumerate(robot.joints, 1)]
    lines.append(format_table(heads, rows))
    for key, label in (("base", "base   T_R_0"), ("flange", "flange T_n_F")):
        v = [_z(x) for x in pose_to_vendor(getattr(robot, key), "kuka")]
        lines.append(f"{label}: X {v[0]:.3f} Y {v[1]:.3f} Z {v[2]:.3f} mm, "
                     f"A {v[3]:.3f} B {v[4]:.3f} C {v[5]:.3f} deg")
    return "\n".join(lines)


def _z(v: float) -> float:
    """``v`` with rounding noise and negative zero removed, for printing."""
    r = round(v, 9)
    return 0.0 if r == 0 else r


def _report(der: DHDerivation) -> str:
    """Table plus one explanation per frame."""
    lines = [f"{der.robot.title or der.robot.name}: DH procedure", _table(der.robot),
             (f"check: as a model file holds it (mm, degrees), the model moves like its source "
              f"to {der.deviation:.1e} m and rad (at most {EXACT_TOL:g})"), "", "frames:"]
    for note in der.notes:
        lines.append(f"  {note.index} [{note.case}] {note.text}")
    return "\n".join(lines)

