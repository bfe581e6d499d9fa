"""``--robot-name NAME``: which robot of a cell file of several robots a command acts for.

``--robot`` names a robot *model* (a library name or a model file) in several commands, so the
robot of a cell is named by ``--robot-name``, a key of the cell file's ``robots`` section. A
one-robot cell file needs none (its robot is named ``robot``). The option is kept in
``click.Context.meta`` (the commands' own parameters stay as they are) and :func:`load_cell`
reads it: the cell as that robot sees it (:meth:`robotcell.cell.Cell.for_robot`).
"""

from __future__ import annotations

from collections.abc import Callable

import click

from robotcell.cell import Cell
from robotcell.errors import InputError

__all__ = ["ROBOT_NAME_KEY", "load_cell", "robot_name", "robot_name_option", "robot_of"]

#: Key of ``click.Context.meta`` under which ``--robot-name`` is kept.
ROBOT_NAME_KEY = "robotcell.robot_name"


def _keep(ctx: click.Context, param: click.Parameter, value: str | None) -> None:
    ctx.meta[ROBOT_NAME_KEY] = value


def robot_name_option(func: Callable) -> Callable:
    """Add ``--robot-name NAME`` to a command that takes a cell file."""
    return click.option(
        "--robot-name", default=None, metavar="NAME", expose_value=False, callback=_keep,
        help="In a cell file of several robots (a robots: section), the robot this command "
             "acts for (a key of robots:). Not needed for a cell of one robot.")(func)


def robot_name() -> str | None:
    """``--robot-name`` of the running command (None: not given)."""
    ctx = click.get_current_context(silent=True)
    return None if ctx is None else ctx.meta.get(ROBOT_NAME_KEY)


def robot_of(cell: Cell, path: str) -> str:
    """The robot of ``cell`` (read from ``path``) that ``--robot-name`` names, or its only one.

    Raises
    ------
    InputError
        An unknown name, or no name for a cell of several robots; the message lists the robots.
    """
    name = robot_name()
    if name is None and len(cell.robots) > 1:
        raise InputError(f"{path} has {len(cell.robots)} robots ({', '.join(cell.robots)}): "
                         "say which one with --robot-name NAME")
    try:
        return cell.robot_key(name)
    except InputError as exc:
        raise InputError(f"{path}: {exc}; give one of them to --robot-name") from None


def load_cell(path: str) -> Cell:
    """Read the cell file ``path`` as the robot of ``--robot-name`` sees it (a one-robot cell)."""
    cell = Cell.load(path)
    return cell.for_robot(robot_of(cell, path))
