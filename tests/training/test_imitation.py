"""Imitation pipeline: dataset files, behaviour cloning, DAgger, SB3Policy and ``semexplore train``."""

from __future__ import annotations

import json
import math
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from policies.base import Policy
from semexplore_gym.training.dagger import beta_schedule
from semexplore_gym.training.dataset import DatasetWriter, ImitationDataset
from semexplore_gym.wrappers.egocentric import EgocentricParams

WORLD = "maze:size_m=5,seed=1"
# Small crop (NatureCNN needs >= 36 px) and coarse cells keep the tests fast.
PARAMS = EgocentricParams(crop_cells=36, crop_resolution_m=0.15, n_scan_bins=60)


pytestmark = pytest.mark.usefixtures("one_torch_thread")


# --------------------------------------------------------------- dataset (no torch)
def _fake_episode(n: int, episode_id: int, rng: np.random.Generator) -> ImitationDataset:
    obs = {
        "image": rng.integers(0, 256, (n, 1, 8, 8), dtype=np.uint8),
        "scan": rng.random((n, 6), dtype=np.float32),
    }
    return ImitationDataset(
        obs, rng.uniform(-1, 1, (n, 2)).astype(np.float32), np.full(n, episode_id, np.int64)
    )


def test_dataset_round_trip_and_incremental_writes(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    path = tmp_path / "d.npz"
    writer = DatasetWriter(path, meta={"expert": "x"})
    ep0, ep1 = _fake_episode(5, 0, rng), _fake_episode(3, 0, rng)
    writer.add(ep0)
    # The file is complete after the first episode already (nothing lost on interruption).
    first = ImitationDataset.load(path)
    assert len(first) == 5 and first.meta == {"expert": "x"}
    writer.add(ep1)
    back = ImitationDataset.load(path)
    assert len(back) == 8 and back.n_episodes == 2
    np.testing.assert_array_equal(back.episode_ids, [0] * 5 + [1] * 3)  # second episode id shifted
    np.testing.assert_array_equal(
        back.obs["image"], np.concatenate([ep0.obs["image"], ep1.obs["image"]])
    )
    np.testing.assert_array_equal(
        back.obs["scan"], np.concatenate([ep0.obs["scan"], ep1.obs["scan"]])
    )
    np.testing.assert_array_equal(back.actions, np.concatenate([ep0.actions, ep1.actions]))
    assert not list(tmp_path.glob("*.tmp"))
    # append=True continues an existing file.
    DatasetWriter(path, append=True).add(_fake_episode(2, 7, rng))
    assert ImitationDataset.load(path).episode_ids.tolist() == [0] * 5 + [1] * 3 + [2] * 2


def test_split_by_episode_holds_out_whole_episodes() -> None:
    rng = np.random.default_rng(1)
    data = ImitationDataset.empty()
    for e in range(4):
        data = data.concatenate(_fake_episode(3 + e, 0, rng))
    train, held = data.split_by_episode(0.25, np.random.default_rng(0))
    assert len(train) + len(held) == len(data) and held.n_episodes == 1 and train.n_episodes == 3
    assert not set(train.episode_ids) & set(held.episode_ids)


def test_dataset_errors() -> None:
    with pytest.raises(ValueError, match="samples"):
        ImitationDataset(
            {"scan": np.zeros((3, 2))}, np.zeros((2, 2), np.float32), np.zeros(2, np.int64)
        )
    with pytest.raises(FileNotFoundError, match="dataset not found"):
        ImitationDataset.load("/nonexistent/d.npz")


def test_beta_schedule() -> None:
    exp = beta_schedule(0.5)
    assert [exp(i) for i in range(3)] == [1.0, 0.5, 0.25]
    seq = beta_schedule([0.8, 0.2])
    assert [seq(i) for i in range(4)] == [0.8, 0.2, 0.2, 0.2]
    with pytest.raises(ValueError, match="beta"):
        beta_schedule(1.5)


# ------------------------------------------------------------------ env-based tests
class ReactiveExpert(Policy):
    """Stand-in expert: a deterministic function of the scan (drive forward, steer to open space)."""

    name = "reactive"

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        scan = obs["scan"]
        max_r = float(info["lidar"]["max_range_m"])
        r = np.where(scan > 0, scan, max_r)
        ang = (np.arange(r.size) * 2 * math.pi / r.size + math.pi) % (2 * math.pi) - math.pi
        front = r[np.abs(ang) < 0.5].min()
        left = r[(ang > 0.3) & (ang < 1.6)].mean()
        right = r[(ang < -0.3) & (ang > -1.6)].mean()
        if front < 0.45:
            return np.array([0.0, 1.0 if left >= right else -1.0], np.float32)
        return np.array([min(1.0, front / 1.5), np.clip(0.8 * (left - right), -1, 1)], np.float32)


def _env() -> Any:
    pytest.importorskip("torch")
    pytest.importorskip("stable_baselines3")
    import gymnasium as gym

    try:
        import semexplore_gym  # noqa: F401

        return gym.make("SemanticExplore-v0", world=WORLD, overrides=["episode.random_start=true"])
    except ImportError as e:  # the env's dependencies may still be landing
        pytest.skip(f"SemanticExplore-v0 not importable: {e}")


def _policy(seed: int = 0) -> Any:
    from gymnasium import spaces

    from semexplore_gym.training.learner import make_learner_policy
    from semexplore_gym.wrappers.egocentric import egocentric_observation_space

    return make_learner_policy(
        egocentric_observation_space(PARAMS),
        spaces.Box(-1.0, 1.0, (2,), np.float32),
        seed=seed,
        net_arch=[64, 64],
        log_std_init=-0.5,
        features_extractor_kwargs={"cnn_output_dim": 32},
    )


def test_expert_recording_writes_labelled_episodes(tmp_path: Path) -> None:
    from semexplore_gym.training.recording import record_expert_dataset

    env = _env()
    data = record_expert_dataset(
        env, ReactiveExpert(), tmp_path / "e.npz", 2, PARAMS, seed=5, max_steps=15
    )
    back = ImitationDataset.load(tmp_path / "e.npz")
    assert len(back) == len(data) == 30 and back.n_episodes == 2
    assert back.obs["image"].shape == (30, 1, 36, 36) and back.obs["image"].dtype == np.uint8
    assert back.meta["egocentric"] == PARAMS.to_dict() and back.meta["expert"] == "reactive"
    # Labels are the expert's actions on the recorded states: re-derive the first one.
    obs, info = env.reset(seed=5)
    np.testing.assert_array_equal(back.actions[0], ReactiveExpert().act(obs, info))
    env.close()


def test_bc_reduces_heldout_action_error() -> None:
    from semexplore_gym.training.bc import action_error, train_bc
    from semexplore_gym.training.recording import record_expert_dataset

    env = _env()
    data = record_expert_dataset(env, ReactiveExpert(), None, 5, PARAMS, seed=0, max_steps=60)
    train, held = data.split_by_episode(0.2, np.random.default_rng(0))
    assert held.n_episodes == 1
    policy = _policy()
    before = action_error(policy, held)
    hist = train_bc(train, policy, epochs=12, batch_size=32, lr=1e-3, seed=0)
    after = action_error(policy, held)
    assert hist["loss"][-1] < hist["loss"][0]
    assert after < 0.6 * before, (before, after)
    env.close()


def test_dagger_round_runs_and_grows_the_dataset(tmp_path: Path) -> None:
    from semexplore_gym.training.dagger import run_dagger
    from semexplore_gym.training.recording import record_expert_dataset

    env = _env()
    base = record_expert_dataset(env, ReactiveExpert(), None, 1, PARAMS, seed=0, max_steps=20)
    policy = _policy()
    result = run_dagger(
        env,
        ReactiveExpert(),
        policy,
        PARAMS,
        rounds=2,
        beta=[0.5, 0.0],
        episodes_per_round=1,
        dataset=base,
        dataset_path=tmp_path / "agg.npz",
        bc_kwargs={"epochs": 1, "batch_size": 16},
        seed=3,
        max_steps=20,
    )
    assert len(result.dataset) == len(base) + 40 and result.dataset.n_episodes == 3
    assert [r["dataset_size"] for r in result.rounds] == [len(base) + 20, len(base) + 40]
    assert 0.0 < result.rounds[0]["expert_fraction"] < 1.0  # beta = 0.5 mixes both drivers
    assert result.rounds[1]["expert_fraction"] == 0.0  # beta = 0: the learner drives alone
    assert len(ImitationDataset.load(tmp_path / "agg.npz")) == len(result.dataset)
    env.close()


def test_saved_policy_runs_through_sb3_policy(tmp_path: Path) -> None:
    from policies.sb3_policy import SB3Policy
    from semexplore_gym.training.learner import save_policy
    from semexplore_gym.wrappers.egocentric import egocentric_features

    env = _env()
    policy = _policy(seed=4)
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
    from policies.sb3_policy import SB3Policy

    with pytest.raises(FileNotFoundError):
        SB3Policy(tmp_path / "missing.zip")
    bad = tmp_path / "bad.zip"
    with zipfile.ZipFile(bad, "w") as z:
        z.writestr("x.txt", "hello")
    with pytest.raises(ValueError, match="neither"):
        SB3Policy(bad)


def test_registry_builds_sb3_policy(tmp_path: Path) -> None:
    registry = pytest.importorskip("policies.registry")
    from semexplore_gym.training.learner import save_policy

    pytest.importorskip("torch")
    path = save_policy(_policy(), tmp_path / "m.zip", PARAMS)
    agent = registry.make_policy(f"sb3:{path}")
    assert type(agent).__name__ == "SB3Policy" and agent.params == PARAMS


@pytest.mark.slow
def test_train_cli_bc_then_ppo_then_explore(tmp_path: Path) -> None:
    """``semexplore train`` end to end with tiny budgets (real expert when it exists)."""
    env = _env()
    registry = pytest.importorskip("policies.registry")
    try:
        semantic = registry.make_policy("semantic")
        obs, info = env.reset(seed=0)
        semantic.reset(obs, info, seed=0)
        semantic.act(obs, info)
        expert = "semantic"
    except Exception:  # the expert's dependencies may not have landed yet: test the plumbing
        expert = "random"
    from semexplore_gym.cli import main

    repo = Path(__file__).resolve().parents[2]
    common = ["--no-progress", "--set", f"env.world={WORLD}", "--set", "egocentric.crop_cells=36"]
    common += ["--set", "torch_threads=1"]  # one core: keep the shared machine's other one free
    bc_out = tmp_path / "bc"
    rc = main(
        [
            "train",
            "--algo",
            "bc",
            "--config",
            str(repo / "configs/agents/bc_maze.yml"),
            "--out",
            str(bc_out),
            *common,
        ]
        + [
            "--set",
            f"expert.spec={expert}",
            "--set",
            "expert.episodes=2",
            "--set",
            "expert.max_steps=20",
            "--set",
            "bc.epochs=2",
            "--set",
            "expert.workers=1",
        ]
    )
    assert rc == 0
    for name in ("model.zip", "config.yaml", "args.json", "metrics.json", "dataset.npz"):
        assert (bc_out / name).is_file(), name
    assert json.loads((bc_out / "metrics.json").read_text())["dataset_samples"] == 40
    assert any((bc_out / "tb").rglob("*")), "no training logs"
    ppo_out = tmp_path / "ppo"
    rc = main(
        [
            "train",
            "--algo",
            "ppo",
            "--config",
            str(repo / "configs/agents/ppo_maze.yml"),
            "--out",
            str(ppo_out),
            *common,
        ]
        + [
            "--set",
            "ppo.total_timesteps=64",
            "--set",
            "ppo.n_steps=32",
            "--set",
            "ppo.batch_size=16",
            "--set",
            f"ppo.init_from={bc_out / 'model.zip'}",
        ]
    )
    assert rc == 0 and (ppo_out / "model.zip").is_file()
    assert list((ppo_out / "tb").rglob("events.out.tfevents.*")), "no PPO TensorBoard log"
    recorded = json.loads((ppo_out / "args.json").read_text())
    assert recorded["command_line"].startswith("semexplore train --algo ppo --out ")
    assert "ppo.total_timesteps=64" in recorded["command_line"]
    from policies.sb3_policy import SB3Policy

    assert SB3Policy(ppo_out / "model.zip").params.crop_cells == 36
    explore = Path(repo / "semexplore_gym/cli/explore.py")
    if explore.is_file():
        rc = main(
            [
                "explore",
                "--world",
                WORLD,
                "--policy",
                f"sb3:{ppo_out / 'model.zip'}",
                "--max-time-s",
                "2",
                "--no-progress",
                "--json",
            ]
        )
        assert rc == 0


# ------------------------------------------------- DART noise, best epoch, mirroring
class ConstantExpert(Policy):
    """Always drives straight at half speed."""

    name = "constant"

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        return np.array([0.5, 0.0], np.float32)


def test_dart_noise_perturbs_execution_not_labels() -> None:
    from semexplore_gym.training.episodes import rollout_episode

    env = _env()

    def run(noise_std: float, rng_seed: int) -> tuple[np.ndarray, np.ndarray]:
        """(scans seen, labels) of a 12-step episode from the same start."""
        rec = rollout_episode(
            env,
            ConstantExpert(),
            PARAMS,
            rng=np.random.default_rng(rng_seed),
            seed=4,
            max_steps=12,
            noise_std=noise_std,
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
        rollout_episode(env, ConstantExpert(), PARAMS, seed=4, max_steps=2, noise_std=-0.1)
    env.close()


def test_select_best_restores_the_best_epoch_and_mirroring_trains() -> None:
    from semexplore_gym.training.bc import action_error, train_bc
    from semexplore_gym.training.recording import record_expert_dataset

    env = _env()
    params = EgocentricParams(
        crop_cells=36, crop_resolution_m=0.15, n_scan_bins=72, scan_bins_centred=True
    )
    data = record_expert_dataset(env, ReactiveExpert(), None, 3, params, seed=0, max_steps=40)
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
        epochs=5,
        batch_size=16,
        lr=3e-3,
        eval_data=held,
        select_best=True,
        mirror_params=params,
        lr_final_fraction=0.1,
    )
    errs = hist["eval_action_error"]
    assert len(errs) == 5 and hist["best_epoch"] == [float(int(np.argmin(errs)))]
    assert action_error(policy, held) == pytest.approx(min(errs), rel=1e-6)
    with pytest.raises(ValueError, match="scan_bins_centred"):
        train_bc(train, policy, epochs=1, mirror_params=PARAMS)
    env.close()


def test_concatenate_all_matches_chained_concatenate() -> None:
    rng = np.random.default_rng(2)
    parts = [_fake_episode(n, e, rng) for n, e in [(3, 4), (2, 0), (4, 9)]]
    parts[0].meta["a"] = 1
    chained = parts[0].concatenate(parts[1]).concatenate(parts[2])
    once = ImitationDataset.concatenate_all([ImitationDataset.empty({"w": 2}), *parts])
    np.testing.assert_array_equal(once.episode_ids, chained.episode_ids)
    np.testing.assert_array_equal(once.actions, chained.actions)
    np.testing.assert_array_equal(once.obs["image"], chained.obs["image"])
    assert once.meta == {"w": 2, "a": 1}


def test_dataset_writer_throttles_rewrites_and_flushes(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    path = tmp_path / "d.npz"
    writer = DatasetWriter(path, meta={"k": 1}, min_interval_s=3600.0)
    writer.add(_fake_episode(4, 0, rng))  # the first episode is written at once
    writer.add(_fake_episode(2, 0, rng))  # within the interval: kept in memory only
    assert len(ImitationDataset.load(path)) == 4 and len(writer.data) == 6
    writer.flush()
    back = ImitationDataset.load(path)
    assert len(back) == 6 and back.episode_ids.tolist() == [0] * 4 + [1] * 2
    assert back.meta == {"k": 1}
