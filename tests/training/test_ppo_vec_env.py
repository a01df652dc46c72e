"""PPO collects from several envs at once by default (``ppo.n_envs``, ``ppo.vec_env``)."""

from __future__ import annotations

import pytest

pytest.importorskip("stable_baselines3")

from semexplore_gym.training.config import TrainConfig, check_train_config, load_train_config
from semexplore_gym.training.ppo import make_vec_env

SMALL = [
    "env.world=maze:seed=0,size_m=4",
    "env.overrides=[episode.max_time_s=20]",
    "ppo.max_episode_steps=50",
]


def test_defaults_collect_from_two_envs_in_worker_processes() -> None:
    assert TrainConfig().ppo.n_envs == 2 and TrainConfig().ppo.vec_env == "auto"


def test_bad_n_envs_or_vec_env_is_rejected_before_any_work() -> None:
    for bad in ("ppo.n_envs=0", "ppo.vec_env=threads"):
        with pytest.raises(ValueError, match=bad.split("=")[0]):
            check_train_config(load_train_config(None, [bad]), "ppo")


@pytest.mark.parametrize(
    ("vec_env", "cls_name"), [("dummy", "DummyVecEnv"), ("auto", "SubprocVecEnv")]
)
def test_vec_env_kind(vec_env: str, cls_name: str) -> None:
    cfg = load_train_config(None, [*SMALL, f"ppo.vec_env={vec_env}"])
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
