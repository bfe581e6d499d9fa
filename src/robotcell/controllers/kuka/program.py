"""KUKA KRL programs: ``NAME.src`` (the motions) and ``NAME.dat`` (the points), both ways.

Written (sources in ``docs/programs.md``):

- ``NAME.src``: ``DEF NAME( )``, the initialisation that pendant-made programs start with
  (``BAS (#INITMOV,0 )`` after the stop interrupt), ``$TOOL=TOOL_DATA[n]``, ``$BASE=BASE_DATA[n]``
  for a base fixed in the cell or ``$BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,
  BASE_DATA[n])`` for a base on the turntable (the numbers of ``robotcell export``),
  ``$ACT_EX_AX=n``, the number of external axes the program moves (track and table axes, as
  RoboDK's KUKA posts write it), ``$VEL.CP`` (m/s), ``$APO.CDIS`` (mm), then ``PTP XPi`` / ``LIN XPi`` (``C_DIS`` where the zone
  is not 0) and ``END``.
- ``NAME.dat``: ``DEFDAT NAME`` with one ``DECL E6POS XPi={X ..,Y ..,Z ..,A ..,B ..,C ..,S ..,
  T ..,E1 ..,...,E6 ..}`` per point (mm, deg; ``R = Rz(A) Ry(B) Rx(C)``) and ``ENDDAT``.

Read: the same, and the common subset that pendants and offline tools write: the inline forms
(``FDAT_ACT=FPi`` with ``DECL FDAT``, ``PDAT``/``LDAT``), ``BAS(#TOOL,n)``, ``BAS(#BASE,n)``,
``$TOOL``/``$BASE`` given as frames, points as ``E6POS``, ``POS``, ``FRAME``, ``E6AXIS`` or
``AXIS``, declared in the ``.dat`` or written inline (``PTP {A1 0,...}``), typed aggregates
(``{E6POS: X 1,...}``), lower-case fields, ``S``/``T`` as decimals or as ``'B110'``, missing
``S``/``T``, ``SPTP``/``SLIN``, and Latin-1 text. ``PTP HOME`` and ``PTP $AXIS_ACT`` move to
points the program does not hold and are skipped (named in what :func:`read` returns).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robotcell.controllers.data import DEG_DECIMALS, MM_DECIMALS
from robotcell.controllers.kuka.export import MACHINE_INDEX
from robotcell.controllers.model import FLAG_LIMIT, PTP_SPEED, Config, Program, ProgramPoint, Ref
from robotcell.controllers.text import JOINT_DECIMALS, NUMBER, Lines, fmt_num, strip_comment
from robotcell.errors import InputError
from robotcell.io.poseformats import pose_from_vendor, pose_to_vendor
from robotcell.io.tables import MAX_ABS_VALUE

__all__ = ["config_text", "read", "set_joints", "set_pose", "write"]

_POSE_KEYS = ("X", "Y", "Z", "A", "B", "C")
_AXIS_KEYS = tuple(f"A{i}" for i in range(1, 7))
_EXT_KEYS = tuple(f"E{i}" for i in range(1, 7))
_CARTESIAN = {"E6POS", "POS", "FRAME"}
_JOINT = {"E6AXIS", "AXIS"}


# -- writing -------------------------------------------------------------------------------------
def config_text(values: tuple[int, ...]) -> str:
    """Status and Turn as an ``E6POS`` writes them: ``S 6,T 50``."""
    return f"S {values[0]},T {values[1]}"


def _aggregate(p: ProgramPoint) -> str:
    assert p.pose is not None and p.config is not None
    v = pose_to_vendor(p.pose, "kuka")
    parts = [f"{k} {fmt_num(x, MM_DECIMALS if i < 3 else DEG_DECIMALS)}"
             for i, (k, x) in enumerate(zip(_POSE_KEYS, v))]
    parts.append(config_text(p.config.values))
    parts += [f"{k} {fmt_num(p.external.get(k, 0.0), DEG_DECIMALS)}" for k in _EXT_KEYS]
    return "{" + ",".join(parts) + "}"


def _base_line(ref: Ref) -> str:
    if ref.number in (None, 0):
        return "$BASE=$NULLFRAME"
    if ref.on_table:
        m = MACHINE_INDEX
        return (f"$BASE=EK(MACHINE_DEF[{m}].ROOT,MACHINE_DEF[{m}].MECH_TYPE,"
                f"BASE_DATA[{ref.number}])")
    return f"$BASE=BASE_DATA[{ref.number}]"


def _external_axes(program: Program) -> int:
    """The number of external axes the program moves: the track and the table's axes it
    writes (``E1``..), the unused ones (written as 0) left out."""
    return len({k for p in program.points for k in p.external})


def write(program: Program, header: list[str]) -> dict[str, str]:
    """``NAME.src`` and ``NAME.dat`` of a program of Cartesian points.

    Parameters
    ----------
    program : Program
        Points with ``pose``, ``config`` (KUKA S/T) and ``external`` (``E1``..), one tool and
        one base.
    header : list of str
        Comment lines (without ``;``) that say where the program comes from.

    Returns
    -------
    dict of str to str
        File name -> text.
    """
    name = program.name
    first = program.points[0]
    src = ["&ACCESS RVP", "&REL 1", f"DEF {name}( )", *(f"; {h}" for h in header),
           (f"; points: {name}.dat (X, Y, Z mm, A, B, C deg with R = Rz(A) Ry(B) Rx(C) in "
            "the base; S, T; E1..E6)"),
           ";FOLD INI", "  ;FOLD BASISTECH INI",
           "    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
           "    INTERRUPT ON 3", "    BAS (#INITMOV,0 )", "  ;ENDFOLD (BASISTECH INI)",
           ";ENDFOLD (INI)",
           f"$TOOL=TOOL_DATA[{first.tool.number}]  ; {first.tool.name}",
           _base_line(first.frame) + (f"  ; {first.frame.name}" if first.frame.name else "")]
    axes = _external_axes(program)
    if axes:
        src.append(f"$ACT_EX_AX={axes}")
    speed = zone = None
    for i, p in enumerate(program.points):
        if p.motion == "lin" and p.speed is not None and p.speed != speed:
            src.append(f"$VEL.CP={p.speed:.6g}")
            speed = p.speed
        if p.motion == "ptp" and i == 0:
            src.append(f"BAS(#VEL_PTP,{PTP_SPEED * 100:.0f})")
        z = p.zone or 0.0
        if z > 0 and z != zone:
            src.append(f"$APO.CDIS={z * 1e3:.6g}")
            zone = z
        src.append(f"{p.motion.upper()} {p.name}" + (" C_DIS" if z > 0 else ""))
    src.append("END")
    dat = ["&ACCESS RVP", "&REL 1", f"DEFDAT {name}", *(f"; {h}" for h in header)]
    dat += [f"DECL E6POS {p.name}={_aggregate(p)}" for p in program.points]
    dat.append("ENDDAT")
    return {f"{name}.src": "\n".join(src) + "\n", f"{name}.dat": "\n".join(dat) + "\n"}


# -- reading -------------------------------------------------------------------------------------
_DECL_RE = re.compile(r"^\s*(?:DECL\s+)?(?:GLOBAL\s+)?(E6POS|POS|FRAME|E6AXIS|AXIS|FDAT|PDAT|LDAT)"
                      r"\s+(\w+)\s*=\s*(.*)$", re.IGNORECASE)
_ITEM_RE = re.compile(r"^\s*([A-Za-z_$][\w\[\]$]*)\s*(.*?)\s*$")
_MOVE_RE = re.compile(r"^\s*(S?PTP|S?LIN)\s+(.*)$", re.IGNORECASE)
_CIRC_RE = re.compile(r"^\s*S?CIRC\b", re.IGNORECASE)
_TOOL_RE = re.compile(r"^\s*\$TOOL\s*=\s*(.*)$", re.IGNORECASE)
_BASE_RE = re.compile(r"^\s*\$BASE\s*=\s*(.*)$", re.IGNORECASE)
_BAS_RE = re.compile(r"^\s*BAS\s*\(\s*#(TOOL|BASE)\s*,\s*(\d+)\s*\)", re.IGNORECASE)
_EK_RE = re.compile(r"^EK\s*\(.*?,\s*BASE_DATA\s*\[\s*(\d+)\s*\]\s*\)$", re.IGNORECASE)
_DATA_RE = re.compile(r"^(TOOL_DATA|BASE_DATA)\s*\[\s*(\d+)\s*\]$", re.IGNORECASE)
_FDAT_ACT_RE = re.compile(r"^\s*FDAT_ACT\s*=\s*(\w+)", re.IGNORECASE)
_LDAT_ACT_RE = re.compile(r"^\s*(LDAT_ACT|PDAT_ACT)\s*=\s*(\w+)", re.IGNORECASE)
_VEL_RE = re.compile(r"^\s*\$VEL\.CP\s*=\s*([-+0-9.eE]+)\s*$", re.IGNORECASE)
_APO_RE = re.compile(r"^\s*\$APO\.CDIS\s*=\s*([-+0-9.eE]+)\s*$", re.IGNORECASE)


def _split_items(body: str) -> list[str]:
    """Top-level comma-separated items of an aggregate's inside (quotes and braces kept)."""
    items, depth, quoted, cur = [], 0, False, []
    for ch in body:
        if ch == '"':
            quoted = not quoted
        elif not quoted and ch == "{":
            depth += 1
        elif not quoted and ch == "}":
            depth -= 1
        if ch == "," and depth == 0 and not quoted:
            items.append("".join(cur))
            cur = []
        else:
            cur.append(ch)
    items.append("".join(cur))
    return [i for i in items if i.strip()]


def _aggregate_fields(text: str, lines: Lines, lineno: int) -> tuple[str | None, dict[str, str]]:
    """``{[TYPE:] K v, ...}`` -> (TYPE or None, {K (upper): v}); an unclosed brace is an error."""
    t = text.strip()
    if not t.startswith("{"):
        raise lines.error(lineno, f"expected an aggregate {{...}}, got {t[:40]!r}")
    if not t.endswith("}"):
        raise lines.error(lineno, "the aggregate is not closed with '}' (truncated file?)")
    body = t[1:-1]
    typ = None
    m = re.match(r"^\s*(\w+)\s*:(.*)$", body, re.DOTALL)
    if m and m.group(1).upper() not in ("S", "T"):
        typ, body = m.group(1).upper(), m.group(2)
    fields = {}
    for item in _split_items(body):
        im = _ITEM_RE.match(item)
        if not im:
            raise lines.error(lineno, f"cannot read {item.strip()!r} in the aggregate")
        fields[im.group(1).upper()] = im.group(2)
    return typ, fields


def _int_value(text: str, lines: Lines, lineno: int) -> int:
    """``6``, ``'B110'`` (binary) or ``'H6'`` (hexadecimal) as an integer."""
    t = text.strip().strip("'")
    try:
        if t[:1] in "Bb" and len(t) > 1:
            v = lines.integer(t[1:], lineno, 2)
        elif t[:1] in "Hh" and len(t) > 1:
            v = lines.integer(t[1:], lineno, 16)
        else:
            f = float(t)
            if not abs(f) <= MAX_ABS_VALUE:  # NaN, infinite, 1e300
                raise ValueError(t)
            v = int(f)
    except ValueError:
        v = FLAG_LIMIT
    if abs(v) >= FLAG_LIMIT:
        raise lines.error(lineno, f"{text.strip()!r} is not a status or turn value")
    return v


class _Point:
    """A point value: Cartesian (pose, config) or joints, with its external axes."""

    def __init__(self, kind: str, fields: dict[str, str], lines: Lines, lineno: int,
                 name: str) -> None:
        def num(key: str) -> float:
            return lines.number(fields[key], lineno)

        self.where = lines.where(lineno)
        self.external = {k: num(k) for k in _EXT_KEYS if k in fields}
        if kind in _JOINT:
            missing = [k for k in _AXIS_KEYS if k not in fields]
            if missing:
                raise lines.error(lineno, f"{name}: the axis values lack {', '.join(missing)}")
            self.pose = None
            self.joints = np.radians([num(k) for k in _AXIS_KEYS])
            self.config = None
            return
        missing = [k for k in _POSE_KEYS if k not in fields]
        if missing:
            raise lines.error(lineno, f"{name}: the pose lacks {', '.join(missing)}")
        self.pose = pose_from_vendor([num(k) for k in _POSE_KEYS], "kuka")
        self.joints = None
        self.config = None
        if "S" in fields and "T" in fields:
            self.config = Config("kuka", (_int_value(fields["S"], lines, lineno),
                                          _int_value(fields["T"], lines, lineno)))


def _kind_of(typ: str | None, fields: dict[str, str]) -> str:
    if typ in _CARTESIAN | _JOINT:
        return typ
    return "E6AXIS" if "A1" in fields else "E6POS"


def _frame_value(text: str, lines: Lines, lineno: int) -> np.ndarray:
    _, fields = _aggregate_fields(text, lines, lineno)
    missing = [k for k in _POSE_KEYS if k not in fields]
    if missing:
        raise lines.error(lineno, f"the frame lacks {', '.join(missing)}")
    return pose_from_vendor([lines.number(fields[k], lineno) for k in _POSE_KEYS], "kuka")


def _read_dat(path: Path) -> tuple[dict[str, _Point], dict[str, dict[str, str]]]:
    """Points and motion data (FDAT, PDAT, LDAT by name, upper case) of a ``.dat`` file."""
    lines = Lines(path, "KUKA .dat file")
    points: dict[str, _Point] = {}
    data: dict[str, dict[str, str]] = {}
    started = ended = False
    for lineno, raw in enumerate(lines.lines, start=1):
        line = strip_comment(raw, ";")
        if not line.strip() or line.lstrip().startswith("&"):
            continue
        if re.match(r"^\s*DEFDAT\b", line, re.IGNORECASE):
            started = True
            continue
        if re.match(r"^\s*ENDDAT\b", line, re.IGNORECASE):
            ended = True
            break
        m = _DECL_RE.match(line)
        if not m:
            continue
        kind, name, value = m.group(1).upper(), m.group(2).upper(), m.group(3)
        typ, fields = _aggregate_fields(value, lines, lineno)
        if kind in ("FDAT", "PDAT", "LDAT"):
            data[name] = fields
        else:
            points[name] = _Point(_kind_of(typ or kind, fields), fields, lines, lineno, name)
    if not started:
        raise InputError(f"{path}: no DEFDAT line: not a KUKA .dat file")
    if not ended:
        raise InputError(f"{path}: line {len(lines.lines)}: no ENDDAT (truncated file?)")
    return points, data


def _dat_of(src: Path) -> Path | None:
    for p in src.parent.glob("*"):
        if p.stem.lower() == src.stem.lower() and p.suffix.lower() == ".dat":
            return p
    return None


def read(path: str | Path) -> tuple[Program, list[str]]:
    """Read a KUKA program: the ``.src`` and the ``.dat`` of the same name beside it.

    Parameters
    ----------
    path : str or Path
        The ``.src`` file (or the ``.dat``: the ``.src`` of the same name is read).

    Returns
    -------
    program : Program
        Points in the order the ``.src`` moves to them; ``line`` is the ``.src`` line.
    skipped : list of str
        Motions to points the program does not hold (``PTP HOME``, ``PTP $AXIS_ACT``).

    Raises
    ------
    InputError
        A missing file, a missing ``DEF``/``END``/``ENDDAT``, an unreadable aggregate or number,
        a motion to a point declared nowhere; the message names the file and line.
    """
    src = Path(path)
    if src.suffix.lower() == ".dat":
        src = next((p for p in src.parent.glob("*") if p.stem.lower() == src.stem.lower()
                    and p.suffix.lower() == ".src"), src.with_suffix(".src"))
    lines = Lines(src, "KUKA .src file")
    dat = _dat_of(src)
    points, data = _read_dat(dat) if dat is not None else ({}, {})
    tool, base = Ref(number=0), Ref(number=0, on_table=None)
    speed: float | None = None
    zone = 0.0
    motion_data: dict[str, str] = {}
    out: list[ProgramPoint] = []
    skipped: list[str] = []
    name = src.stem
    started = ended = False
    for lineno, raw in enumerate(lines.lines, start=1):
        line = strip_comment(raw, ";")
        if not line.strip() or line.lstrip().startswith("&"):
            continue
        if m := re.match(r"^\s*(?:GLOBAL\s+)?DEF\s+(\w+)", line, re.IGNORECASE):
            if not started:
                name, started = m.group(1), True
            continue
        if re.match(r"^\s*END\s*$", line, re.IGNORECASE):
            ended = True
            break
        if m := _TOOL_RE.match(line):
            tool = _tool_ref(m.group(1).strip(), lines, lineno)
        elif m := _BASE_RE.match(line):
            base = _base_ref(m.group(1).strip(), lines, lineno)
        elif m := _BAS_RE.match(line):
            n = int(m.group(2))
            if m.group(1).upper() == "TOOL":
                tool = Ref(number=n)
            else:
                base = Ref(number=n, on_table=None)
        elif m := _FDAT_ACT_RE.match(line):
            f = data.get(m.group(1).upper())
            if f is None:
                raise lines.error(lineno, f"FDAT {m.group(1)} is not declared in the .dat")
            tool = Ref(number=int(_int_value(f.get("TOOL_NO", "0"), lines, lineno)))
            base = Ref(number=int(_int_value(f.get("BASE_NO", "0"), lines, lineno)),
                       on_table=None)
        elif m := _LDAT_ACT_RE.match(line):
            motion_data = data.get(m.group(2).upper(), {})
        elif m := _VEL_RE.match(line):
            speed = lines.number(m.group(1), lineno)
        elif m := _APO_RE.match(line):
            zone = lines.number(m.group(1), lineno) * 1e-3
        elif m := _MOVE_RE.match(line):
            point = _move(m, lines, lineno, points, dat, tool, base, speed, zone, motion_data)
            if isinstance(point, str):
                skipped.append(point)
            else:
                out.append(point)
        elif _CIRC_RE.match(line):
            skipped.append(f"line {lineno}: CIRC (circular motions are not checked)")
    if not started:
        raise InputError(f"{src}: no DEF line: not a KUKA .src file")
    if not ended:
        raise InputError(f"{src}: line {len(lines.lines)}: no END (truncated file?)")
    files = (str(src),) + ((str(dat),) if dat is not None else ())
    return Program(name, "kuka", out, files), skipped


def _tool_ref(value: str, lines: Lines, lineno: int) -> Ref:
    if value.startswith("{"):
        return Ref(pose=_frame_value(value, lines, lineno))
    if m := _DATA_RE.match(value):
        return Ref(number=int(m.group(2)))
    if value.upper() in ("$NULLFRAME", "TOOL_DATA[0]"):
        return Ref(number=0)
    raise lines.error(lineno, f"$TOOL={value}: give TOOL_DATA[n] or a frame")


def _base_ref(value: str, lines: Lines, lineno: int) -> Ref:
    if value.startswith("{"):
        return Ref(pose=_frame_value(value, lines, lineno), on_table=False)
    if m := _EK_RE.match(value):
        return Ref(number=int(m.group(1)), on_table=True)
    if m := _DATA_RE.match(value):
        return Ref(number=int(m.group(2)), on_table=False)
    if value.upper() in ("$NULLFRAME", "$WORLD"):
        return Ref(number=0, on_table=False)
    raise lines.error(lineno, f"$BASE={value}: give BASE_DATA[n], EK(...) or a frame")


def _move(m: re.Match, lines: Lines, lineno: int, points: dict[str, _Point], dat: Path | None,
          tool: Ref, base: Ref, speed: float | None, zone: float, motion_data: dict[str, str]
          ) -> ProgramPoint | str:
    """The point of a ``PTP``/``LIN`` line, or why it is skipped."""
    motion = "lin" if m.group(1).upper().endswith("LIN") else "ptp"
    rest = re.split(r"\s+WITH\s+", m.group(2), maxsplit=1, flags=re.IGNORECASE)[0].strip()
    approx = re.search(r"\s+(C_DIS|C_PTP|C_ORI|C_VEL|C_SPL)\s*$", rest, re.IGNORECASE)
    target = rest[:approx.start()].strip() if approx else rest
    if target.startswith("{"):
        typ, fields = _aggregate_fields(target, lines, lineno)
        value = _Point(_kind_of(typ, fields), fields, lines, lineno, f"line {lineno}")
        pname = f"line {lineno}"
    else:
        key = target.upper()
        if key in ("$AXIS_ACT", "$POS_ACT") or "HOME" in key:
            return f"line {lineno}: {m.group(1).upper()} {target} (not held by the program)"
        if dat is None:
            raise lines.error(lineno, f"the .dat is missing: {target} is a point of the "
                                      f"program's .dat, and there is no "
                                      f"{Path(lines.path).stem}.dat beside the .src; copy it "
                                      "there with the .src")
        if key not in points:
            raise lines.error(lineno, f"{target} is not declared in the program's .dat")
        value, pname = points[key], target
    v = speed
    if motion == "lin" and "VEL" in motion_data:
        v = lines.number(motion_data["VEL"], lineno)
    z = zone if approx else 0.0
    if approx and "APO_DIST" in motion_data:
        z = lines.number(motion_data["APO_DIST"], lineno) * 1e-3
    return ProgramPoint(pname, lineno, motion, tool, base, value.pose, value.joints,
                        value.config, dict(value.external), v if motion == "lin" else None, z,
                        value.where)


# -- editing in place ----------------------------------------------------------------------------
def set_joints(lines: list[str], idx: int, q: NDArray[np.float64]) -> bool:
    """Write the axis values ``A1..A6`` (``q``, rad) of the ``E6AXIS``/``AXIS`` on line ``idx``."""
    line = lines[idx]
    for i in range(6):
        line, n = re.subn(rf"(\bA{i + 1}\s+){NUMBER}", lambda m, v=q[i]: m.group(1)
                          + fmt_num(math.degrees(v), JOINT_DECIMALS), line, count=1,
                          flags=re.IGNORECASE)
        if n != 1:
            return False
    lines[idx] = line
    return True


def _replace_fields(line: str, values: dict[str, str], pattern: str) -> tuple[str, int]:
    """Replace the number after each key of ``values`` (``pattern`` has {key} and {num})."""
    done = 0
    for key, text in values.items():
        line, n = re.subn(pattern.format(key=key, num=NUMBER), lambda m, t=text: m.group(1) + t,
                          line, count=1, flags=re.IGNORECASE)
        done += n
    return line, done


def set_pose(lines: list[str], idx: int, T: NDArray[np.float64], config: Config | None) -> bool:
    """Write X..C (``T``, m) and, unless None, S and T of the ``E6POS``/``POS`` on line ``idx``."""
    v = pose_to_vendor(T, "kuka")
    values = {k: fmt_num(x, MM_DECIMALS if i < 3 else DEG_DECIMALS)
              for i, (k, x) in enumerate(zip(_POSE_KEYS, v))}
    line, done = _replace_fields(lines[idx], values, r"([{{,]\s*{key}\s+){num}")
    if done != 6:
        return False
    if config is not None:
        flags = {"S": str(config.values[0]), "T": str(config.values[1])}
        line, n = _replace_fields(line, flags, r"([{{,]\s*{key}\s+)(?:'B[01]+'|{num})")
        if n != 2:
            return False
    lines[idx] = line
    return True
