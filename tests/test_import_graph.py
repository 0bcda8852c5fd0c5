"""The package's modules import each other without cycles: every import counts, at
module level or inside a function (a function-local import only hides a cycle), except
those under ``if TYPE_CHECKING:`` (never run) and third-party ones."""

import ast
from pathlib import Path

import ballbal

PACKAGE = Path(ballbal.__file__).parent


def _modules() -> dict[str, Path]:
    """The package's modules: its Python files and its extension (``_native``, a leaf:
    it imports nothing of the package)."""
    mods = {("ballbal" if p.stem == "__init__" else f"ballbal.{p.stem}"): p
            for p in PACKAGE.glob("*.py")}
    for p in [*PACKAGE.glob("*.so"), *PACKAGE.glob("*.pyd")]:
        mods[f"ballbal.{p.name.split('.')[0]}"] = p
    return mods


def _type_checking(node: ast.If) -> bool:
    t = node.test
    return (isinstance(t, ast.Name) and t.id == "TYPE_CHECKING") or (
        isinstance(t, ast.Attribute) and t.attr == "TYPE_CHECKING")


def _imports(tree: ast.AST, modules: set[str]) -> set[str]:
    """The package's modules ``tree`` imports (``from . import x`` names module ``x``
    when there is one, else the package)."""
    out: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _type_checking(node):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.split(".")[0] == "ballbal")
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0 and not (node.module or "").startswith("ballbal"):
                return
            base = "ballbal" if node.level else ""
            target = (f"{base}.{node.module}" if base and node.module
                      else base or node.module or "")
            for a in node.names:
                sub = f"{target}.{a.name}"
                out.add(sub if sub in modules else target)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return {m for m in out if m in modules}


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as its modules in order, or None."""
    state: dict[str, int] = {}
    path: list[str] = []

    def dfs(u: str) -> list[str] | None:
        state[u] = 1
        path.append(u)
        for v in sorted(graph[u]):
            if state.get(v) == 1:
                return path[path.index(v):] + [v]
            if v not in state and (c := dfs(v)) is not None:
                return c
        state[u] = 2
        path.pop()
        return None

    for u in sorted(graph):
        if u not in state and (c := dfs(u)) is not None:
            return c
    return None


def graph() -> dict[str, set[str]]:
    mods = _modules()
    return {m: (_imports(ast.parse(p.read_text()), set(mods)) - {m}
                if p.suffix == ".py" else set()) for m, p in mods.items()}


def test_the_import_graph_finds_imports_at_every_level():
    """The graph sees module-level and function-local imports and skips the
    TYPE_CHECKING ones (checked on a made-up module, so that the test below can fail)."""
    src = ("from . import scan\nfrom typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
           "    from .model import Balancer\n"
           "def f():\n    from .spectrum import vibration\n    import ballbal.basins\n")
    found = _imports(ast.parse(src), set(_modules()))
    assert found == {"ballbal.scan", "ballbal.spectrum", "ballbal.basins"}
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]


def test_the_package_has_no_import_cycle():
    g = graph()
    assert len(g) > 20
    assert _cycle(g) is None, " -> ".join(_cycle(g) or [])
