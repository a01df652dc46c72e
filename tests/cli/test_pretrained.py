"""``semexplore pretrained``: one line per shipped model, starting with its policy spec."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import pytest
from semexplore_gym.policies.pretrained import pretrained_models

from semexplore_gym.cli import main


def test_lists_each_model_on_one_line_starting_with_its_spec(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["pretrained"]) == 0
    lines = capsys.readouterr().out.splitlines()
    models = pretrained_models()
    assert len(lines) == len(models) >= 2
    for line, model in zip(lines, models, strict=True):
        assert line.startswith(f"pretrained:{model.name} ")
        assert model.summary in line and len(line) <= 160, line


def test_details_give_every_field_with_the_reproduce_command_whole(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["pretrained", "--details"]) == 0
    out = capsys.readouterr().out
    for model in pretrained_models():
        assert f"\n{model.spec}\n" in f"\n{out}"
        for part in (model.trained_on, model.command, model.config, model.results):
            assert part in out


def test_reproduce_commands_find_their_config_from_any_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The printed commands say configs/agents/...: from a directory without configs/ (as after
    a pip install) that path is the shipped file and the command's parser accepts it."""
    from semexplore_gym.cli import build_parser
    from semexplore_gym.config.resources import resolve_config_path

    monkeypatch.chdir(tmp_path)
    for model in pretrained_models():
        argv = shlex.split(model.command)
        assert argv[0] == "semexplore" and f"--train-config {model.config}" in model.command
        args = build_parser().parse_args(argv[1:])
        assert args.train_config == model.config
        assert resolve_config_path(model.config).is_file(), model.config


def test_json_lists_paths_and_sizes(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["pretrained", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["spec"] for r in rows] == [f"pretrained:{m.name}" for m in pretrained_models()]
    assert all(r["size_bytes"] and r["size_bytes"] <= 5 * 1024 * 1024 for r in rows)


def test_explore_with_an_unknown_pretrained_name_is_a_clear_error(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert (
        main(["explore", "--world", "maze1", "--policy", "pretrained:nope", "--no-progress"]) == 2
    )
    err = capsys.readouterr().err
    assert (
        "unknown pretrained model pretrained:nope" in err
        and "pretrained:frontier_choice_maze" in err
    )


@pytest.mark.slow
def test_benchmark_runs_pretrained_specs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("stable_baselines3")
    specs = ",".join(m.spec for m in pretrained_models())
    argv = ["benchmark", "--worlds", "maze:seed=0,size_m=4", "--policies", specs, "--runs", "1"]
    argv += ["--max-time-s", "3", "--no-plots", "--no-progress", "--out", str(tmp_path)]
    assert main(argv) == 0
    summary = (tmp_path / "summary.md").read_text()
    assert all(f"| {m.spec} | 1 |" in summary for m in pretrained_models())


@pytest.mark.slow
def test_the_readmes_learned_driver_maps_its_world_without_a_collision(capsys) -> None:
    """The README's pretrained:dagger_maze command, as written: it does not look broken."""
    pytest.importorskip("stable_baselines3")
    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text(encoding="utf-8")
    (line,) = [s for s in readme.splitlines() if "--policy pretrained:dagger_maze" in s]
    argv = shlex.split(line, comments=True)
    assert argv[:2] == ["semexplore", "explore"] and "--max-time-s" in argv
    assert main([*argv[1:], "--json", "--no-progress"]) == 0
    result = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert result["coverage"] >= 0.99 and result["collisions"] == 0, result
