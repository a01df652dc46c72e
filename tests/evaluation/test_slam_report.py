"""summary.md's SLAM table: SLAM's ATE beside odometry's, their ratio, and the false stops."""

from __future__ import annotations

from semexplore_gym.evaluation.slam_report import slam_table


def _row(ate: float, odom: float, false_stop: bool, artefact: str | None = None) -> dict:
    return {
        "ate_m": ate,
        "odom_ate_m": odom,
        "rpe_m": 0.01,
        "map_error": 0.05,
        "loop_closures": 2,
        "slam_degenerate_matches": 0,
        "slam_lost": False,
        "slam_lost_events": 0,
        "slam_false_stop": false_stop,
        "slam_stop_artefact": artefact,
    }


def test_the_table_gives_odometrys_ate_the_ratio_and_the_false_stops() -> None:
    rows = [
        _row(0.02, 0.40, False),
        _row(0.04, 0.20, True, "lost_frontier"),
        _row(0.03, 0.30, True, "ghost_frontier"),
        _row(0.05, 0.50, True, "lost_frontier"),
    ]
    lines = slam_table({"maze": {"semantic": rows}})
    head = next(line for line in lines if line.startswith("| family"))
    assert "odometry ATE (m)" in head and "odometry ÷ SLAM ATE" in head
    assert head.endswith("| lost | false stops |")
    (body,) = [line for line in lines if line.startswith("| maze | semantic | 4 |")]
    cells = [c.strip() for c in body.strip("|").split("|")]
    assert cells[3].startswith("0.035 ")  # ATE median
    assert cells[4].startswith("0.350 ")  # odometry ATE median
    assert cells[5].startswith("10.0 ")  # median of 20, 5, 10, 10
    assert cells[-1] == "3/4 (1 ghost_frontier, 2 lost_frontier)"


def test_a_table_without_false_stops_says_none_of_n() -> None:
    lines = slam_table({"office": {"nearest": [_row(0.02, 0.1, False)]}})
    (body,) = [line for line in lines if line.startswith("| office |")]
    assert body.endswith("| 0/1 | 0/1 |")


def test_lost_is_a_dash_when_no_row_says() -> None:
    """A runs.csv trimmed without the lost columns shows no count, rather than 0 lost."""
    rows = [_row(0.02, 0.40, False), _row(0.04, 0.20, False)]
    for r in rows:
        r["slam_lost"] = r["slam_lost_events"] = None
    (body,) = [ln for ln in slam_table({"maze": {"semantic": rows}}) if ln.startswith("| maze |")]
    assert body.endswith("| – | 0/2 |")
    rows[1]["slam_lost_events"] = 2
    (body,) = [ln for ln in slam_table({"maze": {"semantic": rows}}) if ln.startswith("| maze |")]
    assert body.endswith("| 1/2 | 0/2 |")
