"""The layering rule of STYLE.md, as one ordered list: each layer may import only the layers
listed before it (lowest first), and some layers keep outside packages out or import them only
lazily. ``policies`` sit above the env layers but may use only ``core``; the runners
(``evaluation``, ``training``) and the CLI sit on top."""

from __future__ import annotations

import ast
from dataclasses import dataclass
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
        ),
    ),
    # The package root registers the env ids by string; `import semexplore_gym.core` runs it,
    # so it must not pull gymnasium in at import time.
    Layer("semexplore_gym/__init__.py", lazy_only=("gymnasium",)),
    Layer("semexplore_gym/maps"),
    Layer("semexplore_gym/rendering", lazy_only=("matplotlib", "pygame")),
    Layer("semexplore_gym/sim", forbid=("gymnasium",)),
    Layer("semexplore_gym/envs"),
    Layer("semexplore_gym/wrappers"),
    # A policy turns observations into actions: core and observations only. Loading a trained
    # model may need torch, SB3 and the gymnasium space classes pickled in it (inside functions).
    Layer(
        "policies",
        only=(_CORE,),
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
