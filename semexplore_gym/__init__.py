"""SemanticExplore: semantic topometric exploration with a simulated TurtleBot3.

``import semexplore_gym`` registers the Gymnasium env ``SemanticExplore-v0``::

    import gymnasium as gym
    import semexplore_gym
    env = gym.make("SemanticExplore-v0", world="maze1")
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import sys
from pathlib import Path

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

__version__ = "0.1.0"
__all__ = ["FREE", "OCCUPIED", "UNKNOWN", "GridGeometry", "register_envs", "__version__"]


def register_envs() -> None:
    """Register the package's env ids with Gymnasium (idempotent, by string entry point)."""
    from gymnasium.envs.registration import register, registry

    ids = {
        "SemanticExplore-v0": "semexplore_gym.envs.semantic_explore:SemanticExploreEnv",
        "SemanticExploreFrontier-v0": "semexplore_gym.expert_driven_envs:make_frontier_choice_env",
        "SemanticExploreWeights-v0": "semexplore_gym.expert_driven_envs:make_planner_weights_env",
    }
    for env_id, entry_point in ids.items():
        if env_id not in registry:
            register(id=env_id, entry_point=entry_point)


class _CheckoutPolicies(importlib.machinery.PathFinder):
    """Imports ``semexplore_gym.policies`` from a source checkout's top-level ``policies/``.

    The repository keeps the policies in ``policies/`` beside this package; the wheel installs
    them as ``semexplore_gym/policies`` (``setup.py`` maps the folder), so there is no
    top-level ``policies`` module in site-packages. Running from a checkout (``pytest``, a git
    worktree, ``PYTHONPATH=.``) finds the folder through this finder instead.
    """

    NAME = "semexplore_gym.policies"

    @classmethod
    def find_spec(cls, fullname, path=None, target=None):  # type: ignore[no-untyped-def]
        if fullname != cls.NAME:
            return None
        folder = Path(__file__).resolve().parent.parent / "policies"
        if not (folder / "__init__.py").is_file():
            return None
        return importlib.util.spec_from_file_location(
            fullname, folder / "__init__.py", submodule_search_locations=[str(folder)]
        )


if not (Path(__file__).parent / "policies").is_dir() and not any(
    getattr(f, "NAME", None) == _CheckoutPolicies.NAME for f in sys.meta_path
):
    sys.meta_path.insert(0, _CheckoutPolicies)

register_envs()
