"""Benchmarks in the env's SLAM mode: runs.csv's SLAM columns, summary.md's SLAM table, and
older runs.csv files (without those columns) still read."""

from __future__ import annotations

import csv
import json

import pytest

from semexplore_gym.cli import main
from semexplore_gym.evaluation.run_row import CSV_COLUMNS, SLAM_COLUMNS, read_runs

WORLD = "maze:seed=3,size_m=4"
SUITE_YAML = f"name: tiny-slam\nversion: 1\nruns: 1\nmax_time_s: 12.0\nworlds:\n- {WORLD}\n"


@pytest.mark.slow
@pytest.mark.parametrize("source", ["worlds", "suite"])
def test_a_slam_benchmark_carries_the_slam_figures(tmp_path, capsys, source: str) -> None:
    pytest.importorskip("gtsam")
    out = tmp_path / "bench"
    if source == "suite":
        suite = tmp_path / "tiny.yaml"
        suite.write_text(SUITE_YAML)
        where = ["--suite", str(suite)]
    else:
        where = ["--worlds", WORLD, "--runs", "1", "--max-time-s", "12"]
    argv = ["benchmark", *where, "--policies", "nearest", "--env-config", "slam"]
    argv += ["--no-oracle", "--no-plots", "--no-progress", "--json", "--out", str(out)]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["ran"] == 1
    with (out / "runs.csv").open() as f:
        header = next(csv.reader(f))
    assert tuple(header[-len(SLAM_COLUMNS) :]) == SLAM_COLUMNS  # new columns at the end
    (row,) = read_runs(out / "runs.csv")
    assert 0.0 <= row["ate_m"] < 0.5 and 0.0 <= row["map_error"] <= 1.0
    assert row["rpe_m"] is None or 0.0 <= row["rpe_m"] < 0.5  # None: less than 1 m travelled
    assert isinstance(row["loop_closures"], int) and isinstance(row["slam_lost"], bool)
    summary = (out / "summary.md").read_text()
    assert "## SLAM" in summary
    assert "| maze | nearest | 1 | " + f"{row['ate_m']:.3f}" in summary


#: Every policy the package ships, torch-free ones first (the issue: every policy runs on the
#: SLAM map unchanged; the oracle stays privileged and reads the true map).
TORCH_FREE = (
    "semantic",
    "semantic-paper",
    "frontier",
    "nearest",
    "frontier-student",
    "pretrained:oracle_student",
    "pretrained:frontier_value",
    "oracle",
)
NEEDS_SB3 = ("pretrained:option_ppo", "pretrained:frontier_choice_maze", "pretrained:dagger_maze")


@pytest.mark.slow
def test_every_shipped_policy_runs_on_the_slam_map(tmp_path, capsys) -> None:
    pytest.importorskip("gtsam")
    specs = list(TORCH_FREE)
    try:
        import sb3_contrib  # noqa: F401
    except ImportError:
        pass
    else:
        specs += NEEDS_SB3
    out = tmp_path / "all"
    argv = ["benchmark", "--worlds", WORLD, "--runs", "1", "--max-time-s", "12"]
    argv += ["--policies", ",".join(specs), "--env-config", "slam"]
    argv += ["--no-oracle", "--no-plots", "--no-progress", "--json", "--out", str(out)]
    assert main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["ran"] == len(specs) and report["failed"] == 0
    rows = {r["policy"]: r for r in read_runs(out / "runs.csv")}
    assert sorted(rows) == sorted(specs)
    for spec, row in rows.items():
        assert row["steps"] > 0 and row["coverage"] > 0, spec
        assert row["ate_m"] is not None and 0.0 <= row["ate_m"] < 0.5, spec
        assert row["collisions"] == 0, spec


def test_without_slam_the_columns_are_empty_and_the_section_absent(tmp_path, capsys) -> None:
    out = tmp_path / "plain"
    argv = ["benchmark", "--worlds", WORLD, "--runs", "1", "--max-time-s", "3"]
    argv += ["--policies", "nearest", "--no-oracle", "--no-plots", "--no-progress"]
    assert main([*argv, "--out", str(out)]) == 0
    (row,) = read_runs(out / "runs.csv")
    assert all(row[k] is None for k in SLAM_COLUMNS)
    assert "## SLAM" not in (out / "summary.md").read_text()


def test_an_older_runs_csv_without_the_slam_columns_still_reads(tmp_path) -> None:
    old = [c for c in CSV_COLUMNS if c not in SLAM_COLUMNS]
    cells = dict.fromkeys(old, "")
    cells.update(world="maze1", policy="nearest", seed="0", self_stopped="True")
    cells.update(stop_reason="done", collisions="0", steps="5")
    path = tmp_path / "runs.csv"
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=old)
        w.writeheader()
        w.writerow(cells)
    (row,) = read_runs(path)
    assert row["self_stopped"] is True and "ate_m" not in row
    # A SLAM row's lost flag must be a boolean or empty.
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(CSV_COLUMNS))
        w.writeheader()
        w.writerow({**cells, "ate_m": "0.02", "loop_closures": "3", "slam_lost": "maybe"})
    with pytest.raises(ValueError, match="slam_lost must be True or False, got 'maybe'"):
        read_runs(path)
