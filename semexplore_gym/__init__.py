"""SemanticExplore: semantic topometric exploration with a simulated TurtleBot3.

``import semexplore_gym`` registers the Gymnasium env ``SemanticExplore-v0`` (and the
macro-action ids) and stays light: the public API below is imported on first use::

    import gymnasium as gym
    import semexplore_gym
    env = gym.make("SemanticExplore-v0", world="maze1")
    venv = gym.make_vec("SemanticExplore-v0", num_envs=4)      # FastSyncVectorEnv

    from semexplore_gym import make_mission_env, make_policy, run_mission
    policy = make_policy("semantic")
    env = make_mission_env("maze1", "paper")
    result = run_mission(env, policy, seed=0, max_time_s=600)
    print(result.coverage, result.mission_time_s)

The public names: :func:`make_policy` (policy specs, as ``--policy`` spells them),
:func:`run_mission` and :func:`make_mission_env`, :func:`record_expert_dataset` with
:class:`EgocentricParams`, :func:`make_world` and :func:`list_world_names`, :func:`load_suite`
and :func:`list_suites`, :func:`load_env_config` and :class:`EnvConfig`,
:func:`pretrained_models`, :class:`FastSyncVectorEnv`, :func:`warm_up`.
"""

from __future__ import annotations

import importlib
import importlib.machinery
import importlib.util
import sys
from pathlib import Path

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

__version__ = "0.3.0"

#: The public API served by :func:`__getattr__`: name -> the module that defines it. Imported on
#: first use, so that ``import semexplore_gym`` (which every ``semexplore_gym.*`` import runs)
#: pulls in neither gymnasium nor the env, the policies or the runners, and so that the package
#: root, low in the layer order (tests/test_layers.py), names the layers above it only as data.
PUBLIC_API: dict[str, str] = {
    "make_policy": "semexplore_gym.policies.registry",
    "run_mission": "semexplore_gym.evaluation.rollout",
    "make_mission_env": "semexplore_gym.evaluation.rollout",
    "MissionResult": "semexplore_gym.evaluation.rollout",
    "record_expert_dataset": "semexplore_gym.training.recording",
    "EpisodeActors": "semexplore_gym.training.workers",
    "ExpertSection": "semexplore_gym.training.train_config",
    "EgocentricParams": "semexplore_gym.core.features.egocentric",
    "make_world": "semexplore_gym.maps",
    "list_world_names": "semexplore_gym.core.worlds",
    "load_suite": "semexplore_gym.evaluation.suites",
    "list_suites": "semexplore_gym.evaluation.suites",
    "load_env_config": "semexplore_gym.envs.env_config",
    "EnvConfig": "semexplore_gym.envs.env_config",
    "ObservationOptions": "semexplore_gym.envs.observation_options",
    "pretrained_models": "semexplore_gym.policies.pretrained",
    "FastSyncVectorEnv": "semexplore_gym.envs.vector",
    "warm_up": "semexplore_gym.evaluation.warmup",
}

__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "GridGeometry",
    "register_envs",
    "__version__",
    *PUBLIC_API,
]


def __getattr__(name: str) -> object:
    """The public API (:data:`PUBLIC_API`), imported when first asked for."""
    module = PUBLIC_API.get(name)
    if module is None:
        raise AttributeError(f"module 'semexplore_gym' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later lookups skip __getattr__
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *PUBLIC_API})


def register_envs() -> None:
    """Register the package's env ids with Gymnasium (idempotent, by string entry point)."""
    from gymnasium.envs.registration import register, registry

    ids = {
        "SemanticExplore-v0": "semexplore_gym.envs.semantic_explore:SemanticExploreEnv",
        "SemanticExploreFrontier-v0": "semexplore_gym.expert_driven_envs:make_frontier_choice_env",
        "SemanticExploreWeights-v0": "semexplore_gym.expert_driven_envs:make_planner_weights_env",
        "SemanticExploreOptions-v0": "semexplore_gym.expert_driven_envs:make_option_choice_env",
    }
    # gym.make_vec("SemanticExplore-v0", num_envs=n) builds the batched FastSyncVectorEnv
    # (vectorization_mode="sync" still gives gymnasium's SyncVectorEnv).
    vector = {"SemanticExplore-v0": "semexplore_gym.envs.vector:make_vector_env"}
    for env_id, entry_point in ids.items():
        if env_id not in registry:
            register(id=env_id, entry_point=entry_point, vector_entry_point=vector.get(env_id))


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
