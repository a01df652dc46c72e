"""One flag vocabulary across commands (issue #16 item 6).

``--env-config/--env-set`` configure the env, ``--policy-config/--policy-set`` the policy and
``--train-config/--train-set`` a training run. The old bare ``--config``/``--set`` meant
something different in each command; they now stop (exit code 2) naming the new flags.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from semexplore_gym.cli import build_parser, main

REPO = Path(__file__).resolve().parents[2]
_MAIN = "import sys; from semexplore_gym.cli import main; sys.exit(main(sys.argv[1:]))"
_REQUIRED = {
    "explore": [],
    "benchmark": ["--worlds", "maze1", "--out", "unused"],
    "compare-weights": ["--train-worlds", "maze1", "--test-worlds", "maze1", "--out", "unused"],
    "train": ["--algo", "bc", "--out", "unused"],
}


@pytest.mark.parametrize(
    ("command", "old", "new"),
    [
        ("explore", "--config", ["--policy-config", "--env-config"]),
        ("explore", "--set", ["--policy-set", "--env-set"]),
        ("benchmark", "--config", ["--env-config"]),
        ("benchmark", "--set", ["--env-set"]),
        ("compare-weights", "--config", ["--env-config"]),
        ("train", "--config", ["--train-config"]),
        ("train", "--set", ["--train-set"]),
    ],
)
def test_old_flag_spellings_exit_2_naming_the_new_ones(command, old, new, capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main([command, *_REQUIRED[command], old, "x=1"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert f"{old} was renamed" in err
    for flag in new:
        assert flag in err


def test_old_flag_without_a_value_also_names_the_new_one(capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["benchmark", "--worlds", "maze1", "--out", "x", "--set"])
    assert exc.value.code == 2
    assert "--env-set" in capsys.readouterr().err


def test_old_flag_from_the_shell_prints_no_traceback() -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.run(
        [sys.executable, "-c", _MAIN, "explore", "--config", "paper.yaml"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert proc.returncode == 2
    assert "--policy-config" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_explore_new_flags_reach_policy_and_env() -> None:
    args = build_parser().parse_args(
        ["explore", "--policy-config", "p.yaml", "--policy-set", "cost.w_v=2",
         "--env-config", "paper", "--env-set", "lidar.n_beams=90"]
    )  # fmt: skip
    assert (args.policy_config, args.overrides) == ("p.yaml", ["cost.w_v=2"])
    assert (args.env_config, args.env_overrides) == ("paper", ["lidar.n_beams=90"])


def test_explore_env_set_is_validated_as_env_config(capsys) -> None:
    rc = main(["explore", "--env-set", "lidar.bogus_key=1", "--max-time-s", "1", "--no-progress"])
    assert rc == 2
    assert "lidar.bogus_key" in capsys.readouterr().err


def test_benchmark_env_flags_are_validated_as_env_config(tmp_path, capsys) -> None:
    argv = ["benchmark", "--worlds", "maze1", "--policies", "random", "--runs", "1"]
    argv += ["--out", str(tmp_path / "b"), "--no-progress", "--no-plots"]
    assert main([*argv, "--env-set", "lidar.bogus_key=1"]) == 2
    assert "lidar.bogus_key" in capsys.readouterr().err
    assert main([*argv, "--env-config", "no_such_preset"]) == 2
    assert "no_such_preset" in capsys.readouterr().err


def test_compare_weights_env_config_flag() -> None:
    args = build_parser().parse_args(
        ["compare-weights", *_REQUIRED["compare-weights"], "--env-config", "paper"]
    )
    assert args.env_config == "paper"


def test_train_flags_reach_the_training_config(tmp_path, capsys) -> None:
    pytest.importorskip("stable_baselines3")
    args = build_parser().parse_args(
        ["train", "--algo", "bc", "--out", "o", "--train-config", "c.yml", "--train-set", "seed=3"]
    )
    assert (args.train_config, args.overrides) == ("c.yml", ["seed=3"])
    rc = main(["train", "--algo", "bc", "--out", str(tmp_path / "r"), "--train-set", "bogus_key=1"])
    assert rc == 2
    assert "bogus_key" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()
