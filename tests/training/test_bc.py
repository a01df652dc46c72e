"""Behaviour cloning: held-out action error falls; best-epoch restore; mirroring."""

from __future__ import annotations

import numpy as np
import pytest
from _imitation import PARAMS, ReactiveExpert, imitation_env, learner_policy

from semexplore_gym.training.train_config import BCSection, ExpertSection
from semexplore_gym.training.workers import EpisodeActors
from semexplore_gym.wrappers.egocentric import EgocentricParams

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def test_bc_reduces_heldout_action_error() -> None:
    from semexplore_gym.training.bc import action_error, train_bc
    from semexplore_gym.training.recording import record_expert_dataset

    env = imitation_env()
    data = record_expert_dataset(
        EpisodeActors(env, ReactiveExpert()), None, PARAMS, ExpertSection(episodes=5, max_steps=60)
    )
    train, held = data.split_by_episode(0.2, np.random.default_rng(0))
    assert held.n_episodes == 1
    policy = learner_policy()
    before = action_error(policy, held)
    hist = train_bc(train, policy, BCSection(epochs=12, batch_size=32, lr=1e-3), seed=0)
    after = action_error(policy, held)
    assert hist["loss"][-1] < hist["loss"][0]
    assert after < 0.6 * before, (before, after)
    env.close()


def test_select_best_restores_the_best_epoch_and_mirroring_trains() -> None:
    from semexplore_gym.training.bc import action_error, train_bc
    from semexplore_gym.training.recording import record_expert_dataset

    env = imitation_env()
    params = EgocentricParams(
        crop_cells=36, crop_resolution_m=0.15, n_scan_bins=72, scan_bins_centred=True
    )
    data = record_expert_dataset(
        EpisodeActors(env, ReactiveExpert()), None, params, ExpertSection(episodes=3, max_steps=40)
    )
    train, held = data.split_by_episode(0.34, np.random.default_rng(0))
    from gymnasium import spaces

    from semexplore_gym.training.learner import make_learner_policy
    from semexplore_gym.wrappers.egocentric import egocentric_observation_space

    policy = make_learner_policy(
        egocentric_observation_space(params),
        spaces.Box(-1.0, 1.0, (2,), np.float32),
        net_arch=[32],
        features_extractor_kwargs={"cnn_output_dim": 16},
    )
    # A learning rate this large makes the held-out error jump around between epochs.
    hist = train_bc(
        train,
        policy,
        BCSection(
            epochs=5, batch_size=16, lr=3e-3, select_best=True, mirror=True, lr_final_fraction=0.1
        ),
        eval_data=held,
        egocentric=params,
    )
    errs = hist["eval_action_error"]
    assert len(errs) == 5 and hist["best_epoch"] == [float(int(np.argmin(errs)))]
    assert action_error(policy, held) == pytest.approx(min(errs), rel=1e-6)
    with pytest.raises(ValueError, match="scan_bins_centred"):
        train_bc(train, policy, BCSection(epochs=1, mirror=True), egocentric=PARAMS)
    env.close()
