"""navlib's import structure: no circle between its modules and no import running up a layer.

Every ``import``/``from ... import`` of a navlib module counts, at module top or inside a function (an
import inside a function still ties the two modules together).  The layers follow the data flow (issue 37):
foundations, then data, sensors, methods, workbench, studies, and the command line on top; a module may
import its own layer or a lower one.  The book's tooling (``book/navbook``) is not part of navlib: navlib
never imports it.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "navlib"

#: Layer of each top-level module or subpackage of navlib (lower numbers lie below).
LAYERS = {
    "navlib": 0,
    "errors": 0,
    "angles": 0,
    "names": 0,
    "paths": 0,
    "threads": 0,
    "_optional": 0,
    "formatting": 0,
    "seeding": 0,
    "verdicts": 1,
    "plotstyle": 1,
    "engine": 1,
    "claims": 1,
    "data": 2,
    "sensors": 3,
    "methods": 4,
    "workbench": 5,
    "studies": 6,
    "commands": 7,
    "cli": 7,
    "__main__": 8,
}


def module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def imports_of(path: Path) -> set[str]:
    """The navlib (and navbook) modules ``path`` imports, resolved to module names."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.split(".")[0] in ("navlib", "navbook")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if mod.split(".")[0] not in ("navlib", "navbook"):
                continue
            for a in node.names:  # `from . import x` imports the module x
                sub = f"{mod}.{a.name}"
                out.add(
                    sub
                    if (ROOT / Path(*sub.split("."))).with_suffix(".py").exists()
                    or (ROOT / Path(*sub.split(".")) / "__init__.py").exists()
                    else mod
                )
    out.discard(name)
    return out


def graph() -> dict[str, set[str]]:
    return {module_name(p): imports_of(p) for p in sorted(PKG.rglob("*.py"))}


def layer(module: str) -> int:
    parts = module.split(".")
    key = parts[1] if len(parts) > 1 else "navlib"
    if key not in LAYERS:
        raise AssertionError(f"{module}: no layer in LAYERS (add its top-level name)")
    return LAYERS[key]


def cycles(g: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g.get(v, ()):
            if w not in g:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in g:
        if v not in index:
            visit(v)
    return out


def test_the_graph_is_read_from_the_code():
    g = graph()
    assert len(g) > 60 and "navlib.workbench.loop" in g
    assert "navlib.workbench.fit" in g["navlib.workbench.loop"]  # a real edge is found


def test_navlib_has_no_import_circle():
    assert cycles(graph()) == []


def test_no_import_runs_up_a_layer():
    up = [
        f"{a} (layer {layer(a)}) -> {b} (layer {layer(b)})"
        for a, deps in graph().items()
        for b in deps
        if b.startswith("navlib") and layer(b) > layer(a)
    ]
    assert up == []


def test_navlib_never_imports_the_books_tooling():
    assert [(a, b) for a, deps in graph().items() for b in deps if b.startswith("navbook")] == []


@pytest.mark.parametrize(
    "g, expected",
    [
        ({"a": {"b"}, "b": {"a"}, "c": set()}, [["a", "b"]]),
        ({"a": {"b"}, "b": {"c"}, "c": {"a"}}, [["a", "b", "c"]]),
        ({"a": {"b"}, "b": set()}, []),
    ],
)
def test_the_circle_finder_finds_circles(g, expected):
    assert cycles(g) == expected
