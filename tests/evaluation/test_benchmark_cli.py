"""A small real benchmark through the CLI (2 worlds x 3 policies x 2 seeds), and the Ray backend."""

from __future__ import annotations

import argparse
import json
import re
import time

import pytest

from semexplore_gym.cli import main
from semexplore_gym.evaluation.harness import read_runs


@pytest.mark.slow
def test_small_benchmark_end_to_end(tmp_path, capsys) -> None:
    out = tmp_path / "bench"
    argv = [
        "benchmark",
        "--worlds",
        "maze1,maze:seed=*,size_m=4",
        "--policies",
        "semantic,frontier,nearest",
        "--runs",
        "2",
        "--max-time-s",
        "40",
        "--random-start",
        "--out",
        str(out),
        "--no-progress",
        "--json",
    ]
    assert main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["ran"] == 12 and report["failed"] == 0
    rows = read_runs(out / "runs.csv")
    assert len(rows) == 12
    assert {(r["world"], r["policy"], r["seed"]) for r in rows} == {
        (w, p, s)
        for w in ("maze1", "maze:seed=*,size_m=4")
        for p in ("semantic", "frontier", "nearest")
        for s in (0, 1)
    }
    for r in rows:
        assert 0.0 < r["coverage"] <= 1.0
        assert 0.0 < r["mission_time_s"] <= 40.0 + 1e-6
    import numpy as np

    summary = (out / "summary.md").read_text()
    for world in ("maze1", "maze:seed=*,size_m=4"):
        assert f"## {world}" in summary
    # The expert against each baseline, paired: path length too, with a Wilcoxon p.
    import re

    assert "| p (Mann–Whitney U) | p W | wins |" in summary
    path_rows = re.findall(r"^\| nearest \| path length \| ([\d.]+) \| ([\d.]+) \|", summary, re.M)
    assert path_rows  # per family, over all worlds, per world
    sem = {(r["world"], r["seed"]): r["path_length_m"] for r in rows if r["policy"] == "semantic"}
    near = {(r["world"], r["seed"]): r["path_length_m"] for r in rows if r["policy"] == "nearest"}
    per_maze1 = np.median([sem["maze1", s] / near["maze1", s] for s in (0, 1)])
    section = summary.split("## maze1")[1]
    assert re.search(rf"\| nearest \| path length \| [\d.]+ \| {per_maze1:.2f} \|", section)
    for name in (
        "explored_area.png",
        "mission_time.png",
        "map_generation_time.png",
        "global_planning_time.png",
        "trajectories.png",
    ):
        assert (out / name).exists()
    # Paired: every policy starts a seed from the same pose; different seeds start elsewhere.

    def start(policy: str, seed: int) -> np.ndarray:
        return np.load(out / "trajectories" / f"maze1__{policy}__{seed}.npy")[0]

    for seed in (0, 1):
        assert np.allclose(start("semantic", seed), start("frontier", seed))
        assert np.allclose(start("semantic", seed), start("nearest", seed))
    assert not np.allclose(start("semantic", 0), start("semantic", 1))
    # Same command again: everything is skipped.
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["skipped"] == 12


@pytest.mark.slow
def test_ray_backend_runs_two_missions(tmp_path, capsys) -> None:
    pytest.importorskip("ray")
    out = tmp_path / "ray"
    argv = [
        "benchmark",
        "--worlds",
        "maze:seed=*,size_m=4",
        "--policies",
        "semantic",
        "--runs",
        "2",
        "--max-time-s",
        "20",
        "--out",
        str(out),
        "--backend",
        "ray",
        "--workers",
        "2",
        "--no-progress",
        "--no-plots",
    ]
    assert main(argv) == 0
    rows = read_runs(out / "runs.csv")
    assert sorted(r["seed"] for r in rows) == [0, 1]


@pytest.mark.parametrize(
    ("worlds", "fragment"),
    [("maze1,no/such/map.yaml", "world file not found"), ("maze1,mazee", "unknown world 'mazee'")],
)
def test_bad_world_fails_before_any_mission(tmp_path, capsys, worlds, fragment) -> None:
    out = tmp_path / "bench"
    argv = ["benchmark", "--worlds", worlds, "--runs", "1", "--out", str(out), "--no-progress"]
    assert main(argv) != 0
    err = capsys.readouterr().err
    assert fragment in err and "--worlds" in err
    assert not (out / "runs.csv").exists()  # nothing ran


def test_world_label_shortens_map_paths_only() -> None:
    from semexplore_gym.evaluation.report import world_label

    assert world_label("/data/maps/turtlebot3/world/map.yaml") == "turtlebot3/world/map.yaml"
    assert world_label("maps/map.yaml") == "maps/map.yaml"
    assert world_label("maze:seed=*,size_m=5") == "maze:seed=*,size_m=5"
    assert world_label("maze1") == "maze1"


def test_policy_label_shortens_model_and_file_specs_only() -> None:
    from semexplore_gym.evaluation.report import policy_label

    assert policy_label("sb3:runs/fc/model.zip[frontier PPO]") == "frontier PPO"
    assert policy_label("sb3:runs/fc/model.zip") == "sb3:model.zip"
    assert policy_label("py:/home/me/planner.py:Mine") == "py:planner.py:Mine"
    assert policy_label("semantic[paper]") == "semantic[paper]"
    assert policy_label("nearest") == "nearest"


def test_without_out_it_writes_under_runs_and_says_where(tmp_path, monkeypatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    argv = ["benchmark", "--worlds", "maze:seed=0,size_m=3", "--policies", "random", "--runs", "1"]
    assert main([*argv, "--max-time-s", "1", "--no-plots", "--no-progress"]) == 0
    (out,) = (tmp_path / "runs").iterdir()
    assert re.fullmatch(r"maze_seed_0_size_m_3-\d{8}-\d{6}", out.name), out.name
    assert (out / "runs.csv").is_file()
    assert f"writing to runs/{out.name}" in capsys.readouterr().err


def test_the_default_out_names_the_suite_or_the_worlds() -> None:
    from semexplore_gym.cli.benchmark import default_out

    def args(**kw: object) -> argparse.Namespace:
        return argparse.Namespace(**{"suite": None, "split": None, "worlds": None, **kw})

    now = time.mktime((2026, 12, 4, 21, 5, 9, 0, 0, -1))
    assert default_out(args(suite="paper,mazes"), now) == "runs/paper_mazes-20261204-210509"
    assert default_out(args(split="mazes:test"), now) == "runs/mazes_test-20261204-210509"
    assert default_out(args(worlds="maze1,maze2"), now) == "runs/maze1_maze2-20261204-210509"
