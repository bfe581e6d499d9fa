"""The calibration procedures: one descriptor each, in one registry.

A :class:`Procedure` holds everything the library knows of a procedure: its measurement table
(:class:`~robotcell.calibration.spec.TableSpec`, with the names of the results its estimators
write), its calibration into a cell and how ``calibrate cell`` repeats it from what the cell
recorded, the item of the cell it writes, the placement of its touches in a virtual cell
(``simulate``), its touch designs for ``plan`` (:class:`Planner`), and, registered by the
presentation layer when it is imported, the 3D scene and the report figure of its results.
The built-in procedures are defined one per module in :mod:`robotcell.cell.calibrate.procedures`
and registered in their order there; :func:`register` adds another (a plug-in).

The command line (``calibrate``, ``simulate``, ``plan``), :func:`robotcell.studies.simulate.simulate`,
:func:`robotcell.studies.plan.plan`, :func:`robotcell.cell.calibrate.calibrate_cell`, the
reports and the 3D views all find a procedure here, by its name (:func:`procedure`) or by the
name its results carry (:func:`for_result`), and list the procedures that have what they need
(:func:`having`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from robotcell.calibration import spec as specs
from robotcell.calibration.spec import TableSpec
from robotcell.errors import InputError

if TYPE_CHECKING:
    from robotcell.calibration.result import CalibrationResult
    from robotcell.cell import Cell
    from robotcell.cell.calibrate.common import CellCalibration
    from robotcell.cell.calibrate.context import CalibrationContext
    from robotcell.cell.calibrate.simulation import Touches

__all__ = ["PROCEDURES", "Planner", "Procedure", "attach", "for_result", "having", "procedure",
           "register", "unregister"]

T = TypeVar("T")


@dataclass(frozen=True)
class Planner:
    """How :func:`robotcell.studies.plan.plan` compares touch designs of a procedure.

    Attributes
    ----------
    designs : tuple of dict
        Candidate designs: keywords of the procedure's ``simulate`` (SI units), e.g.
        ``{"tilt": 0.35}``; the number of touches stays as the user asks.
    pose : str
        Key of the calibrated pose in ``result.values`` (e.g. ``"T_F_TCP"``); a result without
        it gives the position ``values["tcp"]`` alone.
    truth : str
        Key of the true pose in :attr:`Touches.truth <robotcell.cell.calibrate.simulation.Touches>`,
        in the frame :attr:`calibrate` gives its result in.
    calibrate : callable
        ``calibrate(cell, touches, sigma)``: the estimator on simulated touches, the cell
        giving robot, tool and axes, returning a
        :class:`~robotcell.calibration.result.CalibrationResult`.
    simulation : callable
        ``simulation(design)``: a design as keywords of ``simulate`` (e.g. a span of table angles
        as the angles); default the design as it is.
    """

    designs: tuple[Mapping[str, Any], ...]
    pose: str
    truth: str
    calibrate: Callable[[Cell, Touches, float | None], CalibrationResult]
    simulation: Callable[[dict[str, Any]], dict[str, Any]] = dict


@dataclass(frozen=True)
class Procedure:
    """One calibration procedure: its table, calls, simulation, planning and presentation.

    Attributes
    ----------
    name : str
        As the command line, the cell's provenance and :data:`~robotcell.calibration.spec.SPECS`
        name it (``"turntable"``).
    summary : str
        What it calibrates, e.g. ``"the turntable's root frame (one point on the table at
        several angles)"``.
    spec : TableSpec
        Its measurement table; :attr:`results` are the names its results carry.
    calibrate : callable
        Its calibration into a cell, ``calibrate(cell, measurements, [name,] *, context=None,
        **options)`` returning a :class:`~robotcell.cell.calibrate.common.CellCalibration`
        (``name`` for the procedures whose :attr:`item` has one).
    item : str
        The item of a cell it writes: ``"tools.NAME"`` or ``"frames.NAME"`` (named by the call's
        ``name``), ``"track"``, ``"turntable"`` or ``"positioner"``; empty when it writes none.
    repeat : callable, optional
        ``repeat(cell, file, name, options, context)``: the calibration again from the touch
        file, the item's name and the options its provenance recorded, for
        :func:`~robotcell.cell.calibrate.calibrate_cell`; None when it is not repeated.
    simulate : callable, optional
        ``simulate(cell, rng, noise, tool, track, **design)``: its touches placed in a virtual
        cell, as :class:`~robotcell.cell.calibrate.simulation.Touches`.
    planner : Planner, optional
        Its touch designs, for :func:`robotcell.studies.plan.plan`.
    scene : callable, optional
        ``scene(result, fitted, frames)``: the fitted geometry its results draw in their 3D
        scene (a list of :class:`robotcell.view.scene.Item`); registered by
        :mod:`robotcell.view.calibration`.
    figure_frames : callable, optional
        ``figure_frames(result)``: the frame of the report's figure and the poses drawn in it,
        when its results need other ones than the pose of their key; registered by
        :mod:`robotcell.report.calibration`.
    """

    name: str
    summary: str
    spec: TableSpec
    calibrate: Callable[..., CellCalibration]
    item: str = ""
    repeat: Callable[[Cell, str, str | None, Mapping[str, Any], CalibrationContext],
                     CellCalibration] | None = None
    simulate: Callable[..., Touches] | None = None
    planner: Planner | None = None
    scene: Callable[..., list[Any]] | None = field(default=None, compare=False)
    figure_frames: Callable[..., Any] | None = field(default=None, compare=False)

    @property
    def results(self) -> tuple[str, ...]:
        """The ``procedure`` of its results (:attr:`TableSpec.results`)."""
        return self.spec.results

    @property
    def named(self) -> bool:
        """Whether its call takes the name of the item it writes (a tool or a frame)."""
        return "NAME" in self.item


#: The procedures by name, in the order registered.
_REGISTRY: dict[str, Procedure] = {}
#: Names of procedures whose table :func:`register` added to the specifications.
_ADDED_SPECS: set[str] = set()


def register(proc: Procedure) -> Procedure:
    """Add a procedure; its table joins :data:`~robotcell.calibration.spec.SPECS` when it is
    not one of the built-in tables.

    Returns
    -------
    Procedure
        ``proc``.

    Raises
    ------
    InputError
        A procedure of that name, or one whose results have the same names, is registered.
    """
    if proc.name in _REGISTRY:
        raise InputError(f"a procedure named {proc.name!r} is registered already")
    if proc.spec.name != proc.name:
        raise InputError(f"procedure {proc.name!r} has the table of {proc.spec.name!r}")
    if specs.SPECS.get(proc.name) is not proc.spec:
        specs.add(proc.spec)
        _ADDED_SPECS.add(proc.name)
    _REGISTRY[proc.name] = proc
    return proc


def unregister(name: str) -> None:
    """Remove a procedure that :func:`register` added (and the table it added)."""
    _REGISTRY.pop(name, None)
    if name in _ADDED_SPECS:
        _ADDED_SPECS.discard(name)
        specs.remove(name)


def attach(name: str, **hooks: Callable[..., Any]) -> None:
    """Give a registered procedure its presentation: ``scene=`` or ``figure_frames=``.

    The 3D views and the reports stand above the procedures and register what they draw of
    each one's results here, keyed by the procedure's name, when they are imported.
    """
    _REGISTRY[name] = replace(procedure(name), **hooks)


def procedure(name: str) -> Procedure:
    """The procedure of that name.

    Raises
    ------
    InputError
        No procedure has it (the message lists those that do).
    """
    if name not in _REGISTRY:
        raise InputError(f"unknown procedure {name!r}; choose from {', '.join(_REGISTRY)}")
    return _REGISTRY[name]


def for_result(result_procedure: str) -> Procedure | None:
    """The procedure whose results carry ``procedure`` = ``result_procedure`` (e.g.
    ``"frame-3point"``), or None."""
    return next((p for p in _REGISTRY.values() if result_procedure in p.results), None)


class _Having(Mapping[str, T], Generic[T]):
    """The registered procedures that have a part, by name, to that part (live)."""

    def __init__(self, part: Callable[[Procedure], T | None]):
        self._part = part

    def _items(self) -> dict[str, T]:
        return {name: v for name, p in _REGISTRY.items() if (v := self._part(p)) is not None}

    def __getitem__(self, name: str) -> T:
        return self._items()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._items())

    def __len__(self) -> int:
        return len(self._items())

    def __repr__(self) -> str:
        return repr(self._items())


def having(part: Callable[[Procedure], T | None]) -> Mapping[str, T]:
    """The registered procedures for which ``part(procedure)`` is not None, by name, each to
    that value: e.g. ``having(lambda p: p.planner)``, the procedures ``plan`` can plan.

    The mapping is live: a procedure registered later is in it.
    """
    return _Having(part)


#: Every registered procedure, by name, in the order registered (live).
PROCEDURES: Mapping[str, Procedure] = having(lambda p: p)
