"""One output rule for every ``semexplore`` command: with ``--json``, stdout holds exactly one
JSON document (an object; ``pretrained`` a list) and nothing else, progress bars included."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from semexplore_gym.cli import SUBCOMMANDS, main

CONFIGS = Path(__file__).resolve().parents[2] / "configs" / "agents"
WORLD = "maze:seed=3,size_m=4"


def _commands(tmp: Path) -> dict[str, list[list[str]]]:
    """Per subcommand, tiny runs of it with ``--json`` (progress bars left on)."""
    tiny_bench = ["--runs", "1", "--max-time-s", "2", "--no-plots", "--json"]
    return {
        "show-world": [["show-world", WORLD, "--out", str(tmp / "w.png"), "--json"]],
        "segment": [["segment", WORLD, "--out", str(tmp / "s.png"), "--json"]],
        "explore": [
            ["explore", "--world", WORLD, "--policy", "random", "--max-time-s", "2", "--json"],
            ["explore", "--world", WORLD, "--robots", "2", "--max-time-s", "2", "--json"],
        ],
        "benchmark": [
            ["benchmark", "--worlds", WORLD, "--policies", "random", "--out", str(tmp / "b")]
            + tiny_bench,
            ["benchmark", "--worlds", WORLD, "--robots", "2", "--policies", "greedy"]
            + ["--out", str(tmp / "t"), *tiny_bench],
        ],
        "train": [
            [
                "train",
                "--algo",
                "frontier_value",
                "--train-config",
                str(CONFIGS / "frontier_value.yml"),
            ]
            + ["--out", str(tmp / "fv"), "--json"]
            + ["--train-set", "generations=1", "--train-set", "population=2"]
            + ["--train-set", "elite=1", "--train-set", "worlds_per_generation=1"]
            + ["--train-set", "workers=1", "--train-set", "max_time_s=3"]
            + ["--train-set", "worlds=['maze:seed=*,size_m=4']"],
        ],
        "compare-weights": [
            ["compare-weights", "--train-worlds", WORLD, "--test-worlds", WORLD]
            + ["--trials", "1", "--train-runs", "1", "--train-max-time-s", "2"]
            + ["--runs", "1", "--max-time-s", "2", "--out", str(tmp / "cw"), "--json"],
        ],
        "maps": [["maps", "list", "--json"], ["maps", "path", "--json"]],
        "pretrained": [["pretrained", "--json"]],
        "oracle": [["oracle", WORLD, "--start-seed", "0", "--json"]],
        "report": [["report", str(CONFIGS.parent / "best_known" / "best_known.csv"), "--json"]],
    }


def test_every_subcommand_is_covered(tmp_path: Path) -> None:
    assert set(_commands(tmp_path)) == set(SUBCOMMANDS)


@pytest.mark.parametrize("command", sorted(SUBCOMMANDS))
def test_json_prints_one_json_document_and_nothing_else(
    command: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    tiny_macro_train_args,
    one_torch_thread,
) -> None:
    if command == "oracle":
        pytest.importorskip("elkai")
    if command == "explore":
        pytest.importorskip("pettingzoo")
    monkeypatch.setenv("SEMEXPLORE_CACHE", str(tmp_path / "cache"))
    runs = _commands(tmp_path)[command]
    if command == "train" and importlib.util.find_spec("stable_baselines3") is not None:
        # SB3's progress bar (on, as users run it) must not land on stdout.
        config = str(CONFIGS / "planner_weights_maze.yml")
        tiny = [a for a in tiny_macro_train_args(2) if a != "--no-progress"]
        runs.append(["train", "--algo", "ppo", "--train-config", config, "--json"] + tiny)
        runs[-1] += ["--out", str(tmp_path / "ppo")]
    for argv in runs:
        assert main(argv) == 0, argv
        out = capsys.readouterr().out
        result = json.loads(out)  # fails on a second document or any other text
        assert isinstance(result, list if command == "pretrained" else dict), argv
        assert out.count("\n") <= 1 or command == "pretrained", argv


def test_without_json_benchmark_prints_its_counts_and_tables_for_a_person(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["benchmark", "--worlds", WORLD, "--policies", "random", "--runs", "1"]
    assert main([*argv, "--max-time-s", "2", "--no-plots", "--out", str(tmp_path / "b")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("ran ") and "{" not in out.splitlines()[0]
    assert (tmp_path / "b" / "summary.md").read_text().strip() in out
