"""The add-on's import graph (issue 27): no cycles, and each layer imports only those below
it. Properties (what Blender stores) and export (Blender data to arrays) never import the
engine or the UI; the engine never imports the UI. Read from the sources' own import
statements with ast, without Blender."""
import ast
import pathlib

ADDON = pathlib.Path(__file__).resolve().parents[2] / "addon"

# A layer may import itself and what is listed here (and the top-level helper modules).
ALLOWED = {
    "properties": {"properties"},
    "export": {"export"},
    "engine": {"engine", "export", "properties"},
    "ui": {"ui", "engine", "properties"},
}


def module_name(path):
    parts = list(path.relative_to(ADDON.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def import_graph():
    """{module: set of add-on modules it imports}, relative imports resolved; `from . import
    x` counts x when x is a module, else the package."""
    modules = {module_name(p): p for p in ADDON.rglob("*.py")}
    graph = {}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        edges = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.ImportFrom) and node.level):
                continue
            base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
            target = ".".join(base + ([node.module] if node.module else []))
            named = [f"{target}.{alias.name}" for alias in node.names]
            found = [n for n in named if n in modules]
            edges.update(found)
            if len(found) < len(named) and target in modules:
                edges.add(target)
        graph[name] = edges - {name}
    return graph


def cycles(graph):
    found, state = [], {}

    def visit(node, stack):
        state[node] = "open"
        stack.append(node)
        for dep in sorted(graph[node]):
            if state.get(dep) == "open":
                found.append(stack[stack.index(dep):] + [dep])
            elif dep not in state:
                visit(dep, stack)
        stack.pop()
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node, [])
    return found


def layer(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in ALLOWED else None


def test_the_graph_is_read():
    """The reader sees imports it must see (a reader that found none would pass the rest)."""
    graph = import_graph()
    assert "addon.export.scene_data" in graph["addon.export.camera"]
    assert "addon.native_module" in graph["addon.properties.preferences"]
    assert "addon.engine.memory" in graph["addon.engine.render_engine"]
    assert sum(len(edges) for edges in graph.values()) > 60


def test_no_import_cycles():
    assert cycles(import_graph()) == []


def test_layers_import_only_those_below():
    wrong = []
    for module, edges in import_graph().items():
        own = layer(module)
        if own is None:
            continue
        for dep in edges:
            other = layer(dep)
            if other is not None and other not in ALLOWED[own]:
                wrong.append(f"{module} imports {dep}")
    assert wrong == []


def test_a_planted_cycle_is_found():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == [["a", "b", "c", "a"]]
