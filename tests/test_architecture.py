"""The import graph of robotcell: no cycle, and the library never imports the CLI or click.

Every module under ``src/robotcell`` is parsed with :mod:`ast`. For cycles, every import that runs
when the module is imported counts, ``if TYPE_CHECKING:`` blocks included; an import inside a
function runs when it is called, after both modules are loaded (``Robot.ik`` offers the solvers
of :mod:`robotcell.ik`, which build on ``Robot``), and is not an edge of the import graph. For
the CLI rule every import counts, wherever it is written. An import
``from robotcell.a import b`` is an edge to the module ``robotcell.a.b`` when that is a module,
else to ``robotcell.a`` (the convention of import-linter); the implicit import of a parent
package is not an edge.
"""

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parent.parent / "src"
PACKAGE = SRC / "robotcell"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _nodes(tree: ast.AST, lazy: bool):
    """Every node of ``tree``; with ``lazy=False`` not those inside functions."""
    todo = [tree]
    while todo:
        node = todo.pop()
        yield node
        for child in ast.iter_child_nodes(node):
            if lazy or not isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
                todo.append(child)


def imports_of(name: str, path: Path, lazy: bool) -> set[str]:
    """Modules that ``path`` imports (robotcell modules by full name, others as written).

    With ``lazy`` also the imports inside functions.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out: set[str] = set()
    for node in _nodes(tree, lazy):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                base = f"{anchor}.{base}" if base else anchor
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                out.add(sub if sub in MODULES else base)
    return out


GRAPH = {name: imports_of(name, path, lazy=False) for name, path in MODULES.items()}
ALL_IMPORTS = {name: imports_of(name, path, lazy=True) for name, path in MODULES.items()}


def internal(targets: set[str]) -> set[str]:
    return {t for t in targets if t in MODULES and t != "robotcell"}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle as a list of modules (first == last), or None."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(internal(graph[node])):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        stack.pop()
        state[node] = 2
        return None

    for start in sorted(graph):
        if start not in state and (found := visit(start)):
            return found
    return None


def test_the_graph_sees_every_module_and_its_imports():
    # a guard that the parser does what the tests below rely on
    assert "robotcell.cell" in MODULES and "robotcell.cli.calibrate" in MODULES
    assert "click" in GRAPH["robotcell.cli.calibrate"]
    assert "robotcell.cellcal" in GRAPH["robotcell.cli.calibrate"]
    assert "robotcell.coupled" in GRAPH["robotcell.cell"]
    # TYPE_CHECKING imports are edges; imports inside functions only for the CLI rule
    assert "robotcell.ik.result" in GRAPH["robotcell.robot"]
    assert "robotcell.ik" not in GRAPH["robotcell.robot"]
    assert "robotcell.ik" in ALL_IMPORTS["robotcell.robot"]


def test_find_cycle_finds_a_cycle():
    graph = {"robotcell.cell": {"robotcell.coupled"}, "robotcell.coupled": {"robotcell.cell"}}
    assert find_cycle(graph) == ["robotcell.cell", "robotcell.coupled", "robotcell.cell"]


def test_no_import_cycle():
    assert find_cycle(GRAPH) is None, " -> ".join(find_cycle(GRAPH) or [])


@pytest.mark.parametrize("name", [n for n in MODULES
                                  if n != "robotcell.cli" and not n.startswith("robotcell.cli.")])
def test_library_module_imports_neither_the_cli_nor_click(name):
    bad = sorted(t for t in ALL_IMPORTS[name]
                 if t in ("click", "robotcell.cli") or t.startswith(("click.", "robotcell.cli.")))
    assert not bad, f"{name} imports {bad}"
