"""Every policy says "call reset(obs, info, seed=...) first" when ``act`` comes before ``reset``."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.base import PolicyNotResetError
from semexplore_gym.policies.registry import make_policy, policy_factories

PRETRAINED = Path(__file__).resolve().parents[2] / "policies" / "pretrained"

OWN_POLICY = '''
import numpy as np
from semexplore_gym.policies.base import Policy

class Spinner(Policy):
    """Overrides reset without calling super().reset."""

    def reset(self, obs, info, seed=None):
        self.turn = 0.5

    def act(self, obs, info):
        return np.array([0.0, self.turn], dtype=np.float32)
'''

#: One spec per name of the registry (the oracle needs a privileged env to reset).
SPECS = {
    "semantic": "semantic",
    "semantic-paper": "semantic-paper",
    "semantic-v2": "semantic-v2",
    "semantic-v3": "semantic-v3",
    "semantic-v4": "semantic-v4",
    "frontier-value": "frontier-value",
    "frontier-student": "frontier-student",
    "frontier": "frontier",
    "nearest": "nearest",
    "random": "random",
    "oracle": "oracle",
    "sb3": f"sb3:{PRETRAINED / 'dagger_maze' / 'model.zip'}",
    "pretrained": "pretrained:frontier_choice_maze",
    "option-ppo": f"option-ppo:{PRETRAINED / 'option_ppo' / 'model.zip'}",
    "py": "py:{own}:Spinner",
}


def test_every_registry_name_is_covered() -> None:
    assert set(SPECS) == set(policy_factories())


@pytest.fixture(scope="module")
def env():
    e = gym.make("SemanticExplore-v0", world="maze:seed=3,size_m=4", privileged=True)
    yield e
    e.close()


@pytest.mark.parametrize("name", sorted(SPECS))
def test_act_before_reset_names_the_missing_call(name, env, tmp_path) -> None:
    pytest.importorskip("torch") if name in ("sb3", "pretrained", "option-ppo") else None
    own = tmp_path / "own_policy.py"
    own.write_text(OWN_POLICY)
    policy = make_policy(SPECS[name].format(own=own))
    obs, info = env.reset(seed=0)
    with pytest.raises(PolicyNotResetError, match=r"call reset\(obs, info, seed=\.\.\.\) first"):
        policy.act(obs, info)
    assert issubclass(PolicyNotResetError, RuntimeError)
    policy.reset(obs, info, seed=0)
    action = np.asarray(policy.act(obs, info))
    assert action.shape == (2,) and np.all(np.abs(action) <= 1.0)


def test_a_reset_that_fails_leaves_the_policy_unusable(env) -> None:
    policy = make_policy("semantic")
    obs, info = env.reset(seed=0)
    policy.reset(obs, info, seed=0)
    with pytest.raises(ValueError):
        policy.reset(obs, {}, seed=0)  # no map_geometry
    with pytest.raises(PolicyNotResetError):
        policy.act(obs, info)


TEAM_NAMES = [
    "independent",
    "greedy",
    "coordinated",
    "coordinated_nobranch",
    "semantic",
    "semantic_nosem",
    "oracle",
]


def test_every_team_policy_is_covered() -> None:
    from semexplore_gym.policies.team import team_policy_names

    assert sorted(TEAM_NAMES) == sorted(team_policy_names())


@pytest.mark.parametrize("name", TEAM_NAMES)
def test_team_policies_say_the_same(name) -> None:
    pytest.importorskip("pettingzoo")
    from semexplore_gym.policies.team import make_team_policy

    from semexplore_gym.envs.multi_robot import make_multi

    team = make_team_policy(name)
    privileged = getattr(team, "privileged", False)  # the team oracle reads the true world
    env = make_multi(world="maze:seed=3,size_m=4", n_robots=2, privileged=privileged)
    try:
        observations, infos = env.reset(seed=0)
        with pytest.raises(
            PolicyNotResetError, match=r"call reset\(obs, info, seed=\.\.\.\) first"
        ):
            team.act(observations, infos)
        team.reset(observations, infos, seed=0)
        assert set(team.act(observations, infos)) == set(observations)
    finally:
        env.close()
