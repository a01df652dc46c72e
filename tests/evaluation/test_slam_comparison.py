"""Perfect map against SLAM: the same missions paired per family and policy, and the reference
policy's time over the others' on each map (``semexplore report ... --table slam-vs-perfect``)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from scipy.stats import wilcoxon

from semexplore_gym.evaluation.slam_comparison import median_p, slam_vs_perfect_lines

SLAM_FIGURES = {"ate_m": 0.02, "odom_ate_m": 0.4, "map_error": 0.05, "loop_closures": 3}


def _row(policy: str, seed: int, time_s: float, wall_s: float, **slam: Any) -> dict[str, Any]:
    return {
        "world": "maze1",
        "policy": policy,
        "seed": seed,
        "mission_time_s": time_s,
        "coverage": 0.99,
        "self_stopped": True,
        "collisions": 0,
        "wall_time_s": wall_s,
        "ate_m": None,
        **slam,
    }


def _cells(lines: list[str], start: str) -> list[str]:
    (line,) = [ln for ln in lines if ln.startswith(start)]
    return [c.strip() for c in line.strip().strip("|").split("|")]


def test_missions_pair_by_world_policy_and_seed() -> None:
    perfect = [_row("semantic", s, 100.0 + s, 1.0) for s in range(4)]
    perfect += [_row("nearest", s, 200.0, 1.0) for s in range(4)]
    slam = [
        _row(
            "semantic",
            s,
            110.0,
            2.0,
            slam_false_stop=s == 0,
            **SLAM_FIGURES,
            coverage=0.96 + s / 100,
        )
        for s in range(3)
    ]
    slam += [_row("nearest", s, 150.0, 2.0, **SLAM_FIGURES) for s in range(4)]
    slam.append(_row("frontier", 0, 90.0, 1.0, **SLAM_FIGURES))  # no perfect-map twin
    lines = slam_vs_perfect_lines(perfect + slam, "semantic")
    cells = _cells(lines, "| paper mazes | semantic |")
    assert cells[2] == "3"  # seed 3 has no SLAM twin
    assert cells[3] == "3/3 / 2/3"  # seed 0's SLAM mission ended at 0.96
    assert cells[4] == "0.990 / 0.970"  # median true coverage on each map
    ratios = [110.0 / (100.0 + s) for s in range(3)]
    assert cells[6] == median_p(ratios)
    assert cells[6].startswith("1.09 (p = ")
    assert cells[7:11] == ["0.020", "20.0", "0.050", "3"]
    assert cells[11] == "1/3" and cells[12] == "2.00×"
    assert not [ln for ln in lines if ln.startswith("| paper mazes | frontier |")]
    # The second table: semantic's time over the others' on each map; frontier ran on SLAM only.
    head = next(ln for ln in lines if ln.startswith("| family | map |"))
    assert head == "| family | map | semantic ÷ nearest | semantic ÷ frontier |"
    assert _cells(lines, "| paper mazes | perfect |")[2:] == [
        median_p([(100.0 + s) / 200.0 for s in range(4)]) + ", n = 4",
        "–, n = 0",
    ]
    assert _cells(lines, "| paper mazes | SLAM |")[2:] == [
        median_p([110.0 / 150.0] * 3) + ", n = 3",
        "1.22 (p = –), n = 1",
    ]


def test_the_p_value_is_wilcoxons_on_the_log_ratios() -> None:
    ratios = [1.1, 1.3, 0.9, 1.2, 1.25]
    p = wilcoxon(np.log(ratios), alternative="two-sided").pvalue
    assert median_p(ratios) == f"1.20 (p = {p:.2g})"
    assert median_p([1.0, 1.0]) == "1.00 (p = –)"  # no difference, no test
    assert median_p([]) == "–"


def test_rows_follow_the_families_first_seen_order() -> None:
    office = "office:seed=1,size_m=12"
    rows = [
        _row("semantic", 0, 100.0, 1.0),
        {**_row("semantic", 0, 100.0, 1.0), "world": office},
        _row("nearest", 0, 100.0, 1.0),
    ]
    rows += [{**r, **SLAM_FIGURES} for r in rows]
    lines = slam_vs_perfect_lines(rows, "semantic")
    body = [ln.split(" | ")[:2] for ln in lines if ln.startswith("| ") and "pairs" not in ln]
    assert body[:3] == [["| paper mazes", "semantic"], ["| paper mazes", "nearest"], ["| office", "semantic"]]  # fmt: skip


@pytest.mark.parametrize(
    ("rows", "says"),
    [
        ([_row("semantic", 0, 100.0, 1.0)], "no perfect-map mission has a SLAM twin (1 perfect"),
        (
            [_row("semantic", 0, 100.0, 1.0), _row("semantic", 0, 100.0, 1.0)],
            "two perfect-map missions of world maze1, policy semantic, seed 0",
        ),
    ],
    ids=["no pair", "twice"],
)
def test_bad_rows_are_one_line(rows: list[dict[str, Any]], says: str) -> None:
    with pytest.raises(ValueError) as e:
        slam_vs_perfect_lines(rows, "semantic")
    assert says in str(e.value) and "\n" not in str(e.value)
