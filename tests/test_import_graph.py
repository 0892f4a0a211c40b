"""The import graph: layers between packages, floors inside them, and no cycles.

Three rules, checked on the source with :mod:`ast` (nothing is imported):

1. Packages import downward only: ``sysid_cli -> reports -> simulator ->
   sysid -> flightlogs``; only ``sysid_cli`` imports click, only ``reports``
   imports matplotlib and jinja2.
2. Inside a package, each subpackage imports only the units its row of
   :data:`SUBPACKAGE_LAYERS` lists ("core" is the package's own modules, such
   as ``flightlogs/errors.py``; a new small module there joins it). The
   floors state the order; the lists are the edges the code uses today, and
   every listed edge points to the same floor or below.
3. No module imports itself through others. Every ``import`` statement
   counts, wherever it is (inside functions and ``if TYPE_CHECKING:`` too),
   and so do the ``__init__`` modules an import runs on the way
   (``from sysid.fit.cost import x`` runs ``sysid/fit/__init__.py`` first).
   A cycle is reported as its path, with the line of each import.
4. A package's ``__init__`` re-exports its public API without binding a name
   over one of its own submodules (``from .modes import modes`` would make
   ``import sysid.model.modes as m`` the function).
"""

from __future__ import annotations

import ast
from collections.abc import Iterable
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = ["flightlogs", "sysid", "simulator", "reports", "sysid_cli"]
# Third-party packages a layer may not import (only the CLI has click, only reports matplotlib).
FORBIDDEN_THIRD_PARTY = {
    "flightlogs": {"click", "matplotlib", "jinja2"},
    "sysid": {"click", "matplotlib", "jinja2"},
    "simulator": {"click", "matplotlib", "jinja2"},
    "reports": {"click"},
    "sysid_cli": set(),
}

# unit: (floor, units it may import).  "core" = the package's own modules.
#
# flightlogs    floor  may import
# ------------  -----  --------------------------------------------------------
# core            0    -        (errors, signals, flightlog, record, frames)
# readers         1    core
# writers         1    core, readers   (the DataFlash writer uses the reader's formats)
# maneuvers       1    core
# conditioning    2    core, maneuvers
# store           3    core, readers, writers, maneuvers, conditioning
#
# simulator     floor  may import
# ------------  -----  --------------------------------------------------------
# world           0    -        (and sysid.groundeffect's formulas)
# vehicle         1    -
# autopilot       2    -
# flights         3    world, vehicle, autopilot
# output          4    autopilot, flights
# mrac            4    world, flights
# campaign        5    world, vehicle, autopilot, flights, output
#
# sysid         floor  may import
# ------------  -----  --------------------------------------------------------
# core            0    -        (_json)
# model           1    -
# groundeffect    1    core     (beside model .. verify; the simulator reads its formulas)
# freqresp        2    -
# fit             3    core, model, freqresp
# verify          4    core, model, fit
# discrepancy     4    core, model, freqresp, fit   (a fitted model file in the simulation's place)
# batch           5    core, model, fit, verify, discrepancy   (runs them all on a cluster)
SUBPACKAGE_LAYERS: dict[str, dict[str, tuple[int, frozenset[str]]]] = {
    "flightlogs": {
        "core": (0, frozenset()),
        "readers": (1, frozenset({"core"})),
        "writers": (1, frozenset({"core", "readers"})),
        "maneuvers": (1, frozenset({"core"})),
        "conditioning": (2, frozenset({"core", "maneuvers"})),
        "store": (3, frozenset({"core", "readers", "writers", "maneuvers", "conditioning"})),
    },
    "simulator": {
        "world": (0, frozenset()),
        "vehicle": (1, frozenset()),
        "autopilot": (2, frozenset()),
        "flights": (3, frozenset({"world", "vehicle", "autopilot"})),
        "output": (4, frozenset({"autopilot", "flights"})),
        "mrac": (4, frozenset({"world", "flights"})),
        "campaign": (5, frozenset({"world", "vehicle", "autopilot", "flights", "output"})),
    },
    "sysid": {
        "core": (0, frozenset()),
        "model": (1, frozenset()),
        "groundeffect": (1, frozenset({"core"})),
        "freqresp": (2, frozenset()),
        "fit": (3, frozenset({"core", "model", "freqresp"})),
        "verify": (4, frozenset({"core", "model", "fit"})),
        "discrepancy": (4, frozenset({"core", "model", "freqresp", "fit"})),  # series or a model file; responses
        "batch": (5, frozenset({"core", "model", "fit", "verify", "discrepancy"})),
    },
}
NAMESPACE = "__init__"  # a top package's own __init__: above all its units, imported by none of them

Graph = dict[str, dict[str, int]]  # module -> {imported module: line of the first import}


# ---------------------------------------------------------------------- the checker


def _imports(path: Path) -> set[str]:
    """Top-level names of the absolute imports of one file."""
    tree = ast.parse(path.read_text(), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


def _module_files(root: Path, packages: Iterable[str]) -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` file of `packages` under `root`."""
    files = {}
    for package in packages:
        for path in sorted((root / package).rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            files[".".join(parts)] = path
    return files


def _source(module: str, path: Path, node: ast.ImportFrom) -> str:
    """The module a ``from ... import`` statement imports from, relative levels resolved."""
    if not node.level:
        return node.module or ""
    base = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _targets(module: str, path: Path, node: ast.Import | ast.ImportFrom, known: set[str]) -> list[str]:
    """Modules of `known` one import statement names (relative imports resolved)."""
    if isinstance(node, ast.Import):
        names = [alias.name for alias in node.names]
    else:
        source = _source(module, path, node)
        # ``from pkg import name``: the submodule pkg.name if there is one, else pkg itself
        names = [f"{source}.{alias.name}" if f"{source}.{alias.name}" in known else source for alias in node.names]
    found = []
    for name in names:
        while name and name not in known:  # ``import pkg.mod.attr`` or a third-party name
            name = name.rpartition(".")[0]
        if name:
            found.append(name)
    return found


def _ancestors(module: str) -> list[str]:
    parts = module.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def import_graph(root: Path, packages: Iterable[str]) -> Graph:
    """Every module's imports of other modules of `packages`, the ``__init__`` files they run included.

    Parameters
    ----------
    root : Path
        Directory holding the packages.
    packages : iterable of str
        Top-level package names.

    Returns
    -------
    dict of str to dict of str to int
        Importing module -> {imported module: line number}.
    """
    files = _module_files(root, packages)
    known = set(files)
    graph: Graph = {}
    for module, path in files.items():
        edges: dict[str, int] = {}
        own = set(_ancestors(module))
        if path.name == "__init__.py":
            own.add(module)
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            if not isinstance(node, (ast.Import, ast.ImportFrom)):
                continue
            for target in _targets(module, path, node, known):
                # importing a.b.c runs a and a.b first, unless the importer is inside them already
                for step in [*_ancestors(target), target]:
                    if step != module and step not in own:
                        edges.setdefault(step, node.lineno)
        graph[module] = edges
    return graph


def find_cycles(graph: Graph) -> list[list[str]]:
    """One cycle ``[a, b, ..., a]`` per strongly connected group of modules (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[set[str]] = []

    def visit(start: str) -> None:  # iterative, so deep graphs do not hit the recursion limit
        work = [(start, iter(sorted(graph.get(start, {}))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, {})))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                group = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    group.add(member)
                    if member == node:
                        break
                if len(group) > 1 or node in graph.get(node, {}):
                    groups.append(group)

    for module in sorted(graph):
        if module not in index:
            visit(module)
    return [_cycle_through(graph, group) for group in groups]


def _cycle_through(graph: Graph, group: set[str]) -> list[str]:
    """The shortest path from the group's first module back to itself, inside the group."""
    start = min(group)
    previous: dict[str, str] = {}
    frontier = [start]
    while frontier:
        following = []
        for node in frontier:
            for child in sorted(graph.get(node, {})):
                if child not in group or child in previous:
                    continue
                previous[child] = node
                if child == start:
                    path = [start]
                    while path[-1] != start or len(path) == 1:
                        path.append(previous[path[-1]])
                    return path[::-1]
                following.append(child)
        frontier = following
    raise AssertionError(f"no cycle through {sorted(group)}")  # pragma: no cover - Tarjan found one


def describe_cycle(graph: Graph, cycle: list[str]) -> str:
    """``a (line 3) -> b (line 12) -> a``: the cycle with the line of each import."""
    steps = [f"{a} (line {graph[a][b]})" for a, b in zip(cycle, cycle[1:])]
    return " -> ".join([*steps, cycle[-1]])


def _unit(module: str) -> str:
    """The unit of a module inside its top package: a subpackage, "core", or the namespace itself."""
    parts = module.split(".")
    if len(parts) == 1:
        return NAMESPACE
    if (ROOT / Path(*parts[:2])).is_dir():
        return parts[1]
    return "core"


@pytest.fixture(scope="module")
def graph() -> Graph:
    return import_graph(ROOT, LAYERS)


# ---------------------------------------------------------------------- the rules


@pytest.mark.parametrize("package", LAYERS)
def test_no_upward_or_forbidden_imports(package: str, graph: Graph) -> None:
    rank = LAYERS.index(package)
    upward = set(LAYERS[rank + 1 :])
    offenders = []
    for module, path in _module_files(ROOT, [package]).items():
        bad = _imports(path) & (upward | FORBIDDEN_THIRD_PARTY[package])
        bad |= {target.split(".")[0] for target in graph[module]} & upward
        if bad:
            offenders.append(f"{path.relative_to(ROOT)} imports {sorted(bad)}")
    assert not offenders, "\n".join(offenders)


@pytest.mark.parametrize("package", sorted(SUBPACKAGE_LAYERS))
def test_subpackages_import_only_the_units_their_row_lists(package: str, graph: Graph) -> None:
    table = SUBPACKAGE_LAYERS[package]
    offenders = []
    for module, edges in sorted(graph.items()):
        if module.split(".")[0] != package:
            continue
        unit = _unit(module)
        if unit == NAMESPACE:
            continue
        if unit not in table:
            offenders.append(f"{module}: unit {unit!r} is not in SUBPACKAGE_LAYERS[{package!r}]; give it a floor")
            continue
        for target, line in sorted(edges.items()):
            if target.split(".")[0] != package:
                continue
            other = _unit(target)
            if other != unit and other not in table[unit][1]:
                offenders.append(f"{module} (line {line}) imports {target}: {unit} may not import {other}")
    assert not offenders, "\n".join(offenders)


@pytest.mark.parametrize("package", sorted(SUBPACKAGE_LAYERS))
def test_the_layer_table_points_down(package: str) -> None:
    table = SUBPACKAGE_LAYERS[package]
    for unit, (floor, allowed) in table.items():
        for other in allowed:
            assert other in table, f"{package}: {unit} lists unknown unit {other}"
            assert table[other][0] <= floor, f"{package}: {unit} (floor {floor}) may not import {other} above it"
    units = {unit: dict.fromkeys(allowed, 0) for unit, (_, allowed) in table.items()}
    assert not find_cycles(units), f"{package}: units on one floor import each other"


def test_no_import_cycles(graph: Graph) -> None:
    cycles = find_cycles(graph)
    assert not cycles, "import cycles:\n" + "\n".join(describe_cycle(graph, c) for c in cycles)


def _shadowing(root: Path, packages: Iterable[str]) -> list[tuple[str, str, int]]:
    """Names an ``__init__`` binds that hide a submodule of the same name (``from .modes import modes``)."""
    files = _module_files(root, packages)
    found = []
    for package, path in files.items():
        if path.name != "__init__.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            if not isinstance(node, ast.ImportFrom):
                continue
            source = _source(package, path, node)
            for alias in node.names:
                bound = alias.asname or alias.name
                if f"{package}.{bound}" in files and f"{source}.{alias.name}" != f"{package}.{bound}":
                    found.append((package, bound, node.lineno))
    return found


# Existing shadows, kept: ``from sysid.fit.accuracy import ...`` still works (it goes through
# sys.modules), only ``import sysid.fit.accuracy as m`` and ``sysid.fit.accuracy.name`` do not.
KNOWN_SHADOWS = {("sysid.fit", "accuracy")}


def test_no_reexport_hides_a_submodule() -> None:
    offenders = [
        f"{package} (line {line}) binds {name!r} over its submodule {package}.{name}"
        for package, name, line in _shadowing(ROOT, LAYERS)
        if (package, name) not in KNOWN_SHADOWS
    ]
    assert not offenders, "\n".join(offenders)


# ---------------------------------------------------------------------- the checker's own tests


def test_the_checker_sees_imports(tmp_path: Path) -> None:
    probe = tmp_path / "probe.py"
    probe.write_text("import click\nfrom sysid.x import y\nfrom . import z\n")
    assert _imports(probe) == {"click", "sysid"}


def _write_tree(root: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)


def test_a_cycle_through_a_function_level_import_is_found(tmp_path: Path) -> None:
    _write_tree(
        tmp_path,
        {
            "pkg/__init__.py": '"""Empty."""\n',
            "pkg/a.py": "from pkg.b import helper\n",
            "pkg/b.py": "def helper():\n    from .a import thing\n    return thing\n",
            "pkg/c.py": "import numpy\nfrom pkg import a\n",
        },
    )
    graph = import_graph(tmp_path, ["pkg"])
    assert graph["pkg.b"] == {"pkg.a": 2}
    assert graph["pkg.c"] == {"pkg.a": 2}
    cycles = find_cycles(graph)
    assert cycles == [["pkg.a", "pkg.b", "pkg.a"]]
    assert describe_cycle(graph, cycles[0]) == "pkg.a (line 1) -> pkg.b (line 2) -> pkg.a"


def test_a_cycle_through_an_init_is_found(tmp_path: Path) -> None:
    # sub/__init__ re-exports sub.x; sub.x imports top.core, which imports a name from sub
    _write_tree(
        tmp_path,
        {
            "top/__init__.py": "",
            "top/core.py": "from .sub import name\n",
            "top/sub/__init__.py": "from .x import name\n",
            "top/sub/x.py": "from top.core import other\nname = 1\n",
        },
    )
    graph = import_graph(tmp_path, ["top"])
    assert graph["top.core"] == {"top.sub": 1}
    assert graph["top.sub.x"] == {"top.core": 1}  # top is its own package: already running
    assert find_cycles(graph) == [["top.core", "top.sub", "top.sub.x", "top.core"]]


def test_an_acyclic_tree_has_no_cycles(tmp_path: Path) -> None:
    _write_tree(
        tmp_path,
        {
            "top/__init__.py": "from top.sub import name\n",
            "top/sub/__init__.py": "from .x import name\n",
            "top/sub/x.py": "import top.core\nname = 1\n",
            "top/core.py": "import os\n",
        },
    )
    graph = import_graph(tmp_path, ["top"])
    assert graph["top"] == {"top.sub": 1}  # top.sub.x is run by top.sub, not named by top
    assert find_cycles(graph) == []


def test_a_reexport_hiding_a_submodule_is_found(tmp_path: Path) -> None:
    _write_tree(
        tmp_path,
        {
            "pkg/__init__.py": "from .modes import modes\nfrom .other import fine\nfrom . import other\n",
            "pkg/modes.py": "def modes(): ...\n",
            "pkg/other.py": "fine = 1\n",
        },
    )
    assert _shadowing(tmp_path, ["pkg"]) == [("pkg", "modes", 1)]
