"""PPO collects from several envs at once by default (``ppo.n_envs``, ``ppo.vec_env``)."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

from semexplore_gym.training.ppo import auto_vec_env, make_vec_env
from semexplore_gym.training.train_config import TrainConfig, check_train_config, load_train_config

SMALL = [
    "env.world=maze:seed=0,size_m=4",
    "env.overrides=[episode.max_time_s=20]",
    "ppo.max_episode_steps=50",
]


def test_defaults_collect_from_four_envs() -> None:
    assert TrainConfig().ppo.n_envs == 4 and TrainConfig().ppo.vec_env == "auto"
    cfg = load_train_config(str(Path(__file__).parents[2] / "configs/agents/ppo_maze.yml"), [])
    assert cfg.ppo.n_envs == 4 and cfg.ppo.vec_env == "auto"


@pytest.mark.parametrize(
    ("n_envs", "cores", "kind"),
    [(1, 8, "dummy"), (2, 2, "dummy"), (4, 2, "dummy"), (4, 4, "dummy"), (4, 5, "subproc")],
)
def test_auto_uses_worker_processes_only_with_a_core_per_env_and_the_learner(
    n_envs: int, cores: int, kind: str
) -> None:
    assert auto_vec_env(n_envs, cores) == kind


def test_bad_n_envs_or_vec_env_is_rejected_before_any_work() -> None:
    for bad in ("ppo.n_envs=0", "ppo.vec_env=threads"):
        with pytest.raises(ValueError, match=bad.split("=")[0]):
            check_train_config(load_train_config(None, [bad]), "ppo")


@pytest.mark.parametrize(
    ("vec_env", "cls_name"),
    [("dummy", "DummyVecEnv"), ("subproc", "SubprocVecEnv"), ("auto", "DummyVecEnv")],
)
def test_vec_env_kind(vec_env: str, cls_name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("os.cpu_count", lambda: 2)  # auto on a 2-core machine: this process
    cfg = load_train_config(None, [*SMALL, "ppo.n_envs=2", f"ppo.vec_env={vec_env}"])
    venv = make_vec_env(cfg)
    try:
        assert type(venv).__name__ == cls_name and venv.num_envs == 2
        obs = venv.reset()
        assert obs["image"].shape[0] == 2
        venv.step_async([venv.action_space.sample() for _ in range(2)])
        obs, _rew, _done, _info = venv.step_wait()
        assert obs["image"].shape[0] == 2
    finally:
        venv.close()


def test_one_env_is_stepped_in_this_process() -> None:
    cfg = load_train_config(None, [*SMALL, "ppo.n_envs=1"])
    venv = make_vec_env(cfg)
    assert type(venv).__name__ == "DummyVecEnv"
    venv.close()
