"""The whole-cell fit of a cell of one or several robots: :func:`calibrate_cell`.

A cell of one robot is fitted by :func:`robotcell.cell.calibrate.whole.calibrate_one_robot`, all
its calibrations in one maximum-likelihood fit. In a cell of several robots every robot's
calibrations are repeated in that robot's view (:meth:`robotcell.cell.Cell.for_robot`): its
tools, its track, the frames fixed to it, and the shared items (turntable or positioner, frames
in the world or on the table) that it touched, which the cell records by naming the robot in
their provenance's options (``robot``; :meth:`~robotcell.cell.Cell.with_view` writes it). Each
robot's items are fitted together, as in a cell of one robot; every robot-to-robot placement the
cell records (a base whose provenance is ``robot-to-robot``) is repeated at the fitted tools of
both robots and the reference robot's fitted base, and the robot placed again
(:func:`~robotcell.cell.calibrate.robottorobot.repeat_link`); a placed robot whose items rest on
its base (a table or frame it touched in the world) is fitted again on its new base. A fit of
a shared positioner (provenance ``shared-positioner``: the positioner and the other robot's
base) is repeated last, at every robot's fitted tools and bases
(:func:`~robotcell.cell.calibrate.sharedpositioner.repeat_shared`), and the robots whose items
rest on what it moved are fitted again.

What is not adjusted jointly: the robots' fits are separate (one robot's calibrations do not
move another robot's items), and a link's touches do not refine the tools it used. A link's
uncertainty reaches the placed robot's items in the world through its base (or track), an input
of their calibrations with the link's error sources
(:func:`robotcell.cell.calibrate.chain.base_inputs`), but the covariance of the result is
block-diagonal: one block per robot, one per link.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.linalg import block_diag

from robotcell.calibration.result import CalibrationResult
from robotcell.calibration.uncertainty import Sources
from robotcell.cell import Cell, Positioner, Provenance
from robotcell.cell.calibrate.chain import (
    NOMINAL_ACCURACY,
    NominalAccuracy,
)
from robotcell.cell.calibrate.common import CellCalibration
from robotcell.cell.calibrate.robottorobot import RecordedLink, repeat_link
from robotcell.cell.calibrate.sharedrecord import SOURCE as SHARED_POSITIONER
from robotcell.cell.calibrate.sharedrecord import RecordedShared
from robotcell.cell.calibrate.whole import (
    CellRecalibration,
    ItemChange,
    calibrate_one_robot,
    item_difference,
    rebased,
    touch_files,
)
from robotcell.errors import InputError, term

__all__ = ["NOT_JOINT", "calibrate_cell", "cell_touch_files", "replaced_notes"]

#: What the fit of a cell of several robots says it does not adjust jointly (a note of its
#: report).
NOT_JOINT = ("note: the robots are fitted one by one (each robot's calibrations together, in "
             "its view); each robot-to-robot placement is repeated at the fitted tools and the "
             "reference robot's fitted base. Not adjusted jointly: one robot's touches do not "
             "move another robot's items, and a placement's touches do not refine the tools it "
             "used")

def replaced_notes(before: Cell, after: Cell, robot: str) -> list[str]:
    """Notes on the shared items another robot calibrated that a calibration by ``robot``
    replaced (the turntable or positioner, a frame in the world or on the table).

    A cell file holds one calibration of a shared item: the new one replaces the other robot's
    (the file before it is kept as a backup). The note says so and names how to compare the two
    and fit both robots' touches together.

    Parameters
    ----------
    before, after : Cell
        The cell of several robots before and after the calibration
        (:meth:`~robotcell.cell.Cell.with_view`).
    robot : str
        The robot that calibrated.

    Returns
    -------
    list of str
        One ``note:`` per replaced item; empty when none was another robot's.
    """
    pairs = [("turntable", before.turntable, after.turntable)]
    pairs += [(f"frame {n!r}", before.frames.get(n), f) for n, f in after.frames.items()]
    notes = []
    for what, old, new in pairs:
        if old is None or new is None or new.provenance is old.provenance:
            continue
        by = old.provenance.options.get("robot")
        if old.provenance.measurements is None or by in (None, robot):
            continue
        advice = ""
        if isinstance(old, Positioner):
            what = f"positioner {old.name!r}"
            advice = term("procedure:shared-positioner",
                          "robotcell.cell.calibrate.sharedpositioner.shared_positioner")
        elif what == "turntable":
            what = f"turntable {old.name!r}"
            advice = "robotcell.calibration.sharedtable.shared_turntable"
        notes.append(f"note: {what} was calibrated by robot {by!r} "
                     f"({Path(old.provenance.measurements).name}); this calibration by robot "
                     f"{robot!r} replaces it in the cell file"
                     + (f"; to compare the two within their 1-sigma and fit both robots' "
                        f"touches together, use {advice}" if advice else ""))
    return notes


#: Items of a robot's view that are its own whatever the provenance says.
_OWN_KINDS = ("tools.", "track")


def _candidates(cell: Cell, prov: Provenance) -> list[str]:
    """Robots whose view has every item a shared item's calibration used."""
    out = []
    for name in cell.robots:
        view = cell.for_robot(name)
        have = {f"tools.{t}" for t in view.tools} | {f"frames.{f}" for f in view.frames}
        have |= {"turntable"} | ({"track"} if view.track is not None else set())
        if all(key in have for key in prov.inputs):
            out.append(name)
    return out


def _owners(cell: Cell, label: str) -> dict[str, str]:
    """The robot whose calibration each recorded item outside the robots' sections is.

    A frame fixed to a robot is that robot's; a shared item names its robot in its options
    (``robot``), or, recorded before they did, is the only robot with every item it used.
    """
    shared = [(f"frames.{n}", f.parent, f.provenance) for n, f in cell.frames.items()]
    if cell.turntable is not None:
        shared.append(("turntable", "world", cell.turntable.provenance))
    out, problems = {}, []
    for key, parent, prov in shared:
        if parent in cell.robots:
            out[key] = parent
            continue
        if prov.measurements is None:
            continue
        named = prov.options.get("robot")
        if named is not None:
            if named not in cell.robots:
                problems.append(f"{key} was calibrated by robot {named!r}, which the cell lacks "
                                f"(its robots: {', '.join(cell.robots)})")
            out[key] = str(named)
            continue
        could = _candidates(cell, prov)
        if len(could) == 1:
            out[key] = could[0]
            continue
        again = term("robot=NAME", "through that robot's view (Cell.for_robot, Cell.with_view)")
        problems.append(f"{key}: its provenance does not say which robot touched it ("
                        + (f"any of {', '.join(could)} could have" if could else
                           "no robot has every item it used") + f"); calibrate it again {again}, "
                        "or add robot: NAME to its provenance's options")
    if problems:
        raise InputError(f"{label}: cannot repeat the calibrations: " + "; ".join(problems))
    return out


def _owned(owners: dict[str, str], robot: str) -> Callable[[str], bool]:
    """Which items of ``robot``'s view it refits: its tools and track, and the items it owns."""
    return lambda key: key.startswith(_OWN_KINDS) or owners.get(key) == robot


def _links(cell: Cell, label: str, notes: list[str]) -> dict[str, RecordedLink]:
    """The recorded robot-to-robot placements, by the robot placed; refuses a reference robot
    the cell lacks and missing or changed touch files (all named)."""
    out, problems = {}, []
    for name in cell.robots:
        prov = _base_provenance(cell, name)
        if prov.source != "robot-to-robot":
            continue
        link = RecordedLink.of(name, prov)
        if link is None:
            notes.append(f"note: the base of robot {name!r} was placed robot to robot without "
                         "recording its touch files and options; it is kept as it is (calibrate "
                         "robot-to-robot again to have it refitted)")
            continue
        if link.reference.robot not in cell.robots:
            problems.append(f"robots.{name}.base was placed in the base of robot "
                            f"{link.reference.robot!r}, which the cell lacks (its robots: "
                            f"{', '.join(cell.robots)})")
            continue
        problems += link.problems()
        out[name] = link
    if problems:
        raise InputError(f"{label}: cannot repeat the calibrations: " + "; ".join(problems)
                         + ". Restore the files, or calibrate those items again")
    return out


def _base_provenance(cell: Cell, name: str) -> Provenance:
    """The provenance of a robot's base (of its track's placement, for a robot on a track)."""
    unit = cell.robots[name]
    return unit.base_provenance if unit.track is None else unit.track.provenance


def _shared(cell: Cell, label: str, robot: str | None
            ) -> tuple[RecordedShared | None, list[str]]:
    """The recorded shared-positioner fit to repeat, and a note naming what it wrote when that
    is kept as written instead (refitting one robot only, a provenance without its files, or
    the positioner or the base calibrated otherwise since); refuses a robot the cell lacks and
    missing or changed touch files (all named)."""
    pos = cell.turntable
    on_pos = pos is not None and pos.provenance.source == SHARED_POSITIONER
    bases = [n for n in cell.robots if _base_provenance(cell, n).source == SHARED_POSITIONER]
    if not on_pos and not bases:
        return None, []
    recorded = RecordedShared.of(cell)
    placed = [] if recorded is None else [recorded.common[1].robot]
    why = ("refitting one robot only" if robot is not None else
           "its provenance does not record its touch files and options"
           if on_pos and recorded is None else
           "the positioner or the base was calibrated otherwise since"
           if recorded is None or bases != placed
           or _base_provenance(cell, placed[0]).id != recorded.provenance.id else "")
    if why:
        items = ([f"positioner {pos.name!r}"] if on_pos and pos is not None else []) + [
            f"the base of robot {n!r}" for n in bases]
        verb = "come" if len(items) > 1 else "comes"
        return None, [(f"note: {' and '.join(items)} {verb} from the fit of all touches of "
                       f"calibrate shared-positioner, not repeated ({why}): kept as written")]
    assert recorded is not None
    problems = [f"positioner (shared-positioner) was fitted by robot {t.robot!r}, which the "
                f"cell lacks (its robots: {', '.join(cell.robots)})"
                for t in recorded.common if t.robot not in cell.robots] or recorded.problems()
    if problems:
        raise InputError(f"{label}: cannot repeat the calibrations: " + "; ".join(problems)
                         + ". Restore the files, or calibrate those items again")
    return recorded, []


def _order(names: tuple[str, ...], links: dict[str, RecordedLink]) -> list[str]:
    """The robots, each after the robot its base is placed in (where there is no cycle)."""
    order: list[str] = []
    waiting = list(names)
    while waiting:
        ready = [n for n in waiting if n not in links or links[n].reference.robot not in waiting
                 or links[n].reference.robot == n]
        for n in ready or waiting[:1]:
            order.append(n)
            waiting.remove(n)
    return order


def cell_touch_files(cell: Cell, cell_label: str | None = None) -> list[tuple[str, Path]]:
    """Every touch file :func:`calibrate_cell` reads, each with its item (labelled by its robot
    in a cell of several robots).

    Parameters
    ----------
    cell : Cell
    cell_label : str, optional
        Name of the cell in messages (its file).

    Returns
    -------
    list of (str, Path)

    Raises
    ------
    InputError
        As :func:`calibrate_cell`: a robot named by a provenance that the cell lacks, a shared
        item whose robot cannot be told, a placement's missing or changed touch file.
    """
    if len(cell.robots) == 1:
        return touch_files(cell)
    label = cell_label or f"cell {cell.name!r}"
    owners = _owners(cell, label)
    out = [(f"{name}: {key}", path) for name in cell.robots
           for key, path in touch_files(cell.for_robot(name), _owned(owners, name))]
    for name, link in _links(cell, label, []).items():
        out += [(f"{name}: base", Path(p)) for p in (link.reference.path, link.other.path)]
    shared = _shared(cell, label, None)[0]
    if shared is not None:
        out += [(f"{shared.common[1].robot}: base and positioner", Path(p))
                for p in shared.files]
    return out


def calibrate_cell(cell: Cell, *, robot: str | None = None, cell_label: str | None = None,
                   nominal: NominalAccuracy = NOMINAL_ACCURACY, time: str | None = None,
                   on_note: Callable[[str], None] | None = None) -> CellRecalibration:
    """Re-estimate every calibrated item of a cell from all the touch files its calibrations used.

    Parameters
    ----------
    cell : Cell
        A cell whose items carry the provenance of calibrations into it (touch file, checksum,
        options: what ``calibrate ... --cell`` and ``calibrate robot-to-robot --cell`` record).
    robot : str, optional
        In a cell of several robots, refit this robot's items only (its calibrations and the
        placement of its base); default every robot's, and every placement.
    cell_label : str, optional
        Name of the cell in messages (its file).
    nominal : NominalAccuracy
        Accuracy of the items the calibrations used that have no recorded uncertainty.
    time : str, optional
        ISO 8601 time of the new provenance; default now.
    on_note : callable, optional
        Receives each note as it arises.

    Returns
    -------
    CellRecalibration
        In a cell of several robots each item and calibration is labelled ``ROBOT: ITEM``
        (``kuka: tools.torch``, ``abb: base``) and its ``ItemChange.robot`` set.

    Raises
    ------
    InputError
        A recorded touch file is missing or changed (each is named), a robot named by a
        provenance or by ``robot`` that the cell lacks, a shared item whose robot cannot be
        told, or a cell that records no calibration with its file.
    """
    if len(cell.robots) == 1:
        cell.robot_key(robot)  # an unknown name is refused, listing the robot
        return calibrate_one_robot(cell, cell_label=cell_label, nominal=nominal, time=time,
                                   on_note=on_note)
    label = cell_label or f"cell {cell.name!r}"
    chosen = cell.robot_names if robot is None else (cell.robot_key(robot),)
    notes: list[str] = []
    owners = _owners(cell, label)
    links = {k: v for k, v in _links(cell, label, notes).items() if k in chosen}
    shared, kept = _shared(cell, label, robot)
    stamp = time or Provenance.now("cell").time
    fit = _Fit(cell, owners, label, nominal, stamp, on_note)
    for name in _order(chosen, links):
        fit.robot(name, links.get(name))
    if shared is not None:
        fit.shared(shared)
    if not fit.parts and not fit.links:
        raise InputError(f"{label} records no calibration with its touch file"
                         + (f" for robot {robot!r}" if robot is not None else "")
                         + f": calibrate its items {term('cell:into', 'into the cell')} first "
                         "(each calibration then records its file)")
    for text in [*notes, *kept, NOT_JOINT]:
        fit.note(text)
    return fit.combined()


class _Fit:
    """The fit of a cell of several robots, robot by robot (internal)."""

    def __init__(self, cell: Cell, owners: dict[str, str], label: str,
                 nominal: NominalAccuracy, stamp: str,
                 on_note: Callable[[str], None] | None) -> None:
        self.original, self.current, self.owners = cell, cell, owners
        self.label, self.nominal, self.stamp, self.on_note = label, nominal, stamp, on_note
        self.parts: list[tuple[str, CellRecalibration]] = []
        self.links: list[tuple[str, RecordedLink, CalibrationResult]] = []
        self.notes: list[str] = []

    def note(self, text: str) -> None:
        if text not in self.notes:
            self.notes.append(text)
            if self.on_note is not None:
                self.on_note(text)

    def _fit_view(self, name: str) -> CellRecalibration | None:
        """Fit robot ``name``'s items in its view and write them into the cell."""
        owned = _owned(self.owners, name)
        view = self.current.for_robot(name)
        if not touch_files(view, owned):
            return None
        out = calibrate_one_robot(view, cell_label=f"{self.label}: robot {name!r}",
                                  nominal=self.nominal, time=self.stamp, on_note=self.note,
                                  owned=owned)
        self.current = self.current.with_view(out.cell, name)
        return out

    def robot(self, name: str, link: RecordedLink | None) -> None:
        """Fit one robot: its items, then the placement of its base, then its items again where
        they rest on its base."""
        part = self._fit_view(name)
        if link is not None:
            self.current, result = repeat_link(self.current, link, self.stamp)
            self.links.append((name, link, result))
            view = self.current.for_robot(name)
            if part is not None and any(not k.startswith("tools.") for k, _ in
                                        touch_files(view, _owned(self.owners, name))):
                again = self._fit_view(name)
                assert again is not None
                firsts = {c.key: c for c in part.changes}
                part = replace(again, changes=tuple(rebased(c, firsts[c.key])
                                                    for c in again.changes))
        if part is not None:
            self.parts.append((name, part))

    def shared(self, recorded: RecordedShared) -> None:
        """Repeat the shared-positioner fit at the fitted tools and bases, then fit again the
        robots whose items rest on the positioner or on the base it placed."""
        # the fit's machinery (the identification engine) loads only when a fit is repeated
        from robotcell.cell.calibrate.sharedpositioner import repeat_shared

        placed, done = repeat_shared(self.current, recorded, self.stamp)
        ref, other = recorded.common
        if placed is None:
            why = (done.agreement.message if not done.agreement.agree else
                   "poor verdict: " + "; ".join(done.joint.verdict.reasons))
            self.note(f"note: the fit of all touches of the shared positioner, repeated, is not "
                      f"written ({why}): the positioner and the base of robot {other.robot!r} "
                      "are kept as written")
            return
        self.current = placed
        self.links.append((other.robot, RecordedLink(ref, other, recorded.provenance),
                           done.joint))
        for name in (ref.robot, other.robot):
            owned = _owned(self.owners, name)
            if not any(not k.startswith(_OWN_KINDS) for k, _ in
                       touch_files(self.current.for_robot(name), owned)):
                continue  # its tools and track rest on neither
            index = next(i for i, (n, _) in enumerate(self.parts) if n == name)
            again = self._fit_view(name)
            assert again is not None
            firsts = {c.key: c for c in self.parts[index][1].changes}
            self.parts[index] = (name, replace(again, changes=tuple(
                rebased(c, firsts[c.key]) for c in again.changes)))

    def _link_change(self, name: str, link: RecordedLink, result: CalibrationResult
                     ) -> tuple[ItemChange, np.ndarray]:
        """How the placement moved robot ``name``'s base (``T_world_R``, or ``T_L_R0`` on a
        track) and the link's covariance, both along the axes of the base's parent (the world,
        or the track frame L): the link's 1-sigma is relative to the reference robot's base,
        and the placement records it along that base's axes."""
        def base(cell: Cell) -> tuple[np.ndarray, Provenance, np.ndarray]:
            unit = cell.robots[name]
            if unit.track is None:
                return unit.T_world_R, unit.base_provenance, np.eye(3)
            return unit.track.T_L_R0, unit.track.provenance, unit.track.T_world_L[:3, :3]

        before, prov, R_w_parent = base(self.original)
        after = base(self.current)[0]
        R = R_w_parent.T @ self.current.for_robot(link.reference.robot).frame_pose(
            "robot", track=link.reference.track)[:3, :3]  # reference base axes -> parent axes
        turn = block_diag(R, R)
        est = result.estimates.get("T_ref_other")
        cov = turn @ est.covariance @ turn.T if est is not None else np.zeros((6, 6))
        old = (Sources(6, dict(prov.sources)).covariance if prov.sources
               else np.diag(np.asarray(self.nominal.sigma(6)) ** 2))
        sigma_before = np.sqrt(np.diag(turn @ old @ turn.T if prov.sources else old))
        return ItemChange(f"{name}: base", before, after, item_difference(after, before),
                          np.sqrt(np.diag(cov)), sigma_before, robot=name), cov

    def combined(self) -> CellRecalibration:
        """The report of every robot's fit and every placement."""
        changes, steps, items, blocks, relative = [], [], [], [], {}
        iterations = 0
        for name, part in self.parts:
            for c in part.changes:
                label = f"{name}: {c.key}"
                changes.append(replace(c, key=label, robot=name))
                relative[label] = _relative(part.relative_to(c.key), name)
            steps += [replace(s, key=f"{name}: {s.key}") for s in part.steps]
            items += [f"{name}: {k}" for k in part.items]
            blocks.append(part.covariance)
            iterations = max(iterations, part.iterations)
        for name, link, result in self.links:
            change, cov = self._link_change(name, link, result)
            changes.append(change)
            relative[change.key] = link.reference.robot
            steps.append(CellCalibration(result, key=change.key, value="T_ref_other"))
            items.append(change.key)
            blocks.append(cov)
        for _, part in self.parts:
            for text in part.notes:
                self.note(text)
        return CellRecalibration(self.current, tuple(changes), tuple(steps), tuple(items),
                                 block_diag(*blocks), iterations, tuple(self.notes), relative)


def _relative(frame: str, robot: str) -> str:
    """The frame of a robot's view an item's 1-sigma is relative to, named in the whole cell:
    ``R`` (the view's robot base) is that robot's base, named by the robot."""
    return robot if frame == "R" else frame
