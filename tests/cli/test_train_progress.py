"""``semexplore train`` as documented, i.e. with SB3's progress bar on (it needs tqdm and rich,
which the ``rl`` extra installs)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from semexplore_gym.cli import main

CONFIGS = Path(__file__).resolve().parents[2] / "configs" / "agents"


@pytest.mark.parametrize(
    ("algo", "config"),
    [("ppo", "planner_weights_maze.yml"), ("maskable_ppo", "frontier_choice_maze.yml")],
)
def test_ppo_training_with_the_progress_bar(
    tmp_path: Path, algo: str, config: str, tiny_macro_train_args, one_torch_thread
) -> None:
    pytest.importorskip("stable_baselines3")
    args = [a for a in tiny_macro_train_args(2) if a != "--no-progress"]
    out = tmp_path / algo
    code = main(
        ["train", "--algo", algo, "--train-config", str(CONFIGS / config), "--out", str(out), *args]
    )
    assert code == 0
    assert json.loads((out / "metrics.json").read_text())["timesteps"] == 8
    assert (out / "model.zip").is_file()
    assert json.loads((out / "args.json").read_text())["args"]["no_progress"] is False
