"""``semexplore train --algo bc|dagger``: the ``workers`` keys (validation, same data as one)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from semexplore_gym.cli import main

CONFIGS = Path(__file__).resolve().parents[2] / "configs" / "agents"


@pytest.fixture(autouse=True)
def _one_thread() -> None:
    torch = pytest.importorskip("torch")
    pytest.importorskip("stable_baselines3")
    torch.set_num_threads(1)


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("expert.workers=0", "expert.workers must be an integer >= 1, got 0"),
        ("dagger.workers=-1", "dagger.workers must be an integer >= 1, got -1"),
        ("expert.workers=two", "expert.workers"),
        ("torch_threads=0", "torch_threads must be an integer >= 1, got 0"),
    ],
)
def test_bad_workers_are_rejected_before_any_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], override: str, message: str
) -> None:
    out = tmp_path / "run"
    rc = main(["train", "--algo", "dagger", "--out", str(out), "--no-progress", "--train-set", override])
    assert rc == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
def test_dagger_with_two_workers_records_the_same_data(tmp_path: Path) -> None:
    """The CLI's env and expert factories feed the workers; the data equals one process's."""
    tiny = [
        "--no-progress",
        "--train-set", "torch_threads=1",
        "--train-set", "env.world=maze:size_m=4,seed=3",
        "--train-set", "egocentric.crop_cells=36",
        "--train-set", "expert.spec=semantic",
        "--train-set", "expert.episodes=3",
        "--train-set", "expert.max_steps=12",
        "--train-set", "expert.holdout_fraction=0.34",
        "--train-set", "bc.epochs=1",
        "--train-set", "dagger.rounds=1",
        "--train-set", "dagger.episodes_per_round=2",
        "--train-set", "dagger.epochs_per_round=1",
    ]  # fmt: skip
    datasets = {}
    for workers in (1, 2):
        out = tmp_path / f"w{workers}"
        rc = main(
            ["train", "--algo", "dagger", "--train-config", str(CONFIGS / "dagger_maze.yml")]
            + ["--out", str(out), *tiny]
            + ["--train-set", f"expert.workers={workers}", "--train-set", f"dagger.workers={workers}"]
        )
        assert rc == 0
        metrics = json.loads((out / "metrics.json").read_text())
        assert metrics["dataset_episodes"] == 3
        datasets[workers] = [np.load(out / name) for name in ("dataset.npz", "dagger_dataset.npz")]
    for one, two in zip(datasets[1], datasets[2], strict=True):
        assert sorted(one.files) == sorted(two.files)
        for key in one.files:
            np.testing.assert_array_equal(one[key], two[key], err_msg=key)
