"""Policies flagged ``reads_map_in_step_only`` run the same missions on a shared map.

The mission runners (``semexplore explore``/``benchmark``, weight tuning, ``bench_expert``)
hand such policies the env's read-only live map (``map_observation="shared"``) instead of a
fresh copy per step. That is only right if the policy keeps no reference to an earlier
step's map: a policy that did would see the map change under it and drive differently. Every
registered policy with the flag is run here with both observations, step by step.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.base import Policy
from semexplore_gym.policies.registry import make_policy, policy_factories

import semexplore_gym  # noqa: F401
from semexplore_gym.evaluation.rollout import map_observation_for, run_mission

#: Registered names that need an argument (a model file, a module) are not built here.
_ARGUMENT_POLICIES = {"py", "sb3", "pretrained", "option-ppo"}
FLAGGED = sorted(
    name
    for name in policy_factories()
    if name not in _ARGUMENT_POLICIES and make_policy(name).reads_map_in_step_only
)
WORLDS = ["maze:seed=3,size_m=8", "office:seed=5,size_m=12", "cave:seed=7,size_m=10"]


def _mission(world: str, spec: str, map_observation: str) -> list[tuple]:
    policy = make_policy(spec)
    env = gym.make(
        "SemanticExplore-v0",
        world=world,
        map_observation=map_observation,
        disable_env_checker=True,
        config={"episode": {"random_start": True}},
        # the oracle reads the true world at reset: the runners make its env privileged
        **{"privileged": True} if getattr(policy, "privileged", False) else {},
    )
    steps: list[tuple] = []
    try:
        run_mission(
            env,
            policy,
            seed=11,
            max_time_s=120.0,
            ignore_terminated=True,
            on_step=lambda i, obs, info, action, pol: steps.append(
                (obs["pose"].tobytes(), action.tobytes(), info["coverage"])
            ),
        )
    finally:
        env.close()
    return steps


def test_the_scripted_policies_are_flagged() -> None:
    assert {"semantic", "semantic-paper", "frontier", "nearest", "frontier-value"} <= set(FLAGGED)
    assert not make_policy("random").reads_map_in_step_only


@pytest.mark.parametrize("spec", FLAGGED)
@pytest.mark.parametrize("world", WORLDS)
def test_flagged_policy_drives_the_same_with_a_shared_map(spec: str, world: str) -> None:
    copied = _mission(world, spec, "copy")
    shared = _mission(world, spec, "shared")
    assert len(copied) > 30
    assert shared == copied


def test_runners_give_the_shared_map_only_to_flagged_policies() -> None:
    class Keeper(Policy):  # keeps every map it saw: must get copies
        def act(self, obs, info):
            return np.zeros(2, dtype=np.float32)

    assert map_observation_for(make_policy("semantic")) == {
        "map_observation": "shared",
        "disable_env_checker": True,
    }
    assert map_observation_for(Keeper()) == {}
    assert map_observation_for(make_policy("random")) == {}
