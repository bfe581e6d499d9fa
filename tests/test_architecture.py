"""The import graph of robotcell: no cycle, and the library never imports the CLI or click.

Every module under ``src/robotcell`` is parsed with :mod:`ast`. For cycles, every import that runs
when the module is imported counts, ``if TYPE_CHECKING:`` blocks included. An import inside a
function counts too in the packages of :data:`LAZY_COUNTED` (the kinematics and the solvers:
``Robot.ik`` imports :mod:`robotcell.ik` when it is called, and the solvers work on the
``Arm`` below the robot, never on the robot); elsewhere it is not yet an edge of the import
graph. For the CLI rule every import counts, wherever it is written. An import
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


#: Packages whose imports inside functions are edges of the import graph like any other.
LAZY_COUNTED = ("robotcell.kinematics", "robotcell.ik", "robotcell.robot")


def lazy_counted(name: str) -> bool:
    return any(name == p or name.startswith(p + ".") for p in LAZY_COUNTED)


GRAPH = {name: imports_of(name, path, lazy=lazy_counted(name)) for name, path in MODULES.items()}
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
    assert "robotcell.cell.calibrate" in GRAPH["robotcell.cli.calibrate"]
    assert "robotcell.cell.kinematics" in GRAPH["robotcell.cell"]
    # TYPE_CHECKING imports are edges; imports inside functions in the kinematics and the solvers
    # (Robot.ik), elsewhere only for the CLI rule (Cell.load imports the schema when called)
    assert "robotcell.ik.result" in GRAPH["robotcell.robot.robot"]
    assert "robotcell.ik.analytic" in GRAPH["robotcell.robot.robot"]
    assert "robotcell.cell.schema" not in GRAPH["robotcell.cell.model"]
    assert "robotcell.cell.schema" in ALL_IMPORTS["robotcell.cell.model"]


def test_the_solvers_stand_below_the_robot():
    # Robot.ik imports the solvers; no solver imports the robot, inside a function or not.
    for name in MODULES:
        if name == "robotcell.ik" or name.startswith("robotcell.ik."):
            assert "robotcell.robot.robot" not in ALL_IMPORTS[name], name


def test_find_cycle_finds_a_cycle():
    graph = {"robotcell.cell": {"robotcell.cell.kinematics"},
             "robotcell.cell.kinematics": {"robotcell.cell"}}
    assert find_cycle(graph) == ["robotcell.cell", "robotcell.cell.kinematics", "robotcell.cell"]


def test_no_import_cycle():
    assert find_cycle(GRAPH) is None, " -> ".join(find_cycle(GRAPH) or [])


@pytest.mark.parametrize("name", [n for n in MODULES
                                  if n != "robotcell.cli" and not n.startswith("robotcell.cli.")])
def test_library_module_imports_neither_the_cli_nor_click(name):
    bad = sorted(t for t in ALL_IMPORTS[name]
                 if t in ("click", "robotcell.cli") or t.startswith(("click.", "robotcell.cli.")))
    assert not bad, f"{name} imports {bad}"


#: The concept packages (docs/conventions.md, "Layout"); the top level holds only these, the
#: package's ``__init__``, ``errors``, ``report`` (one concept, one module).
CONCEPTS = {"kinematics", "ik", "robot", "dhprocedure", "calibration", "identification", "cell", "io",
            "export", "programs", "accuracy", "studies", "view", "report", "cli", "robots"}
TOP_MODULES = {"__init__.py", "errors.py"}


def test_the_top_level_holds_only_the_concept_packages():
    # (a folder left with only __pycache__ after a checkout of older code is not part of the tree)
    entries = {p.name for p in PACKAGE.iterdir()
               if p.name != "__pycache__"
               and (p.is_file() or any(f.suffix != ".pyc" for f in p.rglob("*") if f.is_file()))}
    assert entries == CONCEPTS | TOP_MODULES
    # every concept is a package (robots/ is package data: YAML models and URDFs)
    for name in CONCEPTS - {"robots"}:
        assert (PACKAGE / name / "__init__.py").is_file(), name


#: The layers, bottom first: a module imports only modules of its own layer or of lower layers
#: (a module belongs to the longest prefix listed). The vendor-boundary helpers of ``io`` (files,
#: tables, pose formats) and the pose algebra sit under the kinematics, which reads model files;
#: the pose algebra compiles its one-pose check with ``robotcell.kinematics.jit``, below it;
#: the controller exports (``robotcell.export``) sit over the cell they export; reports of results sit with the
#: estimators whose results they show, and with them the 3D scenes and their plotly drawing
#: (``robotcell.view.scene``, ``.shapes``, ``.arm``, ``.plot``) and the scenes of results
#: (``.calibration``, ``.identification``), which the reports draw; the view of a cell, its
#: paths, programs and reach maps sits over the programs. Imports inside functions count as for
#: cycles (in the packages of :data:`LAZY_COUNTED`).
LAYERS = [
    {"robotcell.errors", "robotcell.kinematics.jit", "robotcell.kinematics.transforms",
     "robotcell.io.fileio",
     "robotcell.io.tables", "robotcell.io.poseformats", "robotcell.io.yamlfile"},
    {"robotcell.kinematics", "robotcell.ik"},
    {"robotcell.robot"},
    {"robotcell.calibration", "robotcell.dhprocedure", "robotcell.identification",
     "robotcell.report", "robotcell.view.scene", "robotcell.view.shapes", "robotcell.view.arm",
     "robotcell.view.plot", "robotcell.view.calibration", "robotcell.view.identification"},
    {"robotcell.cell"},
    {"robotcell.export"},
    {"robotcell.programs"},
    {"robotcell.accuracy"},
    {"robotcell.view"},
    {"robotcell.studies"},
    {"robotcell.cli"},
]


def layer(module: str) -> int:
    """Index in :data:`LAYERS` of the longest prefix of ``module``."""
    best = (-1, -1)
    for i, prefixes in enumerate(LAYERS):
        for p in prefixes:
            if (module == p or module.startswith(p + ".")) and len(p) > best[0]:
                best = (len(p), i)
    assert best[1] >= 0, f"{module} is in no layer"
    return best[1]


def test_every_module_is_in_a_layer():
    assert layer("robotcell.export.kuka") == 5 and layer("robotcell.io.tables") == 0
    assert layer("robotcell.robot.robot") == 2 and layer("robotcell.cli.fk") == 10
    assert layer("robotcell.view.plot") == 3 and layer("robotcell.view.cellscene") == 8
    assert layer("robotcell.view.calibration") == 3 and layer("robotcell.view.program") == 8
    assert layer("robotcell.programs.kuka") == 6 and layer("robotcell.accuracy.filter") == 7


@pytest.mark.parametrize("name", sorted(n for n in MODULES
                                        if n != "robotcell"))
def test_imports_go_down_the_layers(name):
    up = sorted(t for t in internal(GRAPH[name]) if layer(t) > layer(name))
    assert not up, f"{name} (layer {layer(name)}) imports {up} from a layer above"


@pytest.mark.parametrize("name", sorted(n for n in MODULES
                                        if n.startswith("robotcell.calibration")))
def test_calibration_estimators_know_no_files(name):
    # arrays in, results out: no file reading or writing, no YAML, no paths
    bad = sorted(t for t in ALL_IMPORTS[name]
                 if t in ("pathlib", "os", "io", "yaml", "csv", "json", "robotcell.io.fileio"))
    tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
    calls = {n.func.id for n in ast.walk(tree)
             if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
    assert not bad and "open" not in calls, f"{name} imports {bad} or calls open()"
