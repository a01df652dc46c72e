"""Benchmark defects of issue #14 through the CLI: seeds vary missions by default, identical
samples say "no variation", per-policy parameters in brackets, and suites (user-defined too)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from semexplore_gym.cli import main
from semexplore_gym.evaluation.harness import expand_tasks, read_runs, run_benchmark
from semexplore_gym.evaluation.report import write_summary

#: A 6 m maze where the metric weight w_v changes the expert's choices within a minute.
WV_WORLD = "maze:seed=1,size_m=6"
TINY = "maze:seed=1,size_m=4"


def _bench(out: Path, *args: str) -> list[str]:
    # Progress bars on, as users run it; the oracle's regret has tests of its own
    # (tests/evaluation/test_regret.py), here the suites run without it.
    return ["benchmark", "--out", str(out), "--no-plots", "--no-oracle", *args]


def _start(out: Path, world: str, policy: str, seed: int) -> np.ndarray:
    from semexplore_gym.evaluation.harness import task_stem

    return np.load(out / "trajectories" / f"{task_stem(world, policy, seed)}.npy")[0]


def test_seeds_vary_the_start_by_default(tmp_path, capsys) -> None:
    out = tmp_path / "b"
    argv = _bench(
        out, "--worlds", TINY, "--policies", "nearest", "--runs", "2", "--max-time-s", "4"
    )
    assert main(argv) == 0
    assert not np.allclose(_start(out, TINY, "nearest", 0), _start(out, TINY, "nearest", 1))
    summary = (out / "summary.md").read_text()
    assert "no variation" not in summary.split("| nearest |")[1].split("|")[4]  # path length
    manifest = json.loads((out / "benchmark.json").read_text())
    assert manifest["fixed_start"] is False


def test_fixed_start_warns_and_the_summary_says_no_variation(tmp_path, capsys) -> None:
    out = tmp_path / "b"
    argv = _bench(
        out,
        "--worlds",
        TINY,
        "--policies",
        "semantic,nearest",
        "--runs",
        "3",
        "--max-time-s",
        "4",
        "--fixed-start",
    )
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert "--fixed-start: every seed repeats the same mission" in captured.err
    assert np.allclose(_start(out, TINY, "nearest", 0), _start(out, TINY, "nearest", 2))
    summary = (out / "summary.md").read_text()
    rows = [ln for ln in summary.splitlines() if ln.startswith("| nearest | mission time")]
    assert rows and "no variation (3 identical samples)" in rows[0]
    path_cell = next(ln for ln in summary.splitlines() if ln.startswith("| nearest | 3 |"))
    assert "no variation (3 identical samples)" in path_cell.split("|")[6]  # path length


def _constant(task) -> dict:
    row = {
        "world": task.world,
        "policy": task.policy,
        "seed": task.seed,
        "mission_time_s": 100.0 if task.policy == "semantic" else 150.0,
        "coverage": 0.9,
        "self_stopped": True,
        "stop_reason": "done",
        "path_length_m": 10.0,
        "collisions": 0,
        "T90_s": 90.0,
        "T99_s": None,
        "mean_map_generation_ms": 1.0,
        "mean_global_planning_ms": 2.0 + task.seed,
        "wall_time_s": 1.0,
        "explored_area_m2": 5.0,
        "steps": 500,
    }
    return {"row": row, "trace": np.zeros((1, 3)), "trajectory": np.zeros((1, 3))}


def test_identical_samples_print_no_variation_instead_of_p(tmp_path) -> None:
    run_benchmark(
        expand_tasks(["maze1"], ["semantic", "frontier"], [0, 1, 2, 3]),
        tmp_path,
        progress=False,
        task_fn=_constant,
    )
    text = write_summary(tmp_path).read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("| frontier | mission time |"))
    ratio, paired, p, p_w, wins = (c.strip() for c in line.strip("|").split("|")[2:7])
    assert ratio == "0.67" and paired == "0.67"
    assert p == "no variation (4 identical samples)" and p_w == wins == "–"
    # A metric that varies still gets its test.
    line = next(ln for ln in text.splitlines() if ln.startswith("| frontier | global planning"))
    assert "no variation" not in line and line.strip("|").split("|")[6].strip() == "0/4"
    semantic = next(ln for ln in text.splitlines() if ln.startswith("| semantic | 4 |"))
    assert "100.0 — no variation (4 identical samples)" in semantic


def test_bracket_overrides_change_the_mission(tmp_path, capsys) -> None:
    out = tmp_path / "b"
    wv0 = "semantic[cost.w_v=0]"
    argv = _bench(
        out,
        "--worlds",
        WV_WORLD,
        "--policies",
        f"semantic,{wv0}",
        "--runs",
        "1",
        "--max-time-s",
        "60",
        "--fixed-start",
    )
    assert main(argv) == 0
    rows = {r["policy"]: r for r in read_runs(out / "runs.csv")}
    assert set(rows) == {"semantic", wv0}
    from semexplore_gym.evaluation.harness import task_stem

    a, b = (
        np.load(out / "trajectories" / f"{task_stem(WV_WORLD, p, 0)}.npy")
        for p in ("semantic", wv0)
    )
    assert np.allclose(a[0], b[0])  # same start
    assert a.shape != b.shape or not np.allclose(a, b)  # another mission
    assert f"| {wv0} | 1 |" in (out / "summary.md").read_text()  # the whole spec is the label
    # Every expert row carries its replan count and the share the semantic gain decided.
    for r in rows.values():
        assert r["scored_replans"] > 0 and 0.0 <= r["semantic_share"] <= 1.0


def test_explore_takes_the_same_bracket(capsys) -> None:
    def path(policy: str) -> float:
        argv = ["explore", "--world", WV_WORLD, "--policy", policy, "--max-time-s", "60", "--json"]
        assert main(argv) == 0
        return json.loads(capsys.readouterr().out.strip().splitlines()[-1])["path_length_m"]

    assert path("semantic") != path("semantic[cost.w_v=0]")


@pytest.mark.parametrize(
    ("spec", "fragment"),
    [
        ("semantic[cost.w_v=0,tuned]", "'tuned' is not key=value"),
        ("semantic[cost.bogus=1]", "unknown config key 'cost.bogus'"),
        ("semantic[cost.w_v=abc]", "cost.w_v"),
        ("semantic[]", "empty brackets"),
        ("semantic[cost.w_v=0", "unbalanced brackets"),
        ("semantic]", "unbalanced brackets"),
        ("frontier[cost.w_v=1]", "unknown config key 'cost'"),
    ],
)
@pytest.mark.parametrize("command", ["benchmark", "explore"])
def test_a_malformed_bracket_is_a_clear_error(tmp_path, capsys, spec, fragment, command) -> None:
    if command == "benchmark":
        argv = _bench(tmp_path / "b", "--worlds", "maze1", "--policies", f"nearest,{spec}")
    else:
        argv = ["explore", "--world", "maze1", "--policy", spec, "--max-time-s", "1"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0]
    assert spec in err[0] or command == "benchmark" and spec.endswith("0")
    assert not (tmp_path / "b" / "runs.csv").exists()


def test_spec_splitting_respects_brackets() -> None:
    from semexplore_gym.policies.specs import parse_spec, split_specs

    assert split_specs("semantic[cost.w_v=0,cost.w_p=0], nearest,sb3:m.zip[a, b]") == [
        "semantic[cost.w_v=0,cost.w_p=0]",
        "nearest",
        "sb3:m.zip[a, b]",
    ]
    assert parse_spec("semantic[cost.w_v=0;cost.w_p=0.5]") == (
        "semantic",
        None,
        {"cost.w_v": 0, "cost.w_p": 0.5},
    )
    assert parse_spec("semantic[tuned]") == ("semantic", "tuned", {})
    assert parse_spec("nearest") == ("nearest", None, {})


SUITE_YAML = """\
name: tiny
version: 2
runs: 2
random_start: true
time_per_m2_s: 1.0
min_time_s: 30
worlds:
  - maze:seed=1,size_m=4
  - {world: 'cave:seed=2,size_m=6', max_time_s: 6}
"""


def test_a_user_suite_runs_end_to_end_with_family_tables(tmp_path, capsys) -> None:
    suite = tmp_path / "my.yaml"
    suite.write_text(SUITE_YAML)
    out = tmp_path / "s"
    argv = _bench(out, "--suite", str(suite), "--policies", "semantic,nearest")
    argv_short = [*argv, "--max-time-s", "4", "--json"]
    assert main(argv_short) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["ran"] == 8 and report["failed"] == 0  # 2 worlds x 2 policies x 2 runs
    rows = read_runs(out / "runs.csv")
    assert {r["world"] for r in rows} == {"maze:seed=1,size_m=4", "cave:seed=2,size_m=6"}
    assert all(r["mission_time_s"] <= 4.0 + 1e-6 for r in rows)
    summary = (out / "summary.md").read_text()
    for heading in (
        "Suites: `tiny` v2",
        "## Per family",
        "### maze (1 world)",
        "### cave (1 world)",
    ):
        assert heading in summary
    assert "## All worlds (2 worlds)" in summary and "| semantic | 4 |" in summary
    # Baselines do not score semantics: their share cells stay empty.
    assert all(r["semantic_share"] is None for r in rows if r["policy"] == "nearest")
    manifest = json.loads((out / "benchmark.json").read_text())
    assert manifest["suites"][0]["name"] == "tiny" and manifest["suites"][0]["version"] == 2
    fingerprint = json.loads((out / "fingerprint.json").read_text())
    assert fingerprint["suites"] == [{"name": "tiny", "version": 2}]
    # Resumes; a changed suite version is refused.
    assert main(argv_short) == 0
    assert json.loads(capsys.readouterr().out)["skipped"] == 8
    suite.write_text(SUITE_YAML.replace("version: 2", "version: 3"))
    assert main(argv_short) == 2
    assert "suite tiny" in capsys.readouterr().err


def test_suite_time_limits_per_world(tmp_path, capsys) -> None:
    suite = tmp_path / "my.yaml"
    suite.write_text(SUITE_YAML.replace("runs: 2", "runs: 1"))
    out = tmp_path / "s"
    argv = _bench(out, "--suite", str(suite), "--policies", "nearest", "--runs", "1")
    # The cave's own 6 s limit, the maze's area rule (>= 30 s): both in the fingerprint and env.
    import argparse

    from semexplore_gym.cli import benchmark

    parser = argparse.ArgumentParser()
    benchmark.add_parser(parser.add_subparsers())
    args = parser.parse_args(argv)
    tasks, records, worlds = benchmark._suite_tasks(args, lambda runs: list(range(runs)))
    limits = {t.world: t.max_time_s for t in tasks}
    assert limits["cave:seed=2,size_m=6"] == 6.0 and limits["maze:seed=1,size_m=4"] >= 30.0
    for t in tasks:
        assert t.env_config.episode.max_time_s == t.max_time_s
        assert t.env_config.episode.random_start is True
    assert records == [{"name": "tiny", "version": 2, "source": str(suite), "random_start": True}]


@pytest.mark.parametrize(
    ("suite", "fragment"), [("nope", "unknown suite 'nope'"), ("paper,paper", "twice")]
)
def test_bad_suites_fail_at_once(tmp_path, capsys, suite, fragment) -> None:
    assert main(_bench(tmp_path / "b", "--suite", suite)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0]


def test_many_worlds_plot_in_a_grid(tmp_path) -> None:
    from PIL import Image

    from semexplore_gym.evaluation.report import write_plots

    worlds = ["maze1", "maze2", *(f"maze:seed={i},size_m=4" for i in range(4))]
    run_benchmark(
        expand_tasks(worlds, ["semantic", "nearest"], [0, 1]),
        tmp_path,
        progress=False,
        task_fn=_constant,
    )
    text = write_summary(tmp_path).read_text()
    assert "### paper mazes (2 worlds)" in text and "### maze (4 worlds)" in text
    assert "## All worlds (6 worlds)" in text
    paths = {p.name: p for p in write_plots(tmp_path)}
    with Image.open(paths["explored_area.png"]) as im:
        assert im.size[0] < im.size[1] * 3  # two rows of at most four panels, not one long row
    # One exploration-curve figure per family, one panel per world class (seeds pooled).
    assert {"explored_area_paper_mazes.png", "explored_area_maze.png"} <= set(paths)
    with Image.open(paths["explored_area_maze.png"]) as im:
        assert im.size[0] < 800  # the four seed=i,size_m=4 worlds share one panel


def test_world_class_drops_only_the_seed() -> None:
    from semexplore_gym.evaluation.report import world_class

    assert world_class("office:seed=300,size_m=12") == "office:size_m=12"
    assert world_class("forest:size_m=8,seed=3,density=2") == "forest:size_m=8,density=2"
    assert world_class("maze:seed=*") == "maze"
    assert world_class("maze1") == "maze1"
    assert world_class("/maps/a:b/map.yaml") == "/maps/a:b/map.yaml"


def test_the_overview_has_one_row_per_family_and_policy(tmp_path) -> None:
    worlds = ["maze1", *(f"maze:seed={i},size_m=4" for i in range(3))]
    run_benchmark(
        expand_tasks(worlds, ["semantic", "frontier"], [0, 1, 2, 3]),
        tmp_path,
        progress=False,
        task_fn=_constant,
    )
    text = write_summary(tmp_path).read_text()
    overview = text.split("## Overview")[1].split("## Per family")[0]
    rows = [
        ln for ln in overview.splitlines() if ln.startswith("| paper") or ln.startswith("| maze")
    ]
    assert len(rows) == 4  # 2 families x 2 policies
    frontier_maze = next(r for r in rows if r.startswith("| maze | frontier |"))
    cells = [c.strip() for c in frontier_maze.strip("|").split("|")]
    assert cells[2] == "12" and cells[8] == "0.67"  # 3 worlds x 4 seeds; 100 s / 150 s
    # Twelve equal, negative log ratios: the paired signed-rank test rejects equality.
    assert float(cells[10]) < 0.001
