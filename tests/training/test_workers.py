"""Per-episode random streams and multi-process roll-outs of the imitation pipeline."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from _imitation import ReactiveExpert

from semexplore_gym.training.dataset import ImitationDataset
from semexplore_gym.training.train_config import (
    BCSection,
    DaggerSection,
    ExpertSection,
    TrainConfig,
)
from semexplore_gym.training.workers import (
    DAGGER_STREAM,
    EXPERT_STREAM,
    EpisodeActors,
    check_workers,
    episode_rng,
)
from semexplore_gym.wrappers.egocentric import EgocentricParams

WORLD = "maze:size_m=5,seed=1"
PARAMS = EgocentricParams(
    crop_cells=36, crop_resolution_m=0.15, n_scan_bins=60, channels=("occupancy", "trail")
)


pytestmark = pytest.mark.usefixtures("one_torch_thread")


class SteerToOpenExpert(ReactiveExpert):
    """Stand-in expert, a pure function of the scan: forward, turning towards the open side."""

    name = "steer_to_open"


def make_env() -> Any:
    """Module-level env factory (picklable by reference for the worker processes)."""
    import gymnasium as gym

    import semexplore_gym  # noqa: F401  (registers the env)

    return gym.make("SemanticExplore-v0", world=WORLD, overrides=["episode.random_start=true"])


def _env() -> Any:
    pytest.importorskip("torch")
    pytest.importorskip("stable_baselines3")
    return make_env()


def _policy(seed: int = 0) -> Any:
    from gymnasium import spaces

    from semexplore_gym.training.learner import make_learner_policy
    from semexplore_gym.wrappers.egocentric import egocentric_observation_space

    return make_learner_policy(
        egocentric_observation_space(PARAMS),
        spaces.Box(-1.0, 1.0, (2,), np.float32),
        seed=seed,
        net_arch=[16],
        log_std_init=-0.5,
        features_extractor_kwargs={"cnn_output_dim": 16},
    )


def _assert_same(a: ImitationDataset, b: ImitationDataset) -> None:
    assert set(a.obs) == set(b.obs)
    for k in a.obs:
        np.testing.assert_array_equal(a.obs[k], b.obs[k])
    np.testing.assert_array_equal(a.actions, b.actions)
    np.testing.assert_array_equal(a.episode_ids, b.episode_ids)
    assert a.meta == b.meta


def test_episode_rng_depends_on_seed_stream_and_episode_only() -> None:
    draw = episode_rng(3, 5).random(4)
    np.testing.assert_array_equal(draw, episode_rng(3, 5, EXPERT_STREAM).random(4))
    for other in (episode_rng(3, 4), episode_rng(4, 5), episode_rng(3, 5, DAGGER_STREAM)):
        assert not np.array_equal(draw, other.random(4))
    for bad in ((-1, 0), (0, -2), (0, 1.5), (True, 0)):
        with pytest.raises(ValueError, match="must be an integer >= 0"):
            episode_rng(*bad)  # type: ignore[arg-type]


def test_bad_workers_are_rejected() -> None:
    assert check_workers(2) == 2 and check_workers(np.int64(3)) == 3
    for bad in (0, -1, 1.5, True, "2", None):
        with pytest.raises(ValueError, match="workers must be an integer >= 1"):
            check_workers(bad)
    from semexplore_gym.training.dagger import run_dagger
    from semexplore_gym.training.recording import record_expert_dataset

    env = _env()
    actors = EpisodeActors(env, SteerToOpenExpert())
    with pytest.raises(ValueError, match="workers must be an integer >= 1, got 0"):
        record_expert_dataset(
            actors, None, PARAMS, ExpertSection(episodes=1, max_steps=2, workers=0)
        )
    with pytest.raises(ValueError, match="workers must be an integer >= 1, got -2"):
        cfg = TrainConfig(egocentric=PARAMS, dagger=DaggerSection(rounds=1, workers=-2))
        run_dagger(actors, _policy(), cfg)
    # More than one worker needs env and expert in a picklable form.
    with pytest.raises(ValueError, match="picklable make_env"):
        record_expert_dataset(
            EpisodeActors(env, SteerToOpenExpert(), make_env=lambda: make_env()),
            None,
            PARAMS,
            ExpertSection(episodes=2, max_steps=2, workers=2),
        )
    env.close()


def test_an_episode_does_not_depend_on_the_episodes_before_it() -> None:
    from semexplore_gym.training.episodes import EpisodeSpec, rollout_episode
    from semexplore_gym.training.recording import record_expert_dataset

    env = _env()
    data = record_expert_dataset(
        EpisodeActors(env, SteerToOpenExpert()),
        None,
        PARAMS,
        ExpertSection(episodes=3, max_steps=12, noise_std=0.3),
        seed=5,
    )
    # Episode 2 on its own, on a new env: seed 5 + 2, noise from episode_rng(5, 2).
    alone_env = make_env()
    alone = rollout_episode(
        alone_env,
        SteerToOpenExpert(),
        PARAMS,
        EpisodeSpec(seed=7, max_steps=12, episode_id=2, noise_std=0.3),
        rng=episode_rng(5, 2),
    )
    third = data.subset(data.episode_ids == 2)
    third.meta = {}
    _assert_same(third, alone.data)
    # The noise matters: a different stream gives a different episode.
    other = rollout_episode(
        alone_env,
        SteerToOpenExpert(),
        PARAMS,
        EpisodeSpec(seed=7, max_steps=12, noise_std=0.3),
        rng=episode_rng(5, 2, DAGGER_STREAM),
    )
    assert not np.array_equal(other.data.obs["image"], alone.data.obs["image"])
    env.close()
    alone_env.close()


@pytest.mark.slow
def test_two_workers_record_and_dagger_like_one(tmp_path: Path) -> None:
    """Same datasets, files, round facts and learner weights with workers = 1 and 2."""
    from semexplore_gym.training.dagger import run_dagger
    from semexplore_gym.training.recording import record_expert_dataset

    env = _env()
    results = {}
    for workers in (1, 2):
        out = tmp_path / f"w{workers}"
        # workers=2 builds the env with the factory and copies the expert by pickling.
        data = record_expert_dataset(
            EpisodeActors(env, SteerToOpenExpert(), make_env=make_env if workers > 1 else None),
            out / "expert.npz",
            PARAMS,
            ExpertSection(
                episodes=3, max_steps=10, noise_std=0.3, noise_fraction=0.67, workers=workers
            ),
            seed=2,
        )
        learner = _policy(seed=1)
        cfg = TrainConfig(
            seed=4,
            egocentric=PARAMS,
            expert=ExpertSection(max_steps=8),
            bc=BCSection(batch_size=8),
            dagger=DaggerSection(
                rounds=2, beta=(0.5, 0.0), episodes_per_round=2, epochs_per_round=1, workers=workers
            ),
        )
        dagger = run_dagger(
            EpisodeActors(
                env,
                SteerToOpenExpert(),
                make_expert=functools.partial(SteerToOpenExpert) if workers > 1 else None,
            ),
            learner,
            cfg,
            dataset=data,
            dataset_path=out / "agg.npz",
        )
        results[workers] = (data, dagger, learner.state_dict(), out)
    (d1, g1, w1, out1), (d2, g2, w2, out2) = results[1], results[2]
    _assert_same(d1, d2)
    _assert_same(
        ImitationDataset.load(out1 / "expert.npz"), ImitationDataset.load(out2 / "expert.npz")
    )
    assert d1.n_episodes == 3 and len(d1) == 30
    _assert_same(g1.dataset, g2.dataset)
    _assert_same(ImitationDataset.load(out1 / "agg.npz"), g2.dataset)
    assert g1.dataset.n_episodes == 7 and g1.dataset.episode_ids[-1] == 6
    for r1, r2 in zip(g1.rounds, g2.rounds, strict=True):
        assert {k: v for k, v in r1.items() if k != "seconds"} == {
            k: v for k, v in r2.items() if k != "seconds"
        }
    assert 0.0 < g1.rounds[0]["expert_fraction"] < 1.0  # the learner drove part of round 0
    for k in w1:
        assert np.array_equal(w1[k].numpy(), w2[k].numpy()), k
    env.close()
