"""The history of a cell file: a numbered backup of every version an update replaced.

Before :func:`~robotcell.cell.schema.save_cell` replaces a cell file, the file is copied to
``<name>.<N>.bak`` with ``N`` one more than the highest number already there (``cell.yaml.1.bak``,
``cell.yaml.2.bak``, ...). No backup is ever overwritten, so the file as the user first wrote it
stays beside every later version. :func:`cell_history` lists the versions, oldest first, with the
provenance of every item (the procedure, time, residual RMS and note that each calibration
records) and which items changed from one version to the next; :meth:`Version.summary` says
it in one line, :meth:`Version.to_json` in full.
"""

from __future__ import annotations

import datetime as _dt
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from robotcell.errors import InputError
from robotcell.io.fileio import atomic_copy, read_text, real_destination
from robotcell.io.yamlfile import parse_yaml

__all__ = ["Version", "backups", "cell_history", "keep_version"]


def _pattern(path: Path) -> re.Pattern[str]:
    return re.compile(re.escape(path.name) + r"\.(\d+)\.bak")


def backups(path: str | Path) -> list[tuple[int, Path]]:
    """The backups of a cell file, oldest first.

    Parameters
    ----------
    path : str or Path
        The cell file.

    Returns
    -------
    list of (int, Path)
        Number and path of every ``<name>.<N>.bak`` beside the file (beside the file it links
        to, for a symbolic link), by increasing number.
    """
    p = real_destination(path)
    pattern = _pattern(p)
    found = []
    folder = p.parent if str(p.parent) else Path(".")
    if not folder.is_dir():
        return []
    for child in folder.iterdir():
        m = pattern.fullmatch(child.name)
        if m:
            found.append((int(m[1]), p.with_name(child.name)))
    return sorted(found)


def keep_version(path: str | Path) -> Path:
    """Copy the cell file to its next numbered backup, never overwriting one.

    The number is claimed by creating the file exclusively, so two updates at once get two
    backups. The copy is atomic and keeps the file's permissions and modification time. Updates
    are serialised (:mod:`robotcell.cell.update`), so the backups are every version in the order
    they were written. A backup goes beside the file itself: beside the file a symbolic link
    points to, not beside the link.

    Parameters
    ----------
    path : str or Path
        An existing cell file.

    Returns
    -------
    Path
        The backup written, ``<name>.<N>.bak``.
    """
    p = real_destination(path)
    number = max((n for n, _ in backups(p)), default=0) + 1
    while True:
        dst = p.with_name(f"{p.name}.{number}.bak")
        try:
            os.close(os.open(dst, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600))
        except FileExistsError:
            number += 1
            continue
        except OSError as exc:
            raise InputError(f"cannot write the backup {dst}: {exc.strerror or exc}") from None
        break
    try:
        atomic_copy(p, dst)
        st = p.stat()
        os.utime(dst, ns=(st.st_atime_ns, st.st_mtime_ns))  # when this version was written
    except BaseException:
        dst.unlink(missing_ok=True)
        raise
    return dst


@dataclass
class Version:
    """One version of a cell file.

    Attributes
    ----------
    path : Path
        The backup, or the cell file itself for the current version.
    number : int or None
        The backup's number; None for the current file.
    modified : str
        When the file was last written (ISO 8601, local time, to the second).
    provenance : dict
        Item (``tool torch``, ``frame part``, ``track KL1500``, ...) -> its provenance as
        written (``source``, ``time``, ``rms_mm``, ``note``, ...).
    changed : list of str
        Items whose provenance differs from the version before (every item for the first).
    error : str or None
        Why the version could not be read, if it could not.
    """

    path: Path
    number: int | None
    modified: str
    provenance: dict[str, dict[str, Any]] = field(default_factory=dict)
    changed: list[str] = field(default_factory=list)
    error: str | None = None

    def summary(self, first: bool = False) -> str:
        """What this version changed, in one line: each item with its procedure and RMS.

        Parameters
        ----------
        first : bool
            The oldest version kept: its items are listed as what it holds.

        Returns
        -------
        str
            E.g. ``"tool pointer (tcp, RMS 0.087 mm); frame part (workpiece, RMS 0.120
            mm)"``, ``"not readable: ..."`` or ``"no item changed its provenance"``.
        """
        if self.error is not None:
            return f"not readable: {self.error}"
        if not self.changed:
            return "no item changed its provenance"
        items = "; ".join(f"{item} ({_brief(self.provenance[item])})" for item in self.changed)
        return f"first kept version, {len(self.changed)} item(s): {items}" if first else items

    def to_json(self) -> dict[str, Any]:
        """The version as plain JSON values: ``file``, ``number`` (null for the current file),
        ``current``, ``written``, ``changed``, ``error`` and ``provenance`` (every item's
        provenance as written; a value JSON cannot hold is given as text, NaN as null)."""
        return {"file": str(self.path), "number": self.number, "current": self.number is None,
                "written": self.modified, "changed": list(self.changed), "error": self.error,
                "provenance": _plain(self.provenance)}


def _brief(prov: Mapping[str, Any]) -> str:
    """An item's provenance in a few words: its source and residual RMS."""
    text = str(prov.get("source", "no provenance recorded" if not prov else "?"))
    rms = prov.get("rms_mm")
    if isinstance(rms, (int, float)) and not isinstance(rms, bool) and math.isfinite(rms):
        text += f", RMS {rms:.3f} mm"
    return text


def _plain(value: Any) -> Any:
    """``value`` (parsed YAML) as JSON values: mappings, lists, finite numbers, text, null."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if value is None or isinstance(value, bool):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value) if math.isfinite(value) else None
    return str(value)


def _items(data: Any) -> dict[str, dict[str, Any]]:
    """Item label -> provenance of every item of a parsed cell file that records one."""
    if not isinstance(data, Mapping):
        return {}
    out: dict[str, dict[str, Any]] = _robots_items(data)
    robot = data.get("robot")
    if isinstance(robot, Mapping) and robot.get("identified"):
        out[f"robot {robot['identified']}"] = dict(robot.get("provenance") or {})
    for section in ("track", "turntable", "positioner"):
        entry = data.get(section)
        if isinstance(entry, Mapping):
            out[f"{section} {entry.get('name', section)}"] = dict(entry.get("provenance") or {})
    for section, kind in (("tools", "tool"), ("frames", "frame")):
        for name, entry in (data.get(section) or {}).items():
            if isinstance(entry, Mapping):
                out[f"{kind} {name}"] = dict(entry.get("provenance") or {})
    return out


def _robots_items(data: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """The items of the robots of a ``robots`` section, labelled ``<robot>: tool torch``."""
    out: dict[str, dict[str, Any]] = {}
    robots = data.get("robots")
    for name, entry in (robots.items() if isinstance(robots, Mapping) else ()):
        if not isinstance(entry, Mapping):
            continue
        one = {"robot": entry, "track": entry.get("track"), "tools": entry.get("tools")}
        out.update({f"{name}: {k}": v for k, v in _items(one).items()})
        if isinstance(entry.get("base_provenance"), Mapping):
            out[f"{name}: base"] = dict(entry["base_provenance"])
    return out


def cell_history(path: str | Path) -> list[Version]:
    """Every kept version of a cell file, oldest first, ending with the current file.

    Parameters
    ----------
    path : str or Path
        The cell file.

    Returns
    -------
    list of Version

    Raises
    ------
    InputError
        Neither the file nor a backup of it exists.
    """
    p = real_destination(path)
    paths: list[tuple[int | None, Path]] = [*backups(p)]
    if p.is_file():
        paths.append((None, p))
    if not paths:
        raise InputError(f"cell file {str(path)!r} does not exist, and no backup of it "
                         f"({p.name}.N.bak) either")
    versions: list[Version] = []
    before: dict[str, dict[str, Any]] | None = None
    for number, file in paths:
        stamp = _dt.datetime.fromtimestamp(file.stat().st_mtime).isoformat(timespec="seconds")
        v = Version(file, number, stamp)
        try:
            v.provenance = _items(parse_yaml(read_text(file, "cell file"), str(file)))
        except InputError as exc:
            v.error = str(exc)
        v.changed = [k for k, prov in v.provenance.items()
                     if before is None or before.get(k) != prov]
        before = v.provenance
        versions.append(v)
    return versions
