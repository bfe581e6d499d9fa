"""The one lazy-import mechanism (robotcell._lazy): the package's public names, the view's and
the command line's commands are imported on first use, and a registered target that is missing
fails loudly, naming it."""

import pytest
from cli_helpers import run

import robotcell
from robotcell import _lazy, view
from robotcell.cli import COMMANDS, load_command


def test_load_imports_the_attribute_of_a_module_target():
    assert _lazy.load("robotcell.io.targets:read_targets").__name__ == "read_targets"


@pytest.mark.parametrize("target,match", [
    ("robotcell.no_such_module:thing", (r"registered as 'robotcell.no_such_module:thing' cannot "
                                       r"be loaded: No module named 'robotcell.no_such_module'")),
    ("robotcell.io.targets:no_such_name", (r"'robotcell.io.targets:no_such_name' cannot be "
                                          r"loaded: .*no_such_name")),
    ("robotcell.io.targets", (r"'robotcell.io.targets' cannot be loaded: a target is "
                             r"'module:attribute'")),
])
def test_load_of_a_missing_target_raises_import_error_naming_it(target, match):
    with pytest.raises(ImportError, match=match):
        _lazy.load(target)


@pytest.mark.parametrize("package", [robotcell, view], ids=["robotcell", "view"])
def test_a_registered_name_whose_module_is_missing_fails_loudly(package, monkeypatch):
    monkeypatch.setitem(package._LAZY, "ghost", "robotcell.no_such_module")
    with pytest.raises(ImportError, match=rf"the name 'ghost' of {package.__name__} registered "
                                          r"as 'robotcell.no_such_module:ghost' cannot be loaded"):
        package.ghost  # noqa: B018 - the access is the test


@pytest.mark.parametrize("package", [robotcell, view], ids=["robotcell", "view"])
def test_a_registered_name_its_module_lacks_fails_loudly(package, monkeypatch):
    monkeypatch.setitem(package._LAZY, "ghost", "robotcell.errors")
    with pytest.raises(ImportError, match=r"'robotcell.errors:ghost' cannot be loaded"):
        package.ghost  # noqa: B018


@pytest.mark.parametrize("package", [robotcell, view], ids=["robotcell", "view"])
def test_a_name_not_registered_is_an_attribute_error(package):
    with pytest.raises(AttributeError, match=rf"module '{package.__name__}' has no attribute "
                                             r"'no_such_name'"):
        package.no_such_name  # noqa: B018
    assert not hasattr(package, "no_such_name")


@pytest.mark.parametrize("package", [robotcell, view], ids=["robotcell", "view"])
def test_every_registered_name_loads_from_its_module(package):
    for name, module in package._LAZY.items():
        assert getattr(package, name) is getattr(__import__(module, fromlist=[name]), name)


def test_every_registered_command_loads():
    for name, target in COMMANDS.items():
        assert load_command(target).name in (name, target.split(":")[1]), name


def test_a_registered_command_that_is_missing_exits_1_naming_it(monkeypatch, capsys):
    monkeypatch.setitem(COMMANDS, "ghost", "robotcell.cli.no_such_module:ghost")
    code, _, err = run(capsys, "ghost")
    assert code == 1
    assert "the command registered as 'robotcell.cli.no_such_module:ghost' cannot be loaded" in err
