"""scripts/bench_imitation.py: learners run for the expert's mission time; CSV resumes."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


class FakeRunner:
    """Expert missions last 10 s per seed unit; learners cover 0.1 per 10 s of limit."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, str, int, float | None]] = []

    def __call__(self, world: str, policy: str, seed: int, max_time_s: float | None) -> dict:
        self.calls.append((world, policy, seed, max_time_s))
        if policy == "semantic":
            t = 10.0 * seed
            return {"mission_time_s": t, "coverage": 0.8, "collisions": 0, "wall_time_s": 1.0}
        assert max_time_s is not None
        cov = 0.01 * max_time_s * (2.0 if "good" in policy else 1.0)
        return {"mission_time_s": max_time_s, "coverage": cov, "collisions": 1, "wall_time_s": 1.0}


def test_learners_run_for_the_expert_time_and_the_csv_resumes(tmp_path: Path, script: Any) -> None:
    bench = script("bench_imitation")
    runner = FakeRunner()
    out = tmp_path / "b.csv"
    rows = bench.run_imitation_benchmark(
        ["maze:seed=*"], [2, 4], ["a.zip", "good.zip"], out, runner=runner, expert_max_time_s=99
    )
    assert [c[1:] for c in runner.calls] == [
        ("semantic", 2, 99),
        ("sb3:a.zip", 2, 20.0),
        ("sb3:good.zip", 2, 20.0),
        ("semantic", 4, 99),
        ("sb3:a.zip", 4, 40.0),
        ("sb3:good.zip", 4, 40.0),
    ]
    assert runner.calls[0][0] == "maze:seed=2"  # the seed placeholder is filled in
    ratios = bench.mean_ratios(rows)
    # a: 0.2/0.8 and 0.4/0.8; good: twice that.
    assert ratios == pytest.approx({"sb3:a.zip": 0.375, "sb3:good.zip": 0.75})
    with open(out, newline="") as f:
        written = list(csv.DictReader(f))
    assert len(written) == 6 and float(written[1]["ratio"]) == pytest.approx(0.25)
    assert float(written[4]["expert_time_s"]) == 40.0
    # Running again reuses every row: no mission is repeated, the table is the same.
    again = FakeRunner()
    rows2 = bench.run_imitation_benchmark(
        ["maze:seed=*"], [2, 4], ["a.zip", "good.zip"], out, runner=again, expert_max_time_s=99
    )
    assert again.calls == []
    table = bench.markdown_table(rows2)
    assert table == bench.markdown_table(rows)
    assert "| maze:seed=* | 4 | 40.0 | 0.800 | 0.400 | 0.50 | 0.800 | 1.00 |" in table
    assert "**0.375**" not in table and "**0.38**" in table and "**0.75**" in table


def test_seed_ranges(script: Any) -> None:
    bench = script("bench_imitation")
    assert bench.parse_seed_range("100-103") == [100, 101, 102, 103]
    assert bench.parse_seed_range("1,5,7-8") == [1, 5, 7, 8]
    with pytest.raises(ValueError, match="seed list"):
        bench.parse_seed_range("a-b")


def test_real_missions_with_a_tiny_budget(
    tmp_path: Path, capsys: pytest.CaptureFixture, script: Any
) -> None:
    """Expert capped at 3 s, an untrained policy for the same 3 s (real env and harness)."""
    pytest.importorskip("torch")
    pytest.importorskip("stable_baselines3")
    from gymnasium import spaces

    from semexplore_gym.training.learner import make_learner_policy, save_policy
    from semexplore_gym.wrappers.egocentric import EgocentricParams, egocentric_observation_space

    params = EgocentricParams(
        crop_cells=36, crop_resolution_m=0.15, channels=("occupancy", "trail")
    )
    policy = make_learner_policy(
        egocentric_observation_space(params),
        spaces.Box(-1.0, 1.0, (2,), np.float32),
        net_arch=[16],
        features_extractor_kwargs={"cnn_output_dim": 16},
    )
    model = save_policy(policy, tmp_path / "m.zip", params)
    out = tmp_path / "bench.csv"
    rc = script("bench_imitation").main(
        ["--models", str(model), "--seeds", "100", "--expert-max-time-s", "3", "--out", str(out)]
    )
    assert rc == 0
    with open(out, newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["policy"] for r in rows] == ["semantic", f"sb3:{model}"]
    assert float(rows[0]["mission_time_s"]) == pytest.approx(3.0)
    assert float(rows[1]["mission_time_s"]) == pytest.approx(3.0)
    assert 0.0 < float(rows[1]["coverage"]) <= 1.0
    text = capsys.readouterr().out
    assert "| maze:size_m=5,seed=* | 100 | 3.0 |" in text and "mean ratio" in text


def test_summary_per_model_and_paired_comparison(script: Any) -> None:
    bench = script("bench_imitation")
    rows = [{"world": "m", "seed": s, "policy": "semantic", "ratio": 1.0} for s in range(12)]
    rows += [{"world": "m", "seed": s, "policy": "a", "ratio": 0.5 + 0.04 * s} for s in range(12)]
    rows += [{"world": "m", "seed": s, "policy": "b", "ratio": 0.4 + 0.04 * s} for s in range(12)]
    lines = bench.summary_lines(rows)
    assert lines[0].startswith("a: mean ratio 0.720, median 0.720, >= 0.8 on 4/12")
    assert lines[1].startswith("b: mean ratio 0.620")
    # a beats b on all 12 worlds by 0.1: a small p; b against itself would be p = 1.
    assert "a - b: median difference +0.100 over 12 worlds, a ahead on 12, behind on 0" in lines[2]
    assert float(lines[2].rsplit("p = ", 1)[1]) < 0.001
