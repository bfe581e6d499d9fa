"""Rewrite imports of robotcell's old top-level module paths to the concept packages.

Usage: ``python tools/relayout_imports.py FILE...`` (Python or Markdown; files are rewritten in
place and each changed file is printed). The table of old -> new paths is
:data:`robotcell._aliases.ALIASES`, the one the deprecation aliases use, so this script and the
aliases cannot disagree. It rewrites dotted paths (``robotcell.cellik.ik``), file paths
(``robotcell/cellik.py``) and ``from robotcell import <old module>`` of one name; an import of
several old modules on one line is reported for a hand edit.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

from robotcell._aliases import ALIASES

OLD = {old.removeprefix("robotcell."): new.removeprefix("robotcell.")
       for old, new in ALIASES.items()}
_ALT = "|".join(sorted(OLD, key=len, reverse=True))
DOTTED = re.compile(rf"(?<![\w.])robotcell\.({_ALT})\b(?!\.py)")
SLASHED = re.compile(rf"(?<![\w.])robotcell/({_ALT})(\.py\b|/)")
FROM_ONE = re.compile(rf"^(\s*)from robotcell import ({_ALT})$", re.MULTILINE)
FROM_MANY = re.compile(rf"^\s*from robotcell import .*\b({_ALT})\b", re.MULTILINE)


def _from_one(m: re.Match[str]) -> str:
    indent, name = m.group(1), m.group(2)
    package, _, module = OLD[name].rpartition(".")
    alias = f" as {name}" if module != name else ""
    return f"{indent}from robotcell.{package} import {module}{alias}"


def rewrite(text: str) -> str:
    """``text`` with every old module path replaced by its new path."""
    text = FROM_ONE.sub(_from_one, text)
    text = DOTTED.sub(lambda m: "robotcell." + OLD[m.group(1)], text)
    return SLASHED.sub(lambda m: "robotcell/" + OLD[m.group(1)].replace(".", "/") + m.group(2),
                       text)


def main(paths: list[str]) -> int:
    for name in paths:
        path = Path(name)
        text = path.read_text(encoding="utf-8")
        new = rewrite(text)
        if new != text:
            path.write_text(new, encoding="utf-8")
            print("rewrote", name)
        for m in FROM_MANY.finditer(new):
            print(f"{name}: edit by hand: {m.group(0).strip()}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
