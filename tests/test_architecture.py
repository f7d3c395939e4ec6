"""The house as designed (docs/architecture.md): no import cycles, no import against the
layering table, short modules, a small package root.

The imports are read from the source with ``ast`` (module level and inside functions
alike), and the lazy export tables of package ``__init__`` files count as imports of the
modules they name, so a cycle through a re-export is found too.
"""
import ast
import pathlib
import re

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "hmatddm"
ARCHITECTURE = PACKAGE.parent / "docs" / "architecture.md"
MAX_LINES = 500
MAX_ROOT_MODULES = 12


def _modules():
    """``{dotted name: (path, is_package)}`` of every module of the package."""
    modules = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts = parts[:-1]
        modules[".".join(parts)] = (path, is_package)
    return modules


MODULES = _modules()


def _targets(module, is_package, node):
    """The package modules that one import statement loads."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names if alias.name.split(".")[0] == "hmatddm"]
    if node.level:
        base = module.split(".") if is_package else module.split(".")[:-1]
        base = base[:len(base) - (node.level - 1)]
        target = ".".join(base + ([node.module] if node.module else []))
    else:
        target = node.module or ""
    if target.split(".")[0] != "hmatddm":
        return []
    # ``from package import name``: the submodule when ``name`` is one, else the package
    return [f"{target}.{alias.name}" if f"{target}.{alias.name}" in MODULES else target for alias in node.names]


def import_graph():
    """``{module: {imported module: [line numbers]}}`` within the package."""
    graph = {}
    for module, (path, is_package) in MODULES.items():
        edges = {}
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for target in _targets(module, is_package, node):
                    if target != module:
                        edges.setdefault(target, []).append(node.lineno)
            elif is_package and isinstance(node, ast.Constant) and isinstance(node.value, str):
                # a lazy export table: {"Name": ".module"} (hmatddm/_lazy.py)
                if re.fullmatch(r"\.[A-Za-z_][\w.]*", node.value) and module + node.value in MODULES:
                    edges.setdefault(module + node.value, []).append(node.lineno)
        graph[module] = edges
    return graph


def cycles(graph):
    """The strongly connected components with more than one module (Tarjan, iterative)."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    counter = 0
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(graph[start]))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in graph:
                    continue
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(graph[child])))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def room(module):
    """The room of a module: its sub-package, or the root module itself."""
    parts = module.split(".")
    return "hmatddm" if len(parts) == 1 else parts[1]


def allowed_imports(text):
    """``{room: set of rooms it may import}`` from the table of docs/architecture.md."""
    allowed = {}
    for line in text.splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")] if line.startswith("|") else []
        if len(cells) != 2 or cells[0] in ("room", "") or set(cells[0]) <= set("-"):
            continue
        if cells[1].startswith("every room"):
            allowed[cells[0]] = None
        else:
            allowed[cells[0]] = {name.strip() for name in cells[1].split(",") if name.strip()}
    return allowed


def layer_breaks(graph, allowed):
    """``[(module, imported module, line)]`` of the imports the table does not allow."""
    breaks = []
    for module, edges in graph.items():
        source = room(module)
        permitted = allowed.get(source, set())
        for target, lines in edges.items():
            destination = room(target)
            if destination == source or permitted is None or destination in permitted:
                continue
            breaks.append((module, target, lines[0]))
    return breaks


def test_no_import_cycles():
    assert cycles(import_graph()) == []


def test_the_cycle_finder_finds_a_cycle():
    graph = {"a": {"b": [1]}, "b": {"c": [1]}, "c": {"a": [1]}, "d": {"a": [1]}}
    assert cycles(graph) == [["a", "b", "c"]]
    assert cycles({"a": {"b": [1]}, "b": {}}) == []


def test_every_room_is_in_the_table():
    rooms = {room(module) for module in MODULES}
    assert rooms == set(allowed_imports(ARCHITECTURE.read_text())), \
        "docs/architecture.md's table and the package's rooms differ"


def test_no_import_against_the_layering():
    breaks = layer_breaks(import_graph(), allowed_imports(ARCHITECTURE.read_text()))
    assert breaks == [], "\n".join(f"{m} imports {t} (line {n}), not allowed by docs/architecture.md"
                                   for m, t, n in breaks)


def test_a_layer_break_is_found():
    allowed = allowed_imports("| room | may import |\n|---|---|\n| hmatrix | errors |\n| kernels | |\n")
    assert allowed == {"hmatrix": {"errors"}, "kernels": set()}
    graph = {"hmatddm.hmatrix.aca": {"hmatddm.kernels.drivers": [7], "hmatddm.errors": [3]}}
    assert layer_breaks(graph, allowed) == [("hmatddm.hmatrix.aca", "hmatddm.kernels.drivers", 7)]


@pytest.mark.parametrize("room_name, forbidden", [
    ("kernels", {"hmatrix", "layered", "elasticity", "coupled", "simulation", "scene", "app"}),
    ("hmatrix", {"kernels", "settings", "layered", "elasticity", "flow", "fracture", "coupled", "simulation"}),
    ("microseismic", {"app", "scene", "simulation", "render"}),
])
def test_the_table_keeps_the_issue_rules(room_name, forbidden):
    """The engines know no physics; the microseismic physics sits below the faces."""
    assert not allowed_imports(ARCHITECTURE.read_text())[room_name] & forbidden


def test_long_modules_state_why():
    unexplained = []
    for module, (path, _) in MODULES.items():
        text = path.read_text()
        if text.count("\n") > MAX_LINES and "Over 500 lines" not in (ast.get_docstring(ast.parse(text)) or ""):
            unexplained.append(f"{module} ({text.count(chr(10))} lines)")
    assert unexplained == []


def test_package_root_is_small():
    root_modules = sorted(path.name for path in PACKAGE.glob("*.py"))
    assert len(root_modules) <= MAX_ROOT_MODULES, root_modules
