"""Saved learners: the model zip runs through ``SB3Policy`` and the registry."""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest
from _imitation import PARAMS, imitation_env, learner_policy

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def test_saved_policy_runs_through_sb3_policy(tmp_path: Path) -> None:
    from semexplore_gym.policies.sb3_policy import SB3Policy

    from semexplore_gym.training.learner import save_policy
    from semexplore_gym.wrappers.egocentric import egocentric_features

    env = imitation_env()
    policy = learner_policy(seed=4)
    path = save_policy(policy, tmp_path / "model.zip", PARAMS)
    agent = SB3Policy(path)
    assert agent.params == PARAMS
    obs, info = env.reset(seed=2)
    agent.reset(obs, info, seed=0)
    for _ in range(4):
        a = agent.act(obs, info)
        assert a.shape == (2,) and a.dtype == np.float32 and np.all(np.abs(a) <= 1)
        expected, _ = policy.predict(egocentric_features(obs, info, PARAMS), deterministic=True)
        np.testing.assert_allclose(a, np.clip(expected, -1, 1), rtol=1e-5, atol=1e-6)
        obs, _r, _te, _tr, info = env.step(a)
    assert agent.last_stats.local_planning_ms > 0
    env.close()


def test_sb3_policy_rejects_bad_files(tmp_path: Path) -> None:
    pytest.importorskip("torch")
    from semexplore_gym.policies.sb3_policy import SB3Policy

    with pytest.raises(FileNotFoundError):
        SB3Policy(tmp_path / "missing.zip")
    bad = tmp_path / "bad.zip"
    with zipfile.ZipFile(bad, "w") as z:
        z.writestr("x.txt", "hello")
    with pytest.raises(ValueError, match="neither"):
        SB3Policy(bad)


def test_registry_builds_sb3_policy(tmp_path: Path) -> None:
    registry = pytest.importorskip("semexplore_gym.policies.registry")
    from semexplore_gym.training.learner import save_policy

    pytest.importorskip("torch")
    path = save_policy(learner_policy(), tmp_path / "m.zip", PARAMS)
    agent = registry.make_policy(f"sb3:{path}")
    assert type(agent).__name__ == "SB3Policy" and agent.params == PARAMS
