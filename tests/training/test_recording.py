"""Recording expert episodes: labelled states, DART noise on execution only."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _imitation import PARAMS, ConstantExpert, ReactiveExpert, imitation_env

from semexplore_gym.training.dataset import ImitationDataset
from semexplore_gym.training.train_config import ExpertSection
from semexplore_gym.training.workers import EpisodeActors

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def test_expert_recording_writes_labelled_episodes(tmp_path: Path) -> None:
    from semexplore_gym.training.recording import record_expert_dataset

    env = imitation_env()
    data = record_expert_dataset(
        EpisodeActors(env, ReactiveExpert()),
        tmp_path / "e.npz",
        PARAMS,
        ExpertSection(episodes=2, max_steps=15),
        seed=5,
    )
    back = ImitationDataset.load(tmp_path / "e.npz")
    assert len(back) == len(data) == 30 and back.n_episodes == 2
    assert back.obs["image"].shape == (30, 1, 36, 36) and back.obs["image"].dtype == np.uint8
    assert back.meta["egocentric"] == PARAMS.to_dict() and back.meta["expert"] == "reactive"
    # Labels are the expert's actions on the recorded states: re-derive the first one.
    obs, info = env.reset(seed=5)
    expert = ReactiveExpert()
    expert.reset(obs, info, seed=5)
    np.testing.assert_array_equal(back.actions[0], expert.act(obs, info))
    env.close()


def test_dart_noise_perturbs_execution_not_labels() -> None:
    from semexplore_gym.training.episodes import EpisodeSpec, rollout_episode

    env = imitation_env()

    def run(noise_std: float, rng_seed: int) -> tuple[np.ndarray, np.ndarray]:
        """(scans seen, labels) of a 12-step episode from the same start."""
        rec = rollout_episode(
            env,
            ConstantExpert(),
            PARAMS,
            EpisodeSpec(seed=4, max_steps=12, noise_std=noise_std),
            rng=np.random.default_rng(rng_seed),
        )
        return rec.data.obs["scan"], rec.data.actions

    clean_end, clean_labels = run(0.0, 0)
    noisy_end, noisy_labels = run(0.3, 0)
    again_end, _ = run(0.3, 0)
    other_end, _ = run(0.3, 1)
    # Labels are the clean expert action whatever was executed.
    np.testing.assert_array_equal(noisy_labels, np.tile([0.5, 0.0], (12, 1)))
    np.testing.assert_array_equal(clean_labels, noisy_labels)
    # The noise changes what happens, and comes only from the given generator.
    assert not np.array_equal(clean_end, noisy_end)
    np.testing.assert_array_equal(noisy_end, again_end)
    assert not np.array_equal(noisy_end, other_end)
    with pytest.raises(ValueError, match="noise_std"):
        rollout_episode(
            env, ConstantExpert(), PARAMS, EpisodeSpec(seed=4, max_steps=2, noise_std=-0.1)
        )
    env.close()
