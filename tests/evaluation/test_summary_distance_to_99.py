"""``summary.md`` compares the distance driven until 99 % coverage (D99) pair by pair, through
the CLI, from each mission's trace and trajectory."""

from __future__ import annotations

import re

import numpy as np
import pytest

from semexplore_gym.cli import main
from semexplore_gym.evaluation.harness import read_runs
from semexplore_gym.evaluation.report import add_distance_to_99, write_summary
from semexplore_gym.evaluation.run_writer import distance_to_coverage_m

WORLD = "maze:seed=1,size_m=6"


def _bench(out, policies: str, max_time_s: str) -> list[dict]:
    argv = ["benchmark", "--worlds", WORLD, "--policies", policies, "--runs"]
    argv += ["2" if "," in policies else "1", "--max-time-s", max_time_s, "--out", str(out)]
    assert main([*argv, "--no-oracle", "--no-plots", "--no-progress"]) == 0
    return read_runs(out / "runs.csv")


@pytest.mark.slow
def test_the_summary_pairs_the_distance_to_99_percent(tmp_path, capsys) -> None:
    out = tmp_path / "b"
    rows = _bench(out, "semantic,nearest", "300")
    d99 = {(r["policy"], r["seed"]): distance_to_coverage_m(out, r) for r in rows}
    assert all(d is not None and np.isfinite(d) for d in d99.values())  # all reached 99 %
    for r in rows:  # no farther than the whole path, and more than nothing for nearest
        assert d99[r["policy"], r["seed"]] <= r["path_length_m"] + 1e-6
    assert all(d99["nearest", s] > 0 for s in (0, 1))
    ratios = [d99["semantic", s] / d99["nearest", s] for s in (0, 1)]
    summary = (out / "summary.md").read_text()
    section = summary.split(f"## {WORLD}")[1]
    cell = re.search(r"^\| nearest \| distance to 99 % \| [\d.]+ \| ([\d.]+) \|", section, re.M)
    assert cell is not None and float(cell.group(1)) == round(float(np.median(ratios)), 2)


def test_a_mission_that_never_reached_99_percent_has_no_distance(tmp_path, capsys) -> None:
    out = tmp_path / "b"
    rows = _bench(out, "nearest", "4")
    add_distance_to_99(out, rows)
    assert rows[0]["coverage"] < 0.99 and rows[0]["D99_m"] is None
    (out / "traces" / next(p.name for p in (out / "traces").iterdir())).unlink()
    add_distance_to_99(out, rows)  # a missing trace: no distance either, no error
    assert rows[0]["D99_m"] is None
    assert write_summary(out).exists()  # the summary is written without it
