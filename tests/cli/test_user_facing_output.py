"""What the commands print for a user: help texts that list every choice and no developer notes,
the policy spec as given, no figures that do not apply, one error prefix style."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import pytest

from semexplore_gym.cli import main
from semexplore_gym.cli.explore import format_result
from semexplore_gym.evaluation.warmup import COMPILE_ESTIMATE, COMPILE_MESSAGE

REPO = Path(__file__).resolve().parents[2]


def _help(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit):
        main([*argv, "--help"])
    return capsys.readouterr().out


def test_train_help_lists_every_algorithm_first_and_no_developer_notes(capsys) -> None:
    text = _help(["train"], capsys)
    description = text.split("\n\n")[1]
    assert description.startswith(
        "semexplore train --algo bc|dagger|ppo|maskable_ppo|frontier_value"
    )
    assert "This module" not in text and "live in" not in text
    assert "frontier_choice_maze" in text  # the shipped configs


def test_explore_help_lists_every_world_spelling(capsys) -> None:
    text = " ".join(_help(["explore"], capsys).split())
    for spelling in (
        "maze1",
        "'maze:",
        "'office:",
        "'cave:",
        "'forest:",
        "map:NAME",
        ".yaml",
        ".json",
    ):
        assert spelling in text, spelling


def test_the_compile_notice_carries_the_measured_estimate(capsys) -> None:
    assert COMPILE_ESTIMATE in COMPILE_MESSAGE and "~2 min" not in COMPILE_MESSAGE
    assert COMPILE_ESTIMATE in " ".join(_help(["explore"], capsys).split())


def _summary(**changes: object) -> dict:
    summary = {
        "world": "maze1",
        "policy": "semantic",
        "seed": 0,
        "coverage": 0.99,
        "explored_area_m2": 40.0,
        "mission_time_s": 250.0,
        "self_stopped": True,
        "stop_reason": "no frontier left",
        "path_length_m": 50.0,
        "collisions": 0,
        "T90_s": 180.0,
        "T99_s": 240.0,
        "wall_time_s": 2.5,
        "mean_map_generation_ms": 5.0,
        "mean_global_planning_ms": 3.0,
        "n_replans": 100,
        "stage_time_s": {"env_step": 1.0, "map_generation": 0.5, "global_planning": 0.3},
    }
    return {**summary, **changes}


def test_explore_leaves_out_the_figures_a_learned_policy_has_none_of() -> None:
    expert = format_result(_summary())
    assert "map generation   5.00 ms" in expert and "(100 replans)" in expert
    learned = format_result(
        _summary(
            policy="sb3:runs/dagger/model.zip",
            mean_map_generation_ms=0.0,
            mean_global_planning_ms=0.0,
            n_replans=0,
            stage_time_s={"env_step": 1.0, "map_generation": 0.0, "global_planning": 0.0},
        )
    )
    assert "map generation" not in learned and "global planning" not in learned
    assert "0 replans" not in learned
    assert "policy           sb3:runs/dagger/model.zip (seed 0)" in learned
    assert "stage split (s)  env_step 1.000" in learned and "map_generation" not in learned


def test_explore_prints_the_model_path_it_was_given(capsys) -> None:
    pytest.importorskip("stable_baselines3")
    model = REPO / "policies" / "pretrained" / "dagger_maze" / "model.zip"
    argv = ["explore", "--world", "maze:seed=0,size_m=3", "--policy", f"sb3:{model}"]
    assert main([*argv, "--max-time-s", "2", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert f"policy           sb3:{model} (seed 0)" in out
    assert "global planning" not in out and "replans" not in out  # it never plans globally


@pytest.mark.parametrize("spec", ["random", "semantic"])
def test_the_progress_bar_shows_a_mode_only_when_the_policy_has_one(
    spec: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    import tqdm
    from semexplore_gym.policies.registry import make_policy

    from semexplore_gym.evaluation.rollout import run_mission

    shown: list[dict] = []
    original = tqdm.tqdm.set_postfix

    def record(self, ordered_dict=None, refresh=True, **kwargs):  # type: ignore[no-untyped-def]
        shown.append({**(ordered_dict or {}), **kwargs})
        return original(self, ordered_dict, refresh, **kwargs)

    monkeypatch.setattr(tqdm.tqdm, "set_postfix", record)
    env = gym.make("SemanticExplore-v0", world="maze:seed=0,size_m=3")
    try:
        run_mission(env, make_policy(spec), seed=0, max_time_s=12, progress=True)
    finally:
        env.close()
    assert shown and all("coverage" in p for p in shown)
    modes = [p.get("mode") for p in shown]
    if spec == "random":
        assert modes == [None] * len(shown)  # no empty mode= field
    else:
        assert all(modes)


def test_every_error_line_names_the_whole_command(tmp_path: Path, capsys) -> None:
    assert main(["maps", "get", "no-such-map"]) == 2
    assert capsys.readouterr().err.startswith("semexplore maps get: error: unknown map")
    from semexplore_gym.maps.catalogue import get_catalogue_map

    entry = get_catalogue_map("tb3-world")
    src = tmp_path / "src"
    for folder in (src, src / entry.name):
        folder.mkdir(parents=True, exist_ok=True)
        for f in entry.files:
            (folder / f.filename).write_bytes(b"not the map")
    argv = ["maps", "get", "tb3-world", "--from", str(src), "--dir", str(tmp_path / "maps")]
    assert main(argv) != 0
    assert capsys.readouterr().err.startswith("semexplore maps get: error:")
    assert main(["explore", "--max-time-s", "-1"]) == 2
    assert capsys.readouterr().err.startswith("semexplore explore: error:")


def test_a_bad_lidar_range_from_the_command_line_is_one_line(capsys) -> None:
    assert main(["explore", "--env-set", "lidar.max_range_m=1e300", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "lidar.max_range_m" in err and "1e+300" in err
    assert "Traceback" not in err
