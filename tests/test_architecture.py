"""The import graph of robotcell: no cycle, imports go down the layers, and the library never
imports the CLI or click.

Every module under ``src/robotcell`` is parsed with :mod:`ast`. Every import counts, wherever it
is written: at the top, in ``if TYPE_CHECKING:`` blocks and inside functions (an import put off
until a function runs is still a dependency). An import ``from robotcell.a import b`` is an edge
to the module ``robotcell.a.b`` when that is a module, else to ``robotcell.a`` (the convention of
import-linter); the implicit import of a parent package is not an edge.
"""

import ast
from pathlib import Path

import pytest

from robotcell.controllers.registry import names
from robotcell.io.poseformats import FORMATS

SRC = Path(__file__).resolve().parent.parent / "src"
PACKAGE = SRC / "robotcell"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def imports_of(name: str, path: Path) -> set[str]:
    """Modules that ``path`` imports anywhere in it (robotcell modules by full name, others as
    written)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out: set[str] = set()
    for node in ast.walk(tree):
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


GRAPH = {name: imports_of(name, path) for name, path in MODULES.items()}


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
    # imports inside functions (Robot.ik imports the solvers when called) and under
    # TYPE_CHECKING (the result type of Robot.ik) are edges
    assert "robotcell.ik.analytic" in GRAPH["robotcell.robot.robot"]
    assert "robotcell.ik.result" in GRAPH["robotcell.robot.robot"]
    assert "robotcell.cell.ik" in GRAPH["robotcell.cell.model"]


def test_the_solvers_stand_below_the_robot():
    # Robot.ik imports the solvers; no solver imports the robot, inside a function or not.
    for name in MODULES:
        if name == "robotcell.ik" or name.startswith("robotcell.ik."):
            assert not any(t == "robotcell.robot" or t.startswith("robotcell.robot.")
                           for t in GRAPH[name]), name


def test_find_cycle_finds_a_cycle():
    graph = {"robotcell.cell": {"robotcell.cell.kinematics"},
             "robotcell.cell.kinematics": {"robotcell.cell"}}
    assert find_cycle(graph) == ["robotcell.cell", "robotcell.cell.kinematics", "robotcell.cell"]


def test_no_import_cycle():
    assert find_cycle(GRAPH) is None, " -> ".join(find_cycle(GRAPH) or [])


def concept(module: str) -> str:
    """The concept package (or top-level module) that ``module`` belongs to."""
    return ".".join(module.split(".")[:2])


def test_no_import_cycle_between_the_concept_packages():
    # a package is one room: no two packages import each other, even through different modules
    # (io's tables and the cell's file, say), so that each stands on a floor of its own
    packages = {concept(n) for n in MODULES}
    graph = {p: set() for p in packages}
    for name, targets in GRAPH.items():
        graph[concept(name)] |= {concept(t) for t in internal(targets)} - {concept(name)}
    cycle = find_cycle(graph)
    assert cycle is None, " -> ".join(cycle or [])


@pytest.mark.parametrize("name", [n for n in MODULES
                                  if n != "robotcell.cli" and not n.startswith("robotcell.cli.")])
def test_library_module_imports_neither_the_cli_nor_click(name):
    bad = sorted(t for t in GRAPH[name]
                 if t in ("click", "robotcell.cli") or t.startswith(("click.", "robotcell.cli.")))
    assert not bad, f"{name} imports {bad}"


#: The concept packages (docs/conventions.md, "Layout"); the top level holds only these, the
#: package's ``__init__``, ``errors`` and ``_lazy`` (the imports put off until first use).
CONCEPTS = {"kinematics", "ik", "robot", "dhprocedure", "calibration", "identification", "cell",
            "clearance", "io",
            "controllers", "export", "programs", "iso9283", "accuracy", "studies", "view", "report",
            "demo", "cli",
            "robots"}
TOP_MODULES = {"__init__.py", "errors.py", "_lazy.py"}


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
#: (a module belongs to the longest prefix listed). They make four tiers (docs/conventions.md,
#: "Layout"). The core: the vendor-boundary helpers of ``io`` (files, tables, pose formats, YAML)
#: and the pose algebra sit under everything (the pose formats convert the poses of
#: ``robotcell.kinematics.transforms``, which compiles its one-pose check with
#: ``robotcell.kinematics.jit``); the solvers of ``robotcell.ik`` work on the arm of
#: ``robotcell.kinematics`` and the robot (an arm with its IK, model files, the library) stands on
#: both; the estimators stand on the robot, the cell on them (it holds an identified arm, and
#: calibrates into itself), and the clearance of its robot from its parts beside the cell. The
#: features (:data:`FEATURES`): the controllers (one package per vendor: its export, its programs, its limits) and the exports beside them over the cell, the
#: programs over both, the ISO 9283 acceptance test beside the programs (it writes its cycles
#: through them); the accuracy (filtered poses and programs) over the programs, the studies
#: beside it. The presentation: the 3D views of cells, paths, programs and results, the HTML
#: reports, which embed them, over the views, and the demo walk-through, which writes both, over
#: the reports. The command line on top.
LAYERS = [
    {"robotcell.errors", "robotcell._lazy", "robotcell.kinematics.jit",
     "robotcell.kinematics.transforms", "robotcell.io"},
    {"robotcell.kinematics", "robotcell.ik"},
    {"robotcell.robot"},
    {"robotcell.calibration", "robotcell.dhprocedure", "robotcell.identification"},
    {"robotcell.cell", "robotcell.clearance"},
    {"robotcell.controllers", "robotcell.export"},
    {"robotcell.programs", "robotcell.iso9283"},
    {"robotcell.accuracy", "robotcell.studies"},
    {"robotcell.view"},
    {"robotcell.report"},
    {"robotcell.demo"},
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
    assert layer("robotcell.export.urdf") == 5 and layer("robotcell.io.tables") == 0
    assert layer("robotcell.controllers.kuka.program") == 5
    assert layer("robotcell.kinematics.transforms") == 0 and layer("robotcell.kinematics.arm") == 1
    assert layer("robotcell.robot.robot") == 2 and layer("robotcell.cli.fk") == 11
    assert layer("robotcell.view.plot") == 8 and layer("robotcell.report.identification") == 9
    assert layer("robotcell.programs.write") == 6 and layer("robotcell.accuracy.filter") == 7
    assert layer("robotcell.iso9283.analysis") == 6 and layer("robotcell.report.iso9283") == 9
    assert layer("robotcell.studies.reach") == 7 and layer("robotcell.demo.walkthrough") == 10


@pytest.mark.parametrize("name", sorted(n for n in MODULES
                                        if n != "robotcell"))
def test_imports_go_down_the_layers(name):
    up = sorted(t for t in internal(GRAPH[name]) if layer(t) > layer(name))
    assert not up, f"{name} (layer {layer(name)}) imports {up} from a layer above"


#: The features: each stands on the core and is presented by the reports, views and command
#: line above it.
FEATURES = {"controllers", "export", "programs", "iso9283", "accuracy", "studies"}
#: The presentation tier and what stands on it, which no feature imports.
PRESENTATION = {"view", "report", "demo", "cli"}
#: The imports allowed between features (docs/conventions.md, "Layout"): the controllers are the
#: vendor plug-ins every feature that speaks a controller's language goes through; the ISO 9283
#: test writes its cycles with the programs' public ``write_program``; filtering a program reads,
#: checks and rewrites it with the programs' readers and checks.
FEATURE_USES = {"export": {"controllers"}, "programs": {"controllers"},
                "iso9283": {"controllers", "programs"}, "accuracy": {"controllers", "programs"},
                "studies": {"controllers"}, "controllers": set()}


def package_of(module: str) -> str:
    """The concept package of a robotcell module (``robotcell.accuracy.poses`` -> ``accuracy``)."""
    return module.split(".")[1] if module.count(".") else module


@pytest.mark.parametrize("name", sorted(n for n in MODULES
                                        if package_of(n) in FEATURES))
def test_features_import_neither_report_nor_view(name):
    """A feature returns its results; the command line (or the demo) hands them to the report
    or view that presents them (an import inside a function counts)."""
    bad = sorted(t for t in internal(GRAPH[name]) if package_of(t) in PRESENTATION)
    assert not bad, f"{name} imports {bad}: return the result and let the caller present it"


@pytest.mark.parametrize("name", sorted(n for n in MODULES
                                        if package_of(n) in FEATURES))
def test_features_import_no_other_feature_but_the_allowed_ones(name):
    own = package_of(name)
    bad = sorted(t for t in internal(GRAPH[name])
                 if package_of(t) in FEATURES - {own} - FEATURE_USES[own])
    assert not bad, f"{name} imports {bad}, another feature (allowed: {FEATURE_USES[own]})"


def test_the_iso9283_test_uses_only_the_public_program_writer():
    uses = {t for n in MODULES if package_of(n) == "iso9283"
            for t in internal(GRAPH[n]) if package_of(t) == "programs"}
    assert uses <= {"robotcell.programs"}, uses


def test_the_feature_check_sees_a_report_import_inside_a_function(tmp_path):
    # a guard that the checks above see the imports they are meant to forbid
    path = tmp_path / "poses.py"
    path.write_text("def f():\n    from robotcell.report.accuracy import write_accuracy_report\n"
                    "    from ..programs import write_program\n", encoding="utf-8")
    found = internal(imports_of("robotcell.accuracy.poses", path))
    assert found == {"robotcell.report.accuracy", "robotcell.programs"}
    assert {package_of(t) for t in found} & PRESENTATION == {"report"}


@pytest.mark.parametrize("name", sorted(n for n in MODULES
                                        if n.startswith("robotcell.calibration")))
def test_calibration_estimators_know_no_files(name):
    # arrays in, results out: no file reading or writing, no YAML, no paths
    bad = sorted(t for t in GRAPH[name]
                 if t in ("pathlib", "os", "io", "yaml", "csv", "json", "robotcell.io.fileio"))
    tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
    calls = {n.func.id for n in ast.walk(tree)
             if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
    assert not bad and "open" not in calls, f"{name} imports {bad} or calls open()"


def test_the_command_line_is_a_thin_layer():
    """A command parses, calls one library function and prints: cli/ holds at most 12 % of the
    package's lines (the whole package counted, docstrings included)."""
    package = SRC / "robotcell"

    def lines(files):
        return sum(len(f.read_text(encoding="utf-8").splitlines()) for f in files)

    share = lines((package / "cli").rglob("*.py")) / lines(package.rglob("*.py"))
    assert 0.02 < share <= 0.12, f"cli/ holds {share:.1%} of the package's lines"


#: The vendors' names: every registered controller's and every pose format's. ``ur`` is also the
#: name of the inverse kinematics of arms with three parallel axes (``robotcell.ik``), a solver
#: and not a vendor, which those modules compare with.
VENDOR_NAMES = set(names()) | set(FORMATS)
SOLVER_NAMES = {"robotcell.ik": {"ur"}}


def vendor_branches(name: str, tree: ast.AST) -> list[str]:
    """Comparisons with a vendor's name (``vendor == "yaskawa"``, ``fmt in ("kuka", "abb")``)
    and tables keyed by one (``{"kuka": ...}``) in a module's syntax tree, as ``line: name``."""
    allowed = set().union(*(v for k, v in SOLVER_NAMES.items()
                            if name == k or name.startswith(k + ".")))

    def named(node: ast.AST | None) -> list[str]:
        values = node.elts if isinstance(node, (ast.Tuple, ast.List, ast.Set)) else [node]
        return [v.value for v in values if isinstance(v, ast.Constant)
                and isinstance(v.value, str) and v.value.lower() in VENDOR_NAMES - allowed]

    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            hits = [h for operand in (node.left, *node.comparators) for h in named(operand)]
        elif isinstance(node, ast.Dict):
            hits = [h for key in node.keys for h in named(key)]
        elif isinstance(node, ast.MatchValue):
            hits = named(node.value)
        else:
            continue
        found += [f"{node.lineno}: {h}" for h in hits]
    return found


def test_vendor_branches_are_found():
    # a guard that the check below sees the branches it is meant to forbid
    code = ('if vendor == "yaskawa": pass\nok = fmt in ("kuka", "abb")\n'
            'T = {"fanuc": 1}\nm = method == "ur"\n')
    tree = ast.parse(code)
    assert vendor_branches("robotcell.programs.x", tree) == [
        "1: yaskawa", "2: kuka", "2: abb", "3: fanuc", "4: ur"]
    assert vendor_branches("robotcell.ik.analytic", tree)[-1] == "3: fanuc"


@pytest.mark.parametrize("name", sorted(n for n in MODULES
                                        if not n.startswith("robotcell.controllers")))
def test_no_module_outside_the_controllers_branches_on_a_vendor_name(name):
    """What differs between controllers is an attribute or a method of the controller object
    (docs/conventions.md, "How to add a controller"); a module outside robotcell.controllers
    that compares with a vendor's name, or keys a table by one, would miss a controller added
    later."""
    tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
    assert not vendor_branches(name, tree), f"{name} branches on {vendor_branches(name, tree)}"


def private_imports(name: str, tree: ast.AST) -> list[str]:
    """Names starting with ``_`` that a module imports from another (``from m import _x``,
    dunder names and ``__future__`` excepted), as ``line: module._x``."""
    return [f"{node.lineno}: {node.module}.{alias.name}" for node in ast.walk(tree)
            if isinstance(node, ast.ImportFrom) and node.module != "__future__"
            for alias in node.names
            if alias.name.startswith("_") and not (alias.name.startswith("__")
                                                   and alias.name.endswith("__"))]


def test_private_imports_are_found():
    # a guard that the check below sees what it is meant to forbid, and lets the rest through
    code = ("from __future__ import annotations\nfrom robotcell.a import _b, c\n"
            "from robotcell import __version__\ndef f():\n    from .d import _E\n")
    assert private_imports("robotcell.x", ast.parse(code)) == ["2: robotcell.a._b", "5: d._E"]


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_module_imports_another_modules_private_name(name):
    """A name starting with ``_`` is private to its module: another module that needs it needs
    it public (documented, in ``__all__``) or moved to where both can import it."""
    tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
    assert not private_imports(name, tree), f"{name} imports {private_imports(name, tree)}"


#: Limits on a function in ``src/``: its lines (``def`` to its last line) and its parameters.
MAX_LINES = 100
MAX_PARAMETERS = 10


def oversized_functions(tree: ast.AST) -> list[str]:
    """Functions of a syntax tree over :data:`MAX_LINES` lines or :data:`MAX_PARAMETERS`
    parameters (positional, keyword-only, ``*args`` and ``**kwargs``; ``self`` and ``cls`` not
    counted), as ``line: name (lines, parameters)``."""
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        a = node.args
        positional = [p.arg for p in (*a.posonlyargs, *a.args)]
        count = (len(positional) - (positional[:1] in (["self"], ["cls"])) + len(a.kwonlyargs)
                 + (a.vararg is not None) + (a.kwarg is not None))
        length = node.end_lineno - node.lineno + 1
        if length > MAX_LINES or count > MAX_PARAMETERS:
            found.append(f"{node.lineno}: {node.name} ({length} lines, {count} parameters)")
    return found


def test_oversized_functions_are_found():
    # a guard that the check below sees what it is meant to forbid, and lets the rest through
    body = "\n".join(f"    x{i} = {i}" for i in range(100))
    code = (f"def long():\n{body}\n"
            "def wide(a, b, c, d, e, f, g, h, i, *, j, k):\n    pass\n"
            "class C:\n    def ten(self, a, b, c, d, e, f, g, h, i, j):\n        pass\n"
            "def ok(*args, **kwargs):\n    pass\n")
    assert oversized_functions(ast.parse(code)) == ["1: long (101 lines, 0 parameters)",
                                                    "102: wide (2 lines, 11 parameters)"]


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_function_is_over_100_lines_or_10_parameters(name):
    """A function a reader can hold in view: at most 100 lines and 10 parameters; a longer one
    is split into named steps, a wider one takes its related options as one object."""
    tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
    assert not oversized_functions(tree), f"{name}: {oversized_functions(tree)}"
