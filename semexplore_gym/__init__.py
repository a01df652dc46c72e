"""SemanticExplore: semantic topometric exploration with a simulated TurtleBot3.

``import semexplore_gym`` registers the Gymnasium env ``SemanticExplore-v0``::

    import gymnasium as gym
    import semexplore_gym
    env = gym.make("SemanticExplore-v0", world="maze1")
"""

from __future__ import annotations

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

__version__ = "0.1.0"
__all__ = ["FREE", "OCCUPIED", "UNKNOWN", "GridGeometry", "register_envs", "__version__"]


def register_envs() -> None:
    """Register the package's env ids with Gymnasium (idempotent, by string entry point)."""
    from gymnasium.envs.registration import register, registry

    ids = {
        "SemanticExplore-v0": "semexplore_gym.envs.semantic_explore:SemanticExploreEnv",
        "SemanticExploreFrontier-v0": "semexplore_gym.macro_envs:make_frontier_choice_env",
        "SemanticExploreWeights-v0": "semexplore_gym.macro_envs:make_planner_weights_env",
    }
    for env_id, entry_point in ids.items():
        if env_id not in registry:
            register(id=env_id, entry_point=entry_point)


register_envs()
