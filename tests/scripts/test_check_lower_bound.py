"""scripts/check_lower_bound.py: the bound per (world, start) of a benchmark folder, resumed."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "check_lower_bound.py"


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return subprocess.run(
        [sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=600, env=env
    )


def _fake_runs(folder: Path, t99_s: list[str], policies: tuple[str, ...] = ("p",)) -> None:
    """A runs.csv of one world (seed=* resolved per seed; each policy in turn) and a
    benchmark.json."""
    folder.mkdir()
    (folder / "benchmark.json").write_text(json.dumps({"fixed_start": False, "suites": None}))
    with (folder / "runs.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["world", "policy", "seed", "T99_s"])
        w.writeheader()
        for i, t in enumerate(t99_s):
            policy = policies[(i // 2) % len(policies)]
            w.writerow(
                {"world": "maze:seed=*,size_m=5", "policy": policy, "seed": i % 2, "T99_s": t}
            )


def test_a_mission_faster_than_the_bound_is_counted_and_the_csv_resumes(tmp_path, capsys) -> None:
    run_dir = tmp_path / "bench"
    _fake_runs(run_dir, ["0.5", "1e6", "", "1e6"])
    first = _run(str(run_dir), "--no-progress")
    assert first.returncode == 0, first.stderr
    assert "with T99: 3, T99 below the bound: 1" in first.stdout
    rows = list(csv.DictReader((run_dir / "lower_bounds.csv").open()))
    assert sorted(int(r["seed"]) for r in rows) == [0, 1]
    assert all(float(r["lower_bound_s"]) > 0.5 for r in rows)
    missions = tmp_path / "checked.csv"
    again = _run(str(run_dir), "--no-progress", "--missions-out", str(missions))  # resumed
    assert again.returncode == 0 and again.stdout == first.stdout
    assert len(list(csv.DictReader((run_dir / "lower_bounds.csv").open()))) == 2
    # The checked missions give `semexplore report` the script's own tables, bounds and all.
    assert len(list(csv.DictReader(missions.open()))) == 4
    from semexplore_gym.cli import main

    assert main(["report", str(missions)]) == 0
    assert capsys.readouterr().out.strip() == first.stdout.strip()


def test_a_folder_without_runs_is_one_clear_line(tmp_path) -> None:
    res = _run(str(tmp_path))
    assert res.returncode == 2 and res.stderr.strip().startswith("error: no runs.csv")


def test_folders_are_checked_together_per_family_with_the_oracle_s_wins(tmp_path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    # seed 0: oracle 1e6 s, p 2e6 s (a win); seed 1: the oracle never reached 99 % (a loss).
    _fake_runs(a, ["1e6", "", "2e6", "1e6"], ("oracle", "p"))
    _fake_runs(b, ["3e6", "3e6"], ("q",))
    res = _run(str(a), str(b), "--no-progress", "--json")
    assert res.returncode == 0, res.stderr
    maze = json.loads(res.stdout)["maze"]
    assert (maze["starts"], maze["missions"], maze["T99_below_bound"]) == (2, 6, 0)
    assert (maze["oracle_wins"], maze["oracle_pairs"]) == (1, 2)
    # A folder that ran the same policies from the same starts adds no mission.
    c = tmp_path / "c"
    _fake_runs(c, ["1e6", "", "2e6", "1e6"], ("oracle", "p"))
    again = _run(str(a), str(b), str(c), "--no-progress", "--json")
    assert json.loads(again.stdout)["maze"]["missions"] == 6
    assert "4 missions repeat a (world, start, policy) of an earlier folder" in again.stderr
    # The best known per start is the best of both folders: 1e6 s from either seed.
    fresh = _run(str(a), str(b), "--no-progress", "--json", "--fresh")
    assert json.loads(fresh.stdout)["maze"]["median_best_known_over_bound"] == pytest.approx(
        maze["median_best_known_over_bound"]
    )
    assert _run(str(a), str(b), "--out", str(tmp_path / "x.csv")).returncode == 2


def test_a_split_part_benchmark_is_checked_with_the_splits_starts(tmp_path) -> None:
    """`benchmark --split caves:test` records its suite as the split's YAML path and ":test"."""
    folder = tmp_path / "split"
    folder.mkdir()
    source = f"{REPO / 'configs' / 'splits' / 'caves.yaml'}:test"
    meta = {
        "fixed_start": False,
        "suites": [{"name": "caves-test", "version": 1, "source": source}],
    }
    (folder / "benchmark.json").write_text(json.dumps(meta))
    with (folder / "runs.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["world", "policy", "seed", "T99_s"])
        w.writeheader()
        w.writerow({"world": "cave:seed=63800,size_m=8,min_passage_m=0.5", "policy": "p",
                    "seed": 0, "T99_s": "1e6"})  # fmt: skip
    res = _run(str(folder), "--no-progress", "--json")
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["cave"]["missions"] == 1
