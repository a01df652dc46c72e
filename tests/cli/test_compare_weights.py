"""``semexplore compare-weights``: table statistics, and a tiny end-to-end run."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest
from scipy.stats import mannwhitneyu

from semexplore_gym.cli import main
from semexplore_gym.cli.compare_weights import PAPER, TUNED, summarise, weight_sets


def _rows(label: str, times: list[float], cov: float = 0.99) -> list[dict]:
    return [{"policy": label, "mission_time_s": t, "coverage": cov} for t in times]


def _tiny_run(max_time_s: float) -> list[str]:
    """A one-trial, one-run compare-weights on 4 m mazes (add ``--out``)."""
    return [
        "compare-weights",
        "--train-worlds", "maze:seed=*,size_m=4",
        "--test-worlds", "maze:seed=*,size_m=4",
        "--trials", "1", "--train-runs", "1", "--runs", "1",
        "--max-time-s", f"{max_time_s:g}", "--no-progress",
    ]  # fmt: skip


def test_summarise_medians_completion_and_p_values() -> None:
    rows = _rows(PAPER, [100.0, 110.0, 120.0, 130.0]) + _rows(TUNED, [50.0, 60.0, 70.0, 80.0])
    rows += _rows("semantic[cost.w_p=0]", [100.0, 110.0, 120.0, 130.0], cov=0.87)
    table = summarise(rows, [PAPER, TUNED, "semantic[cost.w_p=0]"], 0.97, 600.0)
    paper, tuned, ablated = table
    assert paper["median_mission_time_s"] == 115.0 and math.isnan(paper["p_value_vs_paper"])
    assert tuned["median_mission_time_s"] == 65.0 and tuned["completed_fraction"] == 1.0
    expected_p = mannwhitneyu(
        [50, 60, 70, 80], [100, 110, 120, 130], alternative="two-sided"
    ).pvalue
    assert tuned["p_value_vs_paper"] == pytest.approx(expected_p)
    assert ablated["p_value_vs_paper"] == 1.0  # same times
    # Same times but every mission 0.1 short of the target: scores 175 vs 115 all differ.
    expected_p = mannwhitneyu(
        [160, 170, 180, 190], [100, 110, 120, 130], alternative="two-sided"
    ).pvalue
    assert ablated["p_value_score_vs_paper"] == pytest.approx(expected_p)
    assert ablated["mean_coverage"] == pytest.approx(0.87)
    assert ablated["completed_fraction"] == 0.0
    assert ablated["mean_score"] == pytest.approx(115.0 + 60.0)


def test_weight_sets_ablate_the_paper_terms() -> None:
    sets = weight_sets({"cost.w_v": 1.0})
    assert sets[TUNED] == {"cost.w_v": 1.0, "cost.w_p": 0.2, "cost.w_i": 0.1}
    assert sets["semantic[cost.w_p=0;cost.w_i=0]"] == {
        "cost.w_v": 4.0,
        "cost.w_p": 0.0,
        "cost.w_i": 0.0,
    }
    assert (
        sets["semantic[cost.w_i=0]"]["cost.w_i"] == 0.0
        and sets["semantic[cost.w_i=0]"]["cost.w_p"] == 0.2
    )


def test_ablation_labels_are_the_specs_that_explore_and_benchmark_run() -> None:
    from policies.registry import make_policy

    for label, overrides in weight_sets({"cost.w_v": 1.0}).items():
        built = make_policy(label, **overrides).params
        if label in (PAPER, TUNED):
            continue  # labels
        assert make_policy(label).params == built, label


def test_overlapping_train_and_test_seeds_are_rejected(tmp_path: Path) -> None:
    argv = [
        "compare-weights",
        "--train-worlds",
        "maze:seed=*,size_m=4",
        "--test-worlds",
        "maze:seed=*,size_m=4",
    ]
    assert main([*argv, "--test-seed0", "0", "--out", str(tmp_path)]) == 2


def test_compare_weights_writes_table_and_plot(tmp_path: Path) -> None:
    out = tmp_path / "cw"
    argv = [*_tiny_run(max_time_s=20), "--out", str(out)]
    assert main(argv) == 0
    with (out / "compare.csv").open() as f:
        table = list(csv.DictReader(f))
    assert [r["weights"] for r in table] == list(weight_sets({}))
    assert all(int(r["n"]) == 1 for r in table)
    assert float(table[0]["median_mission_time_s"]) <= 20.0 + 1e-6
    assert "| semantic[tuned] |" in (out / "compare.md").read_text()
    assert (out / "mission_times.png").stat().st_size > 1000
    assert len((out / "tuning" / "trials.jsonl").read_text().splitlines()) == 1
    assert (out / "tuning" / "study.sqlite").exists()
    sets = json.loads((out / "weights.json").read_text())["sets"]
    assert sets[TUNED] == sets[PAPER]  # one trial: the enqueued paper weights
    with (out / "test" / "runs.csv").open() as f:
        runs = list(csv.DictReader(f))
    assert sorted(r["policy"] for r in runs) == sorted(weight_sets({}))
    assert {r["seed"] for r in runs} == {"1000"}


def test_agents_join_the_test_table_and_bad_agents_fail_early(tmp_path: Path) -> None:
    out = tmp_path / "cw"
    argv = _tiny_run(max_time_s=10)
    assert main([*argv, "--agents", "random[rnd]", "--out", str(out)]) == 0
    with (out / "compare.csv").open() as f:
        table = {r["weights"]: r for r in csv.DictReader(f)}
    assert list(table) == [*weight_sets({}), "random[rnd]"]
    assert int(table["random[rnd]"]["n"]) == 1
    assert float(table["random[rnd]"]["median_mission_time_s"]) == pytest.approx(10.0)
    assert "`random[rnd]`: learned agent" in (out / "compare.md").read_text()

    bad = tmp_path / "bad"
    assert main([*argv, "--agents", "sb3:no/such/model.zip", "--out", str(bad)]) == 2
    assert not (bad / "tuning").exists()  # rejected before any tuning trial
    assert main([*argv, "--agents", "semantic[x]", "--out", str(bad)]) == 2
