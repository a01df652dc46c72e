"""``semexplore train`` on the macro-action env ids (maskable_ppo and ppo), tiny budgets."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from semexplore_gym.cli import main

CONFIGS = Path(__file__).resolve().parents[2] / "configs" / "agents"


@pytest.fixture(autouse=True)
def _one_thread() -> None:
    import torch

    torch.set_num_threads(1)


@pytest.mark.parametrize(
    ("algo", "config", "cls_name"),
    [
        ("maskable_ppo", "frontier_choice_maze.yml", "MaskablePPO"),
        ("ppo", "planner_weights_maze.yml", "PPO"),
    ],
)
def test_macro_training_runs_a_few_steps(
    tmp_path: Path, algo: str, config: str, cls_name: str, tiny_macro_train_args
) -> None:
    out = tmp_path / algo
    assert (
        main(
            [
                "train",
                "--algo",
                algo,
                "--train-config",
                str(CONFIGS / config),
                "--out",
                str(out),
                *tiny_macro_train_args(2),
            ]
        )
        == 0
    )
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["timesteps"] == 8
    if cls_name == "MaskablePPO":
        from sb3_contrib import MaskablePPO as cls
    else:
        from stable_baselines3 import PPO as cls
    model = cls.load(str(out / "model.zip"), device="cpu")
    assert model.observation_space.shape == (8 * 8 + 4,)


def test_macro_env_id_rejects_imitation_and_mask_needs_macro(tmp_path: Path) -> None:
    cfg = str(CONFIGS / "planner_weights_maze.yml")
    assert main(["train", "--algo", "bc", "--train-config", cfg, "--out", str(tmp_path / "a")]) == 2
    cfg = str(CONFIGS / "ppo_maze.yml")
    assert (
        main(
            ["train", "--algo", "maskable_ppo", "--train-config", cfg, "--out", str(tmp_path / "b")]
        )
        == 2
    )
