"""``semexplore train --algo option_ppo``: config errors, and a tiny run that resumes."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from semexplore_gym.cli import main
from semexplore_gym.training.option_ppo import OptionPPOConfig, load_option_ppo_config

TINY = [
    "splits=[mazes]",
    "max_size_m=6",
    "max_time_s=60",
    "bc_episodes=1",
    "bc_epochs=2",
    "total_timesteps=4",
    "n_steps=2",
    "batch_size=2",
    "n_epochs=1",
]


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("n_envs", 0, "n_envs must be an integer >= 1, got 0"),
        ("bc_episodes", -1, "bc_episodes must be an integer >= 0, got -1"),
        ("gamma", 1.5, "gamma must be in (0, 1], got 1.5"),
        ("splits", (), "splits is empty"),
        ("wall_budget_s", -1.0, "wall_budget_s must be a finite number >= 0, got -1.0"),
        ("vec_env", "ray", "vec_env must be one of dummy, subproc, got 'ray'"),
    ],
)
def test_config_errors_name_the_value(key: str, value: object, message: str) -> None:
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace("]", r"\]")):
        OptionPPOConfig(**{key: value})  # type: ignore[arg-type]


def test_the_option_section_is_checked_at_load() -> None:
    with pytest.raises(ValueError, match="max_options must be an integer >= 2, got 1"):
        load_option_ppo_config("configs/agents/option_ppo.yml", ["option.max_options=1"])


def test_cli_reports_a_bad_key_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    pytest.importorskip("sb3_contrib")
    rc = main(["train", "--algo", "option_ppo", "--train-config", "configs/agents/option_ppo.yml",
               "--out", str(tmp_path / "run"), "--train-set", "n_envs=0"])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert (
        err.startswith("semexplore train: error:")
        and "n_envs must be an integer >= 1, got 0" in err
    )
    assert len(err.splitlines()) == 1


def _train(out: Path, extra: list[str]) -> int:
    args = ["train", "--algo", "option_ppo", "--train-config", "configs/agents/option_ppo.yml",
            "--out", str(out), "--no-progress"]  # fmt: skip
    for text in TINY + extra:
        args += ["--train-set", text]
    return main(args)


@pytest.mark.slow
def test_tiny_run_writes_its_curve_and_resumes(tmp_path: Path, one_torch_thread: None) -> None:
    pytest.importorskip("sb3_contrib")
    out = tmp_path / "run"
    assert _train(out, []) == 0
    for name in ("model.zip", "bc_model.zip", "bc_data.npz", "curve.csv", "curve.png"):
        assert (out / name).is_file(), name
    assert (out / "checkpoints" / "last.zip").is_file()
    with (out / "curve.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert rows[0]["phase"] == "bc"
    first = json.loads((out / "metrics.json").read_text())
    assert first["timesteps"] >= 4 and first["bc_decisions"] >= 1
    assert _train(out, ["total_timesteps=8"]) == 0  # resumes from checkpoints/last.zip
    second = json.loads((out / "metrics.json").read_text())
    assert second["resumed_at"] >= 4 and second["timesteps"] >= 8
    assert "bc_decisions" not in second  # no second behaviour cloning


def _curve_without_wall_time(out: Path) -> list[dict[str, str]]:
    with (out / "curve.csv").open() as f:
        return [{k: v for k, v in row.items() if k != "wall_s"} for row in csv.DictReader(f)]


@pytest.mark.slow
def test_envs_in_subprocesses_give_the_same_run(tmp_path: Path, one_torch_thread: None) -> None:
    """Two envs in their own processes draw the same worlds and starts as in this process, so
    the episodes, the curve and the trained weights are the same."""
    pytest.importorskip("sb3_contrib")
    import torch as th
    from semexplore_gym.policies.option_ppo import load_option_model

    runs = {}
    for vec_env in ("dummy", "subproc"):
        out = tmp_path / vec_env
        assert _train(out, ["n_envs=2", "total_timesteps=8", f"vec_env={vec_env}"]) == 0
        runs[vec_env] = out
    curves = [_curve_without_wall_time(out) for out in runs.values()]
    assert curves[0] and curves[0] == curves[1]
    params = [load_option_model(out / "model.zip").policy.state_dict() for out in runs.values()]
    assert params[0].keys() == params[1].keys()
    for key, value in params[0].items():
        assert th.equal(value, params[1][key]), key
