"""Run the ``robotcell`` CLI in process, as a user's shell would, for the CLI tests."""

import pytest

from robotcell.cli import main


def run(capsys, *args):
    """Run ``robotcell ARGS``; return (exit status, stdout, stderr)."""
    with pytest.raises(SystemExit) as exc:
        main([str(a) for a in args])
        raise SystemExit(0)
    out = capsys.readouterr()
    return exc.value.code or 0, out.out, out.err
