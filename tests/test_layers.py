"""The layering rule of STYLE.md, as one ordered list: each layer may import only the layers
listed before it (lowest first), and some layers keep outside packages out or import them only
lazily. ``policies`` sit above the env layers but may use only ``core``; the runners
(``evaluation``, ``training``) and the CLI sit on top."""

from __future__ import annotations

import ast
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Layer:
    """A package layer: a folder or a module, as a path relative to the checkout.

    Attributes:
        path: ``semexplore_gym/core``, ``semexplore_gym/expert_driven_envs.py``, ``policies``, ...
        only: if set, the only layers (paths) of this project it may import besides itself,
            instead of every layer listed before it.
        forbid: outside packages it must never import.
        lazy_only: outside packages it may import only inside functions.
    """

    path: str
    only: tuple[str, ...] | None = None
    forbid: tuple[str, ...] = ()
    lazy_only: tuple[str, ...] = ()

    @property
    def module(self) -> str:
        """The dotted module name the layer's files are imported as."""
        return _module_of_path(self.path.removesuffix("/__init__.py").removesuffix(".py"))


_CORE = "semexplore_gym/core"
_CONFIG = "semexplore_gym/config"
LAYERS: list[Layer] = [
    # numpy/scipy/numba only: no simulator, no gym, no learners, no drawing.
    Layer(
        _CORE,
        forbid=(
            "gymnasium",
            "pymunk",
            "torch",
            "stable_baselines3",
            "sb3_contrib",
            "matplotlib",
            "pygame",
            # no file or network I/O: reading configs and maps is the job of the layers above
            "yaml",
            "json",
            "pickle",
            "csv",
            "io",
            "urllib",
            "http",
            "socket",
            "tempfile",
            "shutil",
            "zipfile",
            "PIL",
            "os",
            "pathlib",
        ),
    ),
    # Config and file input: build_params, bounded YAML/JSON reading, output path checks.
    Layer(_CONFIG),
    # The package root registers the env ids by string; `import semexplore_gym.core` runs it,
    # so it must not pull gymnasium in at import time.
    Layer("semexplore_gym/__init__.py", lazy_only=("gymnasium",)),
    Layer("semexplore_gym/maps"),
    Layer("semexplore_gym/rendering", lazy_only=("matplotlib", "pygame")),
    Layer("semexplore_gym/sim", forbid=("gymnasium",)),
    Layer("semexplore_gym/envs"),
    Layer("semexplore_gym/wrappers"),
    # A policy turns observations into actions: core, config and observations only. Loading a
    # trained model may need torch, SB3 and the gymnasium space classes pickled in it (inside
    # functions).
    Layer(
        "policies",
        only=(_CORE, _CONFIG),
        forbid=("pymunk",),
        lazy_only=("gymnasium", "torch", "stable_baselines3", "sb3_contrib"),
    ),
    Layer("semexplore_gym/expert_driven_envs.py"),
    Layer("semexplore_gym/evaluation"),
    Layer("semexplore_gym/training"),
    Layer("semexplore_gym/cli"),
]
_PROJECT_ROOTS = ("semexplore_gym", "policies")


def _imports(path: Path) -> list[tuple[int, str, bool]]:
    """(line, module, top_level) for every absolute import in a file."""
    tree = ast.parse(path.read_text(), filename=str(path))
    out = []
    top_level_nodes = set(map(id, tree.body))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name, id(node) in top_level_nodes) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.append((node.lineno, node.module, id(node) in top_level_nodes))
    return out


def _has_relative_import(path: Path) -> bool:
    tree = ast.parse(path.read_text(), filename=str(path))
    return any(isinstance(n, ast.ImportFrom) and n.level > 0 for n in ast.walk(tree))


def _layer_of_module(module: str, layers: list[Layer]) -> int | None:
    """Index of the layer a module of this project belongs to (the longest match)."""
    best, best_len = None, -1
    for i, layer in enumerate(layers):
        name = layer.module
        # A module layer (`expert_driven_envs.py`, the package root) holds that module only.
        inside = module == name or (
            not layer.path.endswith(".py") and module.startswith(name + ".")
        )
        if inside and len(name) > best_len:
            best, best_len = i, len(name)
    return best


def _files(root: Path, layer: Layer, layers: list[Layer]) -> list[Path]:
    """The layer's own files (a folder's, less those of a sub-layer listed separately)."""
    path = root / layer.path
    if path.is_file():
        return [path]
    own = _layer_of_module(layer.module, layers)
    return [
        f
        for f in sorted(path.rglob("*.py"))
        if _layer_of_module(_module_of_file(root, f), layers) == own
    ]


def _module_of_path(rel: str) -> str:
    """``policies/...`` is installed and imported as ``semexplore_gym.policies...``."""
    dotted = rel.replace("/", ".")
    return "semexplore_gym." + dotted if dotted.split(".")[0] == "policies" else dotted


def _module_of_file(root: Path, f: Path) -> str:
    rel = f.relative_to(root).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return _module_of_path("/".join(parts))


def layer_violations(root: Path, index: int, layers: list[Layer] = LAYERS) -> list[str]:
    """Every import of layer ``layers[index]`` under ``root`` that breaks the rules."""
    layer = layers[index]
    allowed = (
        set(range(index))
        if layer.only is None
        else {i for i, other in enumerate(layers) if other.path in layer.only}
    ) | {index}
    bad = []
    for f in _files(root, layer, layers):
        where = f.relative_to(root)
        if _has_relative_import(f):
            bad.append(f"{where}: relative import (write it absolute so the layers can be read)")
        for line, mod, top_level in _imports(f):
            top = mod.split(".")[0]
            if top in _PROJECT_ROOTS:
                target = _layer_of_module(mod, layers)
                if target is None:
                    bad.append(f"{where}:{line} imports {mod}, which is in no layer of LAYERS")
                elif target not in allowed:
                    bad.append(f"{where}:{line} imports {mod} ({layers[target].path})")
            elif top in layer.forbid:
                bad.append(f"{where}:{line} imports {mod}, which {layer.path} must not use")
            elif top in layer.lazy_only and top_level:
                bad.append(f"{where}:{line} imports {mod} at module level (import it lazily)")
    return bad


@pytest.mark.parametrize("index", range(len(LAYERS)), ids=[layer.path for layer in LAYERS])
def test_no_layer_imports_upward(index: int) -> None:
    assert _files(ROOT, LAYERS[index], LAYERS), f"layer {LAYERS[index].path} has no modules"
    bad = layer_violations(ROOT, index)
    assert not bad, "layering broken:\n" + "\n".join(bad)


def test_every_package_module_is_in_one_layer() -> None:
    orphans = [
        str(f.relative_to(ROOT))
        for top in _PROJECT_ROOTS
        for f in sorted((ROOT / top).rglob("*.py"))
        if _layer_of_module(_module_of_file(ROOT, f), LAYERS) is None
    ]
    assert not orphans, f"add these to LAYERS: {orphans}"


def test_layer_checker_detects_a_violation(tmp_path: Path) -> None:
    f = tmp_path / "m.py"
    f.write_text("import os\nfrom semexplore_gym.envs import x\n\ndef g():\n    import pymunk\n")
    mods = [m for _, m, _ in _imports(f)]
    assert mods == ["os", "semexplore_gym.envs", "pymunk"]


def test_layer_checker_fails_on_upward_and_outside_imports(tmp_path: Path) -> None:
    """A fake tree with one broken rule per file: the checker names every one of them."""
    fake = {
        "semexplore_gym/__init__.py": "from semexplore_gym.core import a\n",
        "semexplore_gym/core/__init__.py": "",
        "semexplore_gym/core/a.py": "import numpy\nfrom semexplore_gym.envs.e import Env\n",
        "semexplore_gym/core/b.py": "def f():\n    import gymnasium\n",
        "semexplore_gym/rendering/r.py": "import matplotlib.pyplot\n",
        "semexplore_gym/envs/e.py": "from semexplore_gym.sim import s\nfrom . import x\n",
        "semexplore_gym/sim/s.py": "from semexplore_gym.core import a\nimport semexplore_gym.nowhere\n",
        "policies/p.py": "from semexplore_gym.core import a\nfrom semexplore_gym.sim import s\n",
        "policies/q.py": "def f():\n    import torch\n",
    }
    for rel, text in fake.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    bad = {
        layer.path: layer_violations(tmp_path, i)
        for i, layer in enumerate(LAYERS)
        if (tmp_path / layer.path).exists()
    }
    assert bad == {
        "semexplore_gym/core": [
            "semexplore_gym/core/a.py:2 imports semexplore_gym.envs.e (semexplore_gym/envs)",
            "semexplore_gym/core/b.py:2 imports gymnasium, which semexplore_gym/core must not use",
        ],
        "semexplore_gym/__init__.py": [],
        "semexplore_gym/rendering": [
            "semexplore_gym/rendering/r.py:1 imports matplotlib.pyplot at module level"
            " (import it lazily)"
        ],
        "semexplore_gym/sim": [
            "semexplore_gym/sim/s.py:2 imports semexplore_gym.nowhere, which is in no layer of"
            " LAYERS"
        ],
        "semexplore_gym/envs": [
            "semexplore_gym/envs/e.py: relative import (write it absolute so the layers can be"
            " read)"
        ],
        "policies": ["policies/p.py:2 imports semexplore_gym.sim (semexplore_gym/sim)"],
    }


def test_layers_are_listed_lowest_first() -> None:
    """Every `only` names a layer listed earlier, and no path is listed twice."""
    paths = [layer.path for layer in LAYERS]
    assert len(set(paths)) == len(paths)
    for i, layer in enumerate(LAYERS):
        assert set(layer.only or ()) <= set(paths[:i]), layer.path


# ----------------------------------------------------------------------------------------------
# Whole-project import rules: no circle, no private names across modules, no IO in core
# ----------------------------------------------------------------------------------------------


def _project_modules(root: Path) -> dict[str, Path]:
    """Every module of the project by dotted name (``policies/`` as ``semexplore_gym.policies``)."""
    return {
        _module_of_file(root, f): f
        for top in _PROJECT_ROOTS
        for f in sorted((root / top).rglob("*.py"))
    }


def _import_targets(
    node: ast.Import | ast.ImportFrom, importer: str, is_package: bool
) -> list[tuple[str, str | None]]:
    """``(module, name)`` pairs an import statement names: ``import a.b`` gives ``("a.b",
    None)``, ``from a.b import c`` gives ``("a.b", "c")``; relative imports resolved."""
    if isinstance(node, ast.Import):
        return [(_module_of_path(a.name.replace(".", "/")), None) for a in node.names]
    base = node.module or ""
    if node.level:
        parts = importer.split(".")
        keep = len(parts) - node.level + (1 if is_package else 0)
        base = ".".join(parts[:keep] + ([base] if base else []))
    base = _module_of_path(base.replace(".", "/"))
    return [(base, a.name) for a in node.names]


def _import_nodes(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """Every import statement, at module level, in functions and under ``TYPE_CHECKING``."""
    return [n for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom))]


def import_graph(root: Path) -> dict[str, dict[str, int]]:
    """Module -> {imported project module: first line}. ``from a import b`` points at the
    module ``a.b`` when there is one, else at ``a``. Only the module named counts, not the
    packages above it (Python runs their ``__init__`` too, but counting them would make every
    package that re-exports its modules a circle)."""
    modules = _project_modules(root)
    graph: dict[str, dict[str, int]] = {m: {} for m in modules}
    for mod, f in modules.items():
        tree = ast.parse(f.read_text(), filename=str(f))
        for node in _import_nodes(tree):
            for base, name in _import_targets(node, mod, f.name == "__init__.py"):
                target = f"{base}.{name}" if name and f"{base}.{name}" in modules else base
                if target in modules and target != mod:
                    graph[mod].setdefault(target, node.lineno)
    return graph


def import_cycles(graph: dict[str, dict[str, int]]) -> list[list[str]]:
    """One cycle (first module repeated at the end) per strongly connected group of modules."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[list[str]] = []
    for start in sorted(graph):
        if start in index:
            continue
        # iterative Tarjan: (node, iterator over its successors)
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, succ = work[-1]
            nxt = next(succ, None)
            if nxt is not None:
                if nxt not in index:
                    index[nxt] = low[nxt] = len(index)
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph[nxt]))))
                elif nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                group = []
                while True:
                    m = stack.pop()
                    on_stack.discard(m)
                    group.append(m)
                    if m == node:
                        break
                if len(group) > 1:
                    groups.append(sorted(group))
    cycles = []
    for group in groups:
        members = set(group)
        first = group[0]
        # shortest way back to `first` inside the group (breadth first)
        came_from: dict[str, str] = {}
        frontier = [first]
        while first not in came_from:
            nxt_frontier = []
            for m in frontier:
                for t in sorted(graph[m]):
                    if t in members and t not in came_from:
                        came_from[t] = m
                        nxt_frontier.append(t)
            frontier = nxt_frontier
        path = [first]
        while path[-1] != first or len(path) == 1:
            path.append(came_from[path[-1]])
        cycles.append(path[::-1])
    return cycles


def _describe_cycle(cycle: list[str], graph: dict[str, dict[str, int]]) -> str:
    steps = [f"{a} (line {graph[a][b]}) -> {b}" for a, b in pairwise(cycle)]
    return "\n    ".join(steps)


def test_no_import_circle() -> None:
    """Module-level, function-level and ``TYPE_CHECKING`` imports all count: a circle hidden in
    a function is still one module needing the other's finished definitions."""
    graph = import_graph(ROOT)
    cycles = import_cycles(graph)
    assert not cycles, (
        "import circles (break each by moving what both need into a third module):\n  "
        + ("\n  ".join(_describe_cycle(c, graph) for c in cycles))
    )


def _owner_allows(owner: str, importer: str) -> bool:
    """A private name belongs to the module (or package) ``owner`` that defines it."""
    return importer == owner or importer.startswith(owner + ".")


def _private_parts(dotted: str) -> list[tuple[str, str]]:
    """``(owner, name)`` for every ``_name`` (not dunder) in a dotted path."""
    parts = dotted.split(".")
    return [
        (".".join(parts[:i]), p)
        for i, p in enumerate(parts)
        if p.startswith("_") and not (p.startswith("__") and p.endswith("__"))
    ]


def private_name_uses(root: Path) -> list[str]:
    """Imports of another module's ``_names`` (``from m import _x``, ``import pkg._m`` from
    outside ``pkg``) and ``m._x`` read on an imported module ``m``. A package's private modules
    may be used by the modules of that package."""
    modules = _project_modules(root)
    bad = []
    for mod, f in modules.items():
        where = f.relative_to(root)
        tree = ast.parse(f.read_text(), filename=str(f))
        bound: dict[str, str] = {}  # local name -> project module it names
        for node in _import_nodes(tree):
            for base, name in _import_targets(node, mod, f.name == "__init__.py"):
                if base.split(".")[0] != "semexplore_gym":
                    continue
                dotted = f"{base}.{name}" if name else base
                for owner, private in _private_parts(dotted):
                    if not _owner_allows(owner, mod):
                        bad.append(f"{where}:{node.lineno} imports {private} of {owner}")
                        break
                if isinstance(node, ast.Import):
                    alias = next(
                        a for a in node.names if _module_of_path(a.name.replace(".", "/")) == base
                    )
                    if alias.asname:
                        bound[alias.asname] = base
                    else:
                        top = alias.name.split(".")[0]
                        bound[top] = _module_of_path(top)
                elif name and dotted in modules:
                    asname = next(a.asname for a in node.names if a.name == name)
                    bound[asname or name] = dotted
        for node in ast.walk(tree):
            if not isinstance(node, ast.Attribute) or not _private_parts(node.attr):
                continue
            chain = _dotted_module(node.value, bound, modules)
            if chain is not None and not _owner_allows(chain, mod):
                bad.append(f"{where}:{node.lineno} reads {node.attr} of {chain}")
    return bad


def _dotted_module(expr: ast.expr, bound: dict[str, str], modules: dict[str, Path]) -> str | None:
    """The project module an expression like ``m`` or ``pkg.sub`` names, or None."""
    if isinstance(expr, ast.Name):
        return bound.get(expr.id)
    if isinstance(expr, ast.Attribute):
        base = _dotted_module(expr.value, bound, modules)
        if base is not None and f"{base}.{expr.attr}" in modules:
            return f"{base}.{expr.attr}"
    return None


def test_no_module_uses_another_modules_private_names() -> None:
    bad = private_name_uses(ROOT)
    assert not bad, "private names used outside their module (make them public or move them):\n" + (
        "\n".join(bad)
    )


#: Modules that read or write files, sockets or serialised data: the edges' business, not core's.
IO_MODULES = ("yaml", "json", "pickle", "urllib", "http", "tempfile", "shutil", "PIL")


def test_core_imports_no_io_module() -> None:
    """``core`` is algorithms on arrays: loading, saving and fetching live above it."""
    core = next(i for i, layer in enumerate(LAYERS) if layer.path == _CORE)
    bad = [
        f"{f.relative_to(ROOT)}:{line} imports {mod}"
        for f in _files(ROOT, LAYERS[core], LAYERS)
        for line, mod, _ in _imports(f)
        if mod.split(".")[0] in IO_MODULES
    ]
    assert not bad, "core imports IO modules:\n" + "\n".join(bad)


def test_import_rule_checkers_find_circles_and_private_names(tmp_path: Path) -> None:
    """A fake tree with a circle through a function-level import, one through
    ``TYPE_CHECKING``, and private names used across modules."""
    fake = {
        "semexplore_gym/__init__.py": "",
        "semexplore_gym/core/__init__.py": "",
        "semexplore_gym/core/a.py": "def f():\n    from semexplore_gym.core.b import g\n",
        "semexplore_gym/core/b.py": "from semexplore_gym.core import a\n_g = 1\n",
        "semexplore_gym/core/c.py": (
            "from typing import TYPE_CHECKING\n"
            "if TYPE_CHECKING:\n    from semexplore_gym.core.d import D\n"
        ),
        "semexplore_gym/core/d.py": "from semexplore_gym.core.c import x\n",
        "semexplore_gym/core/e.py": (
            "import semexplore_gym.core.b as bm\nfrom semexplore_gym.core.b import _g\n"
            "from semexplore_gym.core import _p\nimport semexplore_gym.core.b\n"
            "y = bm._g + semexplore_gym.core.b._g + bm.__name__\n"
        ),
        "semexplore_gym/core/_p.py": "from semexplore_gym.core import b\n",
        "policies/q.py": "from . import _r\nfrom semexplore_gym.policies._r import _s\n",
        "policies/_r.py": "_s = 1\n",
    }
    for rel, text in fake.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    graph = import_graph(tmp_path)
    assert graph["semexplore_gym.core.a"] == {"semexplore_gym.core.b": 2}
    assert import_cycles(graph) == [
        ["semexplore_gym.core.a", "semexplore_gym.core.b", "semexplore_gym.core.a"],
        ["semexplore_gym.core.c", "semexplore_gym.core.d", "semexplore_gym.core.c"],
    ]
    assert private_name_uses(tmp_path) == [
        "semexplore_gym/core/e.py:2 imports _g of semexplore_gym.core.b",
        "semexplore_gym/core/e.py:5 reads _g of semexplore_gym.core.b",
        "semexplore_gym/core/e.py:5 reads _g of semexplore_gym.core.b",
        "policies/q.py:2 imports _s of semexplore_gym.policies._r",
    ]
