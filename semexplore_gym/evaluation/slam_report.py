"""``summary.md``'s SLAM section: per family and policy, the SLAM mode's figures.

Only missions run in the env's SLAM mode (``--env-config slam``) carry them (``runs.csv``'s
:data:`~semexplore_gym.evaluation.run_row.SLAM_COLUMNS`); without any the section is left out.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: The table's median columns: (runs.csv column, heading, format).
_MEDIAN_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("ate_m", "ATE (m)", "{:.3f}"),
    ("odom_ate_m", "odometry ATE (m)", "{:.3f}"),
    ("odom_ate_ratio", "odometry ÷ SLAM ATE", "{:.1f}"),
    ("rpe_m", "RPE over 1 m (m)", "{:.3f}"),
    ("map_error", "map error", "{:.3f}"),
    ("loop_closures", "loop closures", "{:.0f}"),
    ("slam_degenerate_matches", "degenerate matches", "{:.0f}"),
)


def _median_iqr(rows: list[dict[str, Any]], key: str, fmt: str) -> str:
    v = np.array([float(r[key]) for r in rows if r.get(key) is not None], dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return "–"
    q1, med, q3 = np.percentile(v, [25, 50, 75])
    return f"{fmt.format(med)} [{fmt.format(q1)}–{fmt.format(q3)}]"


def _with_ratio(row: dict[str, Any]) -> dict[str, Any]:
    """``row`` with ``odom_ate_ratio``: odometry ATE ÷ SLAM ATE (None without both)."""
    ate, odom = row.get("ate_m"), row.get("odom_ate_m")
    ratio = odom / ate if ate and odom is not None and ate > 0 else None
    return {**row, "odom_ate_ratio": ratio}


def _false_stops(rows: list[dict[str, Any]]) -> str:
    """``k/n`` missions that stopped short on a SLAM artefact, with the artefacts' counts."""
    kinds = [r.get("slam_stop_artefact") or "?" for r in rows if r.get("slam_false_stop")]
    if not kinds:
        return f"0/{len(rows)}"
    counts = ", ".join(f"{kinds.count(k)} {k}" for k in sorted(set(kinds)))
    return f"{len(kinds)}/{len(rows)} ({counts})"


def _lost(rows: list[dict[str, Any]]) -> str:
    """``k/n`` missions whose back end reported itself lost (``–``: no row says, as in a
    ``runs.csv`` trimmed without the lost columns)."""
    if all(r.get("slam_lost") is None and r.get("slam_lost_events") is None for r in rows):
        return "–"
    lost = sum(1 for r in rows if r.get("slam_lost") or (r.get("slam_lost_events") or 0) > 0)
    return f"{lost}/{len(rows)}"


def slam_table(families: dict[str, dict[str, list[dict[str, Any]]]]) -> list[str]:
    """``summary.md`` lines: per family and policy, median [IQR] of the trajectory errors (of
    SLAM, of odometry alone and their ratio), the map error, the loop closures and the
    degenerate matches, in how many missions the back end reported itself lost, and how many
    stopped short on a SLAM artefact (false stops).

    Args:
        families: ``{family: {policy: [runs.csv rows]}}``.

    Returns:
        The section's lines; none when no row has the SLAM columns.
    """
    slam_rows = {
        (fam, policy): [_with_ratio(r) for r in rs if r.get("ate_m") is not None]
        for fam, by_policy in families.items()
        for policy, rs in by_policy.items()
    }
    if not any(slam_rows.values()):
        return []
    head = " | ".join(label for _, label, _ in _MEDIAN_COLUMNS)
    lines = [
        "## SLAM",
        "",
        "Missions in the env's SLAM mode: the policies saw the map and pose the scan matcher and "
        "pose graph built. ATE: RMSE of the keyframe positions against the true positions there; "
        "odometry ATE: the same for the raw odometry at the same keyframes (and its ratio to "
        "the ATE, per mission); "
        "RPE: RMSE of the error of the keyframes' motion over 1 m of true travel; "
        "map error: share of the SLAM map's known cells whose class differs from the map the "
        "same scans build at the true poses; degenerate matches: scan matches that pinned the "
        "pose only across one direction (a featureless corridor); lost: missions during which "
        "the back end reported itself lost at least once; false stops: missions the policy "
        "ended below the coverage goal where the SLAM map lost a frontier the truth still has "
        "(lost_frontier) or shows one the truth does not (ghost_frontier). Cells: median [IQR].",
        "",
        f"| family | policy | n | {head} | lost | false stops |",
        "|---|---|---:|" + "---:|" * (len(_MEDIAN_COLUMNS) + 2),
    ]
    for (fam, policy), rs in slam_rows.items():
        if not rs:
            continue
        cells = [_median_iqr(rs, key, fmt) for key, _, fmt in _MEDIAN_COLUMNS]
        lines.append(
            f"| {fam} | {policy} | {len(rs)} | "
            + " | ".join(cells)
            + f" | {_lost(rs)} | {_false_stops(rs)} |"
        )
    lines.append("")
    return lines
