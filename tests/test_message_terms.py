"""Library messages name their inputs by parameter or procedure, never by a command line.

A message names an input through ``robotcell.errors.term(key, python)``; the command line gives
its words for each key in one table, ``robotcell.cli.terms.CLI_TERMS``. The keys are the
library's (parameter names, ``procedure:NAME``), so that no library string spells a command.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import robotcell
from robotcell.calibration.spec import SPECS
from robotcell.cli.terms import CLI_TERMS
from robotcell.errors import term, terms

SRC = Path(robotcell.__file__).parent
LIBRARY = sorted(p for p in SRC.rglob("*.py") if "cli" not in p.relative_to(SRC).parts)


def term_keys(path: Path) -> list[tuple[int, ast.expr]]:
    """Line and key expression of every ``term(...)`` call in ``path``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [(node.lineno, node.args[0]) for node in ast.walk(tree)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
            and node.func.id == "term" and node.args]


def literal_text(key: ast.expr) -> str:
    """The key with each formatted field as ``{}``: the text a reader sees in the source."""
    if isinstance(key, ast.Constant) and isinstance(key.value, str):
        return key.value
    assert isinstance(key, ast.JoinedStr), ast.dump(key)
    return "".join(v.value if isinstance(v, ast.Constant) else "{}" for v in key.values)


def keys_of(key: ast.expr) -> set[str]:
    """The keys a call can give: the constant, or a ``procedure:{...}`` key for every
    procedure whose table refuses a column (the one place a key is formatted)."""
    text = literal_text(key)
    if "{}" not in text:
        return {text}
    assert text == "procedure:{}", f"formatted key {text!r}: list its values here"
    return {f"procedure:{spec.name}" for spec in SPECS.values() if spec.unused}


CALLS = [(p, line, key) for p in LIBRARY for line, key in term_keys(p)]


def test_the_scan_finds_the_library_terms():
    assert len(CALLS) > 20
    assert any(literal_text(k) == "sigma" for _, _, k in CALLS)


def test_no_library_term_is_keyed_by_a_command_line():
    bad = [f"{p.relative_to(SRC)}:{line}: {literal_text(k)!r}" for p, line, k in CALLS
           if "--" in literal_text(k) or literal_text(k).startswith(("calibrate ", "robotcell "))]
    assert not bad, "keys that spell a command line: " + "; ".join(bad)


def test_every_key_the_library_uses_has_the_command_lines_words():
    used = set().union(*(keys_of(k) for _, _, k in CALLS))
    missing = sorted(used - set(CLI_TERMS))
    assert not missing, f"keys without an entry in CLI_TERMS: {missing}"


def test_every_command_line_word_belongs_to_a_key_the_library_uses():
    used = set().union(*(keys_of(k) for _, _, k in CALLS))
    assert not sorted(set(CLI_TERMS) - used)


def test_the_scan_sees_a_command_line_key(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("from robotcell.errors import term\n"
                   "x = term('calibrate turntable --cell', 'the turntable')\n", encoding="utf-8")
    ((_, key),) = term_keys(bad)
    assert literal_text(key) == "calibrate turntable --cell"


@pytest.mark.parametrize("key", sorted(CLI_TERMS))
def test_a_front_end_word_replaces_the_python_word(key):
    assert term(key, "python words") == "python words"
    with terms(CLI_TERMS):
        assert term(key, "python words") == CLI_TERMS[key]
