"""Every command and subcommand explains itself with --help, including an example."""

import click
import pytest
from cli_helpers import run

from robotcell.cli import cli


def all_commands(group=cli, prefix=()):
    ctx = click.Context(group)
    for name in group.list_commands(ctx):
        cmd = group.get_command(ctx, name)
        path = (*prefix, name)
        yield path
        if isinstance(cmd, click.Group):
            yield from all_commands(cmd, path)


COMMANDS = list(all_commands())


def test_every_command_is_listed():
    top = {p[0] for p in COMMANDS}
    assert {"robots", "fk", "ik", "calibrate", "dh", "export", "cell", "simulate", "plan",
            "report", "demo"} <= top
    assert ("calibrate", "workpiece") in COMMANDS


@pytest.mark.parametrize("path", COMMANDS, ids=" ".join)
def test_help_has_an_example(path, capsys):
    code, out, _ = run(capsys, *path, "--help")
    assert code == 0
    assert "Example" in out, f"robotcell {' '.join(path)} --help has no example"
    assert f"robotcell {path[0]}" in out.split("Example", 1)[1]
