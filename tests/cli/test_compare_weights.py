"""``semexplore compare-weights``: table statistics, and a tiny end-to-end run."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest
from scipy.stats import mannwhitneyu

from semexplore_gym.cli import main
from semexplore_gym.cli.compare_weights import (
    PAPER,
    TUNED,
    TUNED_IS_PAPER_NOTE,
    summarise,
    tuned_is_paper,
    weight_sets,
)


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


def test_tuned_is_paper_only_when_no_trial_beat_the_paper() -> None:
    assert tuned_is_paper(weight_sets({}))
    assert not tuned_is_paper(weight_sets({"cost.w_v": 1.0}))


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
    from semexplore_gym.policies.registry import make_policy

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


@pytest.mark.slow
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
    assert TUNED_IS_PAPER_NOTE in (out / "compare.md").read_text()  # and the table says so
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


#: A two-world suite: the maze's limit follows the area rule, the cave has its own.
TINY_SUITE = {
    "name": "tiny",
    "version": 1,
    "runs": 2,
    "random_start": True,
    "time_per_m2_s": 1.0,
    "min_time_s": 12,
    "worlds": ["maze:seed=1,size_m=4", {"world": "cave:seed=2,size_m=6", "max_time_s": 6}],
}


def test_compare_weights_tests_on_a_suite_as_benchmark_runs_it(tmp_path: Path, capsys) -> None:
    from semexplore_gym.evaluation.suites import save_suite, suite_from_dict

    suite = save_suite(suite_from_dict(TINY_SUITE), tmp_path / "tiny.yaml")
    out = tmp_path / "cw"
    argv = [
        "compare-weights", "--train-worlds", "maze:seed=*,size_m=4", "--test-suite", str(suite),
        "--trials", "1", "--train-runs", "1", "--train-max-time-s", "5", "--out", str(out),
        "--json",
    ]  # fmt: skip
    assert main(argv) == 0  # progress bars on, as users run it
    report = json.loads(capsys.readouterr().out)
    rows = list(csv.DictReader((out / "test" / "runs.csv").open()))
    # Every set on both worlds with the suite's runs (2) and start seeds (0, 1), not 1000+.
    assert len(rows) == 2 * 2 * len(weight_sets({}))
    assert {r["seed"] for r in rows} == {"0", "1"}
    times = {(r["world"], r["policy"]): float(r["mission_time_s"]) for r in rows}
    assert max(t for (w, _), t in times.items() if w.startswith("cave")) <= 6.0 + 1e-6
    from semexplore_gym.evaluation.suites import load_suite, world_time_limit_s
    from semexplore_gym.maps import make_world

    maze = make_world("maze:seed=1,size_m=4")
    area_m2 = float(maze.free_mask.sum()) * maze.free_geometry.resolution_m**2
    limit = world_time_limit_s(load_suite(suite), load_suite(suite).worlds[0], area_m2)
    assert limit > 12.0  # the area rule, above the suite's minimum and the tuning's 5 s
    step_s = 0.2  # the env's control step: the step that crosses the limit ends the mission
    assert limit < max(t for (w, _), t in times.items() if w.startswith("maze")) <= limit + step_s
    # Tuning ran at its own limit (5 s), not the suite's.
    trial = json.loads((out / "tuning" / "trials.jsonl").read_text().splitlines()[0])
    assert trial["value"] <= 5.0 + 600.0
    summary = Path(report["per_family"]).read_text()
    assert "### maze (1 world)" in summary and "### cave (1 world)" in summary
    assert "Suites: `tiny` v1." in summary
    assert "semantic[paper]" in summary and "test/summary.md" in (out / "compare.md").read_text()

    # The paper row is the same missions `benchmark --suite` runs with the default expert.
    bench = tmp_path / "bench"
    assert main(["benchmark", "--suite", str(suite), "--policies", "semantic", "--out",
                 str(bench), "--no-plots", "--no-progress", "--no-oracle"]) == 0  # fmt: skip
    ref = {
        (r["world"], r["seed"]): (r["mission_time_s"], r["coverage"], r["path_length_m"])
        for r in csv.DictReader((bench / "runs.csv").open())
    }
    paper = {
        (r["world"], r["seed"]): (r["mission_time_s"], r["coverage"], r["path_length_m"])
        for r in rows
        if r["policy"] == PAPER
    }
    assert paper == ref


def test_test_suite_and_test_worlds_exclude_each_other(tmp_path: Path, capsys) -> None:
    base = ["compare-weights", "--train-worlds", "maze:seed=*,size_m=4", "--out", str(tmp_path)]
    for argv in ([*base, "--test-suite", "caves", "--test-worlds", "maze1"], base):
        with pytest.raises(SystemExit) as exc:  # argparse's usage error
            main(argv)
        assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "not allowed with argument" in err and "--test-worlds --test-suite" in err.replace(
        "/", " "
    )
    assert main([*base, "--test-suite", "no_such_suite", "--trials", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--test-suite" in err[0] and "no_such_suite" in err[0]
    assert not (tmp_path / "tuning").exists()  # rejected before any tuning trial


def test_help_says_the_default_budget_is_a_demo_and_gives_the_documented_one(capsys) -> None:
    with pytest.raises(SystemExit):
        main(["compare-weights", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "default budget" in text and "is a demo" in text
    budget = "--trials 16 --runs 10 --max-time-s 600"
    assert budget in text
    # The budget is the one the documented table was measured with.
    docs = Path(__file__).resolve().parents[2] / "docs" / "learning-first-designs.md"
    learning = " ".join(docs.read_text(encoding="utf-8").split())
    measured = learning.split("## Hand-tuned vs learned weights", 1)[1].split("|", 1)[0]
    assert budget in measured and "is a demo" in measured
