"""Best known per (world, start): the table, merging a run into it, the ratios and the summary."""

from __future__ import annotations

import csv
import json
import math

import pytest

from semexplore_gym.evaluation.best_known import (
    COLUMNS,
    SECTION_TITLE,
    merge_runs,
    mission_ratios,
    read_table,
    reproduce_command,
    run_start,
    summary_lines,
    write_best_known,
    write_table,
)
from semexplore_gym.evaluation.harness import CSV_COLUMNS


def _row(world: str, policy: str, seed: int, t99: float | None, d99: float | None = None) -> dict:
    row = {k: None for k in CSV_COLUMNS}
    row.update(world=world, policy=policy, seed=seed, T99_s=t99, D99_m=d99)
    return row


def _entry(world: str, seed: int, t99: float, bound_s: float | None = None) -> dict:
    return {
        "world": world,
        "seed": seed,
        "start": "random",
        "T99_s": t99,
        "T99_policy": "oracle",
        "D99_m": t99 * 0.2,
        "D99_policy": "oracle",
        "lower_bound_s": bound_s,
        "lower_bound_m": None if bound_s is None else bound_s * 0.22,
    }


TABLE = {
    ("maze:seed=1", 0, "random"): _entry("maze:seed=1", 0, 200.0, 100.0),
    ("cave:seed=2", 0, "random"): _entry("cave:seed=2", 0, 100.0),
}


def test_a_table_survives_writing_and_reading(tmp_path):
    path = write_table(tmp_path / "t.csv", TABLE)
    with path.open() as f:
        assert tuple(next(csv.reader(f))) == COLUMNS
    assert read_table(path) == TABLE
    assert read_table(tmp_path / "absent.csv") == {}


def test_an_infinite_bound_survives_and_flags_a_mission_that_reached_the_goal(tmp_path):
    table = {("cave:seed=2", 0, "random"): _entry("cave:seed=2", 0, 100.0, math.inf)}
    table[("cave:seed=2", 0, "random")]["lower_bound_m"] = math.inf
    assert read_table(write_table(tmp_path / "t.csv", table)) == table
    ratios = mission_ratios([_row("cave:seed=2", "semantic", 0, 120.0, 30.0)], table, "random")
    assert ratios[0]["below_bound"] and ratios[0]["bound_ratio"] is None


@pytest.mark.parametrize(
    ("cell", "value", "message"),
    [
        ("seed", "x", "seed is not an integer"),
        ("start", "left", "start must be random or fixed"),
        ("T99_s", "-3", "T99_s must be a finite number"),
        ("T99_s", "nan", "T99_s must be a finite"),
        ("T99_s", "inf", "T99_s must be a finite"),
    ],
)
def test_a_malformed_table_names_its_line(tmp_path, cell, value, message):
    path = write_table(tmp_path / "t.csv", TABLE)
    rows = list(csv.DictReader(path.open()))
    rows[1][cell] = value
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(COLUMNS))
        w.writeheader()
        w.writerows(rows)
    with pytest.raises(ValueError, match=rf"t\.csv line 3: {message}"):
        read_table(path)


def test_merging_keeps_the_best_and_lists_what_beat_the_table():
    rows = [
        _row("maze:seed=1", "semantic", 0, 150.0, 30.0),  # beats 200 s
        _row("maze:seed=1", "nearest", 0, 199.5, 50.0),  # within the margin: not a beat
        _row("cave:seed=2", "semantic", 0, None, None),  # never reached 99 %
        _row("office:seed=3", "semantic", 4, 80.0, 20.0),  # new key
    ]
    merged, beats = merge_runs(TABLE, rows, "random")
    assert [(b["policy"], b["best_known_T99_s"]) for b in beats] == [("semantic", 200.0)]
    maze = merged[("maze:seed=1", 0, "random")]
    assert (maze["T99_s"], maze["T99_policy"], maze["D99_m"], maze["D99_policy"]) == (
        150.0,
        "semantic",
        30.0,
        "semantic",
    )
    assert maze["lower_bound_s"] == 100.0  # the bound stays
    assert merged[("cave:seed=2", 0, "random")] == TABLE[("cave:seed=2", 0, "random")]
    new = merged[("office:seed=3", 4, "random")]
    assert new["T99_s"] == 80.0 and new["lower_bound_s"] is None
    assert TABLE[("maze:seed=1", 0, "random")]["T99_s"] == 200.0  # the input is not changed
    # Fixed starts are other missions: nothing of the random-start table is compared.
    assert merge_runs(TABLE, rows, "fixed")[1] == []


def test_the_table_names_the_expert_version_a_mission_ran():
    rows = [
        {
            **_row("maze:seed=1", "semantic[cost.w_v=2]", 0, 100.0, 5.0),
            "policy_version": "semantic-v3",
        },
        {**_row("cave:seed=2", "semantic", 0, 50.0, 10.0), "policy_version": "semantic-v3"},
    ]
    merged, _ = merge_runs(TABLE, rows, "random")
    assert merged[("maze:seed=1", 0, "random")]["T99_policy"] == "semantic-v3[cost.w_v=2]"
    assert merged[("cave:seed=2", 0, "random")]["D99_policy"] == "semantic-v3"


def test_ratios_flag_a_mission_below_the_bound():
    rows = [
        _row("maze:seed=1", "semantic", 0, 300.0, 66.0),
        _row("maze:seed=1", "broken", 0, 90.0, 10.0),  # faster than any explorer can be
        _row("maze:seed=1", "nearest", 0, None, None),
        _row("maze:seed=9", "semantic", 0, 10.0, 1.0),  # not in the table
    ]
    by = {r["policy"]: r for r in mission_ratios(rows, TABLE, "random")}
    assert set(by) == {"semantic", "broken", "nearest"}
    assert by["semantic"]["best_ratio"] == 1.5 and by["semantic"]["bound_ratio"] == 3.0
    assert by["semantic"]["distance_bound_ratio"] == pytest.approx(3.0)
    assert not by["semantic"]["below_bound"] and not by["semantic"]["at_best"]
    assert by["broken"]["below_bound"] and by["broken"]["at_best"]
    assert math.isinf(by["nearest"]["best_ratio"]) and not by["nearest"]["below_bound"]
    text = "\n".join(summary_lines(list(by.values()), [], len(TABLE)))
    assert text.startswith(SECTION_TITLE) and "### maze" in text
    assert "**1 (bug)**" in text  # the broken policy's row


def test_a_beat_comes_with_the_command_that_reproduces_it():
    beat = {**_row("maze:seed=1,size_m=5", "semantic[cost.w_v=2]", 3, 150.0), "start": "fixed"}
    cmd = reproduce_command(beat)
    assert cmd == (
        "semexplore explore --world maze:seed=1,size_m=5 --policy 'semantic[cost.w_v=2]' "
        "--seed 3 --env-set episode.random_start=false --json"
    )
    long = reproduce_command({**beat, "start": "random", "mission_time_s": 2400.4})
    assert long.endswith("--env-set episode.random_start=true --max-time-s 2401 --json")
    lines = summary_lines([], [{**beat, "best_known_T99_s": 200.0}], 2)
    assert any(cmd in line and "150.0 s (best known 200.0 s)" in line for line in lines)


def test_only_runs_with_the_default_env_are_compared(tmp_path):
    def manifest(**kw):
        meta = {"fixed_start": False, "config": None, "env_overrides": [], **kw}
        (tmp_path / "benchmark.json").write_text(json.dumps(meta))
        return run_start(tmp_path)

    assert run_start(tmp_path) is None  # no manifest
    assert manifest() == "random" and manifest(fixed_start=True) == "fixed"
    assert manifest(config="slam") is None
    assert manifest(config="default") == "random"  # the default preset, named
    assert manifest(env_overrides=["lidar.max_range_m=5"]) is None
    (tmp_path / "benchmark.json").write_text(json.dumps({"fixed_start": False, "config": None}))
    assert run_start(tmp_path) is None  # an older manifest: overrides unknown
    # A suite or split whose own starts are fixed (the DungeonMaps' markers).
    dungeon = {"name": "dungeon-test", "version": 1, "source": "s", "random_start": False}
    assert manifest(suites=[dungeon]) == "fixed"
    assert manifest(suites=[{**dungeon, "random_start": True}]) == "random"
    assert manifest(suites=[dungeon, {**dungeon, "random_start": True}]) is None  # both kinds
    # A manifest written before suites recorded their starts reads as before.
    assert manifest(suites=[{"name": "paper", "version": 1, "source": "s"}]) == "random"


def test_a_split_with_fixed_starts_records_them_in_the_manifest(tmp_path):
    from semexplore_gym.evaluation.suites import Suite, SuiteWorld, suite_tasks

    worlds = (SuiteWorld("maze1"),)
    fixed = Suite(name="fixed", version=1, worlds=worlds, random_start=False)
    _, records, _ = suite_tasks([fixed], ["nearest"], lambda runs: [0])
    assert records[0]["random_start"] is False
    _, records, _ = suite_tasks(
        [Suite(name="r", version=1, worlds=worlds)], ["nearest"], lambda runs: [0]
    )
    assert records[0]["random_start"] is True
    _, records, _ = suite_tasks(
        [Suite(name="r", version=1, worlds=worlds)], ["nearest"], lambda runs: [0], fixed_start=True
    )
    assert records[0]["random_start"] is False


def test_benchmark_compares_with_a_table_and_writes_the_updated_one(tmp_path, capsys):
    from semexplore_gym.cli import main

    world = "maze:seed=1,size_m=4"
    table = tmp_path / "table.csv"
    write_table(table, {(world, 0, "random"): {**_entry(world, 0, 1e4, 1.0), "world": world}})
    args = ["benchmark", "--worlds", world, "--policies", "nearest", "--runs", "1"]
    args += ["--max-time-s", "400", "--no-progress", "--no-plots", "--best-known", str(table)]
    assert main([*args, "--out", str(tmp_path / "run")]) == 0
    capsys.readouterr()
    text = (tmp_path / "run" / "summary.md").read_text()
    assert SECTION_TITLE in text and "New best known (1 mission beat" in text
    assert (
        "semexplore explore --world maze:seed=1,size_m=4 --policy nearest --seed 0 "
        "--env-set episode.random_start=true --json"
    ) in text
    updated = read_table(tmp_path / "run" / "best_known.csv")[(world, 0, "random")]
    assert updated["T99_policy"] == "nearest" and updated["T99_s"] < 1e4
    assert updated["lower_bound_s"] == 1.0


def test_benchmark_refuses_a_missing_or_malformed_table(tmp_path, capsys):
    from semexplore_gym.cli import main

    args = ["benchmark", "--worlds", "maze:seed=1,size_m=4", "--policies", "nearest"]
    args += ["--out", str(tmp_path / "run")]
    assert main([*args, "--best-known", str(tmp_path / "nope.csv")]) == 2
    assert "--best-known" in capsys.readouterr().err and not (tmp_path / "run").exists()
    bad = tmp_path / "bad.csv"
    bad.write_text("world,seed\nmaze1,0\n")
    assert main([*args, "--best-known", str(bad)]) == 2
    assert "not a best-known table" in capsys.readouterr().err


def test_write_best_known_writes_nothing_for_a_run_with_other_settings(tmp_path):
    (tmp_path / "benchmark.json").write_text(json.dumps({"config": "slam", "env_overrides": []}))
    assert write_best_known(tmp_path)["csv"] is None
    assert not (tmp_path / "best_known.csv").exists()
