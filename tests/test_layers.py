"""The layering rule of STYLE.md: core <- sim <- envs <- wrappers; policies use core only;
the runners (evaluation, training) sit on top and only the CLI and scripts import training."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# For each layer: module prefixes it must never import. Runners sit on top: `evaluation` may use
# envs and policies, `training` anything but the CLI; only the CLI and scripts import `training`.
_ABOVE_WRAPPERS = [
    "semexplore_gym.cli",
    "semexplore_gym.evaluation",
    "semexplore_gym.training",
    "semexplore_gym.macro_envs",
]
FORBIDDEN = {
    "semexplore_gym/core": [
        "gymnasium",
        "pymunk",
        "semexplore_gym.sim",
        "semexplore_gym.envs",
        "semexplore_gym.wrappers",
        "semexplore_gym.rendering",
        *_ABOVE_WRAPPERS,
        "policies",
        "torch",
        "stable_baselines3",
        "matplotlib",
        "pygame",
    ],
    "semexplore_gym/sim": [
        "gymnasium",
        "semexplore_gym.envs",
        "semexplore_gym.wrappers",
        *_ABOVE_WRAPPERS,
        "policies",
    ],
    "semexplore_gym/envs": ["semexplore_gym.wrappers", *_ABOVE_WRAPPERS, "policies"],
    "semexplore_gym/wrappers": [*_ABOVE_WRAPPERS, "policies"],
    "semexplore_gym/rendering": ["semexplore_gym.cli", "semexplore_gym.training"],
    "semexplore_gym/macro_envs.py": ["semexplore_gym.cli", "semexplore_gym.training"],
    "policies": [
        "pymunk",
        "semexplore_gym.sim",
        "semexplore_gym.envs",
        "semexplore_gym.wrappers",
        *_ABOVE_WRAPPERS,
    ],
    "semexplore_gym/evaluation": ["semexplore_gym.cli", "semexplore_gym.training"],
    "semexplore_gym/training": ["semexplore_gym.cli"],
}


def _imports(path: Path) -> list[tuple[int, str, bool]]:
    """(line, module, top_level) for every import in a file."""
    tree = ast.parse(path.read_text(), filename=str(path))
    out = []
    top_level_nodes = set(map(id, tree.body))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name, id(node) in top_level_nodes) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.append((node.lineno, node.module, id(node) in top_level_nodes))
    return out


def _files(layer: str) -> list[Path]:
    path = ROOT / layer
    return [path] if path.is_file() else sorted(path.rglob("*.py"))


@pytest.mark.parametrize("layer", sorted(FORBIDDEN))
def test_no_layer_imports_upward(layer: str) -> None:
    files = _files(layer)
    assert files, f"layer {layer} has no modules"
    bad = []
    for f in files:
        for line, mod, _top in _imports(f):
            for prefix in FORBIDDEN[layer]:
                if mod == prefix or mod.startswith(prefix + "."):
                    # Policies may import matplotlib/torch lazily; the forbidden lists name only
                    # layers, so any hit is an upward import.
                    bad.append(f"{f.relative_to(ROOT)}:{line} imports {mod}")
    assert not bad, "upward imports:\n" + "\n".join(bad)


def test_layer_checker_detects_a_violation(tmp_path: Path) -> None:
    f = tmp_path / "m.py"
    f.write_text("import os\nfrom semexplore_gym.envs import x\n\ndef g():\n    import pymunk\n")
    mods = [m for _, m, _ in _imports(f)]
    assert mods == ["os", "semexplore_gym.envs", "pymunk"]
