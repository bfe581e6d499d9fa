"""The ``robotcell`` command line.

Subcommands live in their own modules and are imported only when used, so that
``robotcell --help`` and every command start fast: ``--help`` reads each command's one-line help
from its source instead of importing it (and numpy, scipy with it).
"""

from __future__ import annotations

import ast
import importlib.util
import os
import sys
import warnings
from pathlib import Path

import click

from robotcell import __version__
from robotcell._lazy import load
from robotcell.cli.terms import CLI_TERMS
from robotcell.errors import RobotcellError, terms

#: command name -> "module:attribute" of its click command
COMMANDS = {
    "robots": "robotcell.cli.robots:robots",
    "fk": "robotcell.cli.fk:fk",
    "ik": "robotcell.cli.ik:ik",
    "calibrate": "robotcell.cli.calibrate:calibrate",
    "dh": "robotcell.cli.dh:dh",
    "export": "robotcell.cli.export:export",
    "cell": "robotcell.cli.cell:cell",
    "simulate": "robotcell.cli.simulate:simulate",
    "plan": "robotcell.cli.plan:plan",
    "report": "robotcell.cli.report:report",
    "demo": "robotcell.cli.demo:demo",
    "identify": "robotcell.cli.identify:identify",
    "reach": "robotcell.cli.reach:reach",
    "sweep": "robotcell.cli.sweep:sweep_cmd",
    "program": "robotcell.cli.program:program",
    "view": "robotcell.cli.view:view",
    "compensate": "robotcell.cli.compensate:compensate",
    "iso9283": "robotcell.cli.iso9283:iso9283",
}


def load_command(target: str) -> click.Command:
    """The click command at ``target``, ``"module:attribute"``, imported now.

    The one way the command line imports a command on first use (:data:`COMMANDS`, and the
    subcommands of ``calibrate`` in :data:`robotcell.cli.calibrate.REGISTERED`).

    Raises
    ------
    ImportError
        The module or the attribute is missing: a registered command that is not there is a
        broken installation, never left out of the listing in silence.
    """
    return load(target, "the command")


class LazyGroup(click.Group):
    """A click group whose subcommands are imported on first use."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(COMMANDS)

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        return load_command(COMMANDS[name]) if name in COMMANDS else None

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """List the commands and their one-line help, as click does, without importing them."""
        names = self.list_commands(ctx)
        if not names:
            return
        limit = formatter.width - 6 - max(len(name) for name in names)
        rows = [(name, _help_command(name).get_short_help_str(limit)) for name in names]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


#: Decorators that make a click command of a function.
_DECORATORS = {"command", "group"}


def _help_command(name: str) -> click.Command:
    """A stand-in for command ``name`` that carries its help text, read from the source.

    The help of a command is the docstring of its decorated function (click's default); it is
    read with :mod:`ast`, so the module and its imports are not loaded. A command whose
    docstring cannot be found this way, or whose ``@click.command``/``@click.group`` sets its
    help or visibility itself, is imported.
    """
    module, attr = COMMANDS[name].split(":")
    spec = importlib.util.find_spec(module)
    if spec is not None and spec.origin is not None and spec.origin.endswith(".py"):
        tree = ast.parse(Path(spec.origin).read_text(encoding="utf-8"))
        for node in tree.body:
            if isinstance(node, ast.FunctionDef) and node.name == attr:
                own = {k.arg for d in node.decorator_list if isinstance(d, ast.Call)
                       and getattr(d.func, "attr", getattr(d.func, "id", None)) in _DECORATORS
                       for k in d.keywords}
                doc = ast.get_docstring(node)
                if doc and not own & {"help", "short_help", "hidden", "deprecated"}:
                    return click.Command(name, help=doc)
    return load_command(COMMANDS[name])


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="robotcell")
def cli() -> None:
    """Kinematics and calibration of industrial robot cells.

    Files and terminal output use millimetres and degrees; see docs/conventions.md.

    \b
    Example:
      robotcell robots
      robotcell fk kuka_kr16 --joints 0,-90,90,0,0,0 --format kuka
    """


def _one_line_warning(message: Warning | str, category: type[Warning], filename: str,
                      lineno: int, file: object = None, line: str | None = None) -> None:
    """``warnings.showwarning`` for users: ``warning: <category>: <message>`` on stderr."""
    click.echo(f"warning: {category.__name__}: {message}", err=True)


def main(argv: list[str] | None = None) -> None:
    """Entry point: run the CLI.

    Exit status: 0 on success; 2 for refused input (a bad option or file, geometry that does not
    determine the result), with ``error: ...`` on stderr; 1 when the user aborts, or for an
    unexpected failure, which is reported in one ``error:`` line with a request to report it
    (never a traceback). A Python warning raised inside (e.g. numpy's overflow on absurd input)
    is one ``warning:`` line, without the source file and line a developer would want.
    """
    try:
        with warnings.catch_warnings(), terms(CLI_TERMS):
            warnings.showwarning = _one_line_warning
            cli.main(args=argv, prog_name="robotcell", standalone_mode=False)
    except click.exceptions.Abort:
        click.echo("aborted", err=True)
        sys.exit(1)
    except click.UsageError as exc:
        if exc.ctx is not None:
            click.echo(f"{exc.ctx.get_usage()}\nTry '{exc.ctx.command_path} --help' for help.",
                       err=True)
        click.echo(f"error: {exc.format_message()}", err=True)
        sys.exit(2)
    except click.ClickException as exc:
        click.echo(f"error: {exc.format_message()}", err=True)
        sys.exit(exc.exit_code)
    except RobotcellError as exc:
        click.echo(f"error: {exc}", err=True)
        sys.exit(2)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except BrokenPipeError:
        # The reader of stdout went away (``robotcell ... | head``): stop quietly.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(1)
    except Exception as exc:  # noqa: BLE001 - the safety net: a message, never a traceback
        click.echo(f"error: unexpected {type(exc).__name__}: {exc}\n"
                   "This is a defect of robotcell, not of your input: please report it with "
                   "the command line and the input files.", err=True)
        sys.exit(1)
