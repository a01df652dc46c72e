"""DAgger: beta schedules and a round that mixes drivers and grows the aggregate."""

from __future__ import annotations

from pathlib import Path

import pytest
from _imitation import PARAMS, ReactiveExpert, imitation_env, learner_policy

from semexplore_gym.training.dagger import beta_schedule
from semexplore_gym.training.dataset import ImitationDataset

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def test_beta_schedule() -> None:
    exp = beta_schedule(0.5)
    assert [exp(i) for i in range(3)] == [1.0, 0.5, 0.25]
    seq = beta_schedule([0.8, 0.2])
    assert [seq(i) for i in range(4)] == [0.8, 0.2, 0.2, 0.2]
    with pytest.raises(ValueError, match="beta"):
        beta_schedule(1.5)


def test_dagger_round_runs_and_grows_the_dataset(tmp_path: Path) -> None:
    from semexplore_gym.training.dagger import run_dagger
    from semexplore_gym.training.recording import record_expert_dataset
    from semexplore_gym.training.train_config import (
        BCSection,
        DaggerSection,
        ExpertSection,
        TrainConfig,
    )
    from semexplore_gym.training.workers import EpisodeActors

    env = imitation_env()
    base = record_expert_dataset(
        EpisodeActors(env, ReactiveExpert()), None, PARAMS, ExpertSection(episodes=1, max_steps=20)
    )
    policy = learner_policy()
    cfg = TrainConfig(
        seed=3,
        egocentric=PARAMS,
        expert=ExpertSection(max_steps=20),
        bc=BCSection(batch_size=16),
        dagger=DaggerSection(rounds=2, beta=(0.5, 0.0), episodes_per_round=1, epochs_per_round=1),
    )
    result = run_dagger(
        EpisodeActors(env, ReactiveExpert()),
        policy,
        cfg,
        dataset=base,
        dataset_path=tmp_path / "agg.npz",
    )
    assert len(result.dataset) == len(base) + 40 and result.dataset.n_episodes == 3
    assert [r["dataset_size"] for r in result.rounds] == [len(base) + 20, len(base) + 40]
    assert 0.0 < result.rounds[0]["expert_fraction"] < 1.0  # beta = 0.5 mixes both drivers
    assert result.rounds[1]["expert_fraction"] == 0.0  # beta = 0: the learner drives alone
    assert len(ImitationDataset.load(tmp_path / "agg.npz")) == len(result.dataset)
    env.close()
