"""One finished mission as a row of ``runs.csv``: the columns, typed, and their parsing.

:class:`RunRow` is the schema: its fields are the CSV columns, in order. ``scored_replans`` and
``semantic_share`` are policy-specific (a policy's ``mission_metrics()``; empty for most
policies); ``coverage_at_planner_clearance`` is the coverage of the cells reachable at the
semantic expert's planning clearance (:mod:`.planner_coverage`; every policy); the path
decomposition's columns (:mod:`.path_decomposition`: the path split into parts that add up to
``path_length_m``, goals cleared and abandoned, the goals' detour ratio) come for every policy;
``policy_version`` names the semantic expert's version a spec ran (``semantic-v3`` for
``semantic``; empty for policies without versions). The SLAM columns (:data:`SLAM_COLUMNS`:
trajectory errors of SLAM and of odometry alone, map error, loop closures, whether the back end
ended lost, and whether the policy stopped short on a SLAM artefact) come only from
missions in the env's SLAM mode (``--env-config slam``; empty otherwise). All of these were
added after the first release, so older files may lack them.
"""

from __future__ import annotations

import csv
import io
import math
import os
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from semexplore_gym.core.validation import short_repr
from semexplore_gym.evaluation.path_decomposition import DECOMPOSITION_COLUMNS


@dataclass(frozen=True)
class RunRow:
    """The figures of one mission, as written to ``runs.csv`` (None: an empty cell)."""

    world: str
    policy: str
    seed: int
    mission_time_s: float
    coverage: float
    self_stopped: bool
    stop_reason: str
    path_length_m: float
    collisions: int
    T90_s: float | None
    T99_s: float | None
    mean_map_generation_ms: float
    mean_global_planning_ms: float
    wall_time_s: float
    explored_area_m2: float
    steps: int
    scored_replans: int | None = None
    semantic_share: float | None = None
    coverage_at_planner_clearance: float | None = None
    path_to_cleared_goals_m: float | None = None
    path_to_abandoned_goals_m: float | None = None
    path_looks_recoveries_m: float | None = None
    path_without_goal_m: float | None = None
    path_after_last_new_cell_m: float | None = None
    goals_cleared: int | None = None
    goals_abandoned: int | None = None
    median_goal_detour_ratio: float | None = None
    goal_detour_excess_m: float | None = None
    policy_version: str | None = None
    ate_m: float | None = None
    rpe_m: float | None = None
    map_error: float | None = None
    loop_closures: int | None = None
    slam_lost: bool | None = None
    slam_lost_events: int | None = None
    slam_degenerate_matches: int | None = None
    odom_ate_m: float | None = None
    slam_false_stop: bool | None = None
    slam_stop_artefact: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """Column -> value, in column order."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def from_csv(cls, raw: dict[str, Any], where: str) -> RunRow:
        """Parse the cells of one ``csv.DictReader`` row; ``where`` names it in errors.

        Raises:
            ValueError: a missing cell, or a cell that is not of its column's type.
        """
        return cls(**parse_cells(raw, where))


#: The columns of ``runs.csv``, in order.
CSV_COLUMNS: tuple[str, ...] = tuple(f.name for f in fields(RunRow))

#: Policy-specific columns: the policy's ``mission_metrics()`` fills them (None if absent).
POLICY_COLUMNS: tuple[str, ...] = ("scored_replans", "semantic_share")

#: The SLAM mode's columns (:meth:`~semexplore_gym.envs.slam_mode.SlamMode.metrics`; empty
#: for missions on the perfect or odometry-only map).
SLAM_COLUMNS: tuple[str, ...] = (
    "ate_m",
    "rpe_m",
    "map_error",
    "loop_closures",
    "slam_lost",
    "slam_lost_events",
    "slam_degenerate_matches",
    "odom_ate_m",
    "slam_false_stop",
    "slam_stop_artefact",
)

#: Columns added after the first release: rows of older ``runs.csv`` files lack them (None).
OPTIONAL_COLUMNS: frozenset[str] = frozenset(
    {
        *POLICY_COLUMNS,
        "coverage_at_planner_clearance",
        *DECOMPOSITION_COLUMNS,
        "policy_version",
        *SLAM_COLUMNS,
    }
)

_TEXT_COLUMNS = ("world", "policy", "stop_reason", "policy_version", "slam_stop_artefact")
_INT_COLUMNS = (
    "seed",
    "collisions",
    "steps",
    "scored_replans",
    "goals_cleared",
    "goals_abandoned",
    "loop_closures",
    "slam_lost_events",
    "slam_degenerate_matches",
)
_BOOL_COLUMNS = ("self_stopped", "slam_lost", "slam_false_stop")


def parse_cells(raw: dict[str, Any], where: str) -> dict[str, Any]:
    """The cells of one CSV row with numbers parsed (empty cells become None)."""
    if None in raw or any(raw.get(k) is None for k in CSV_COLUMNS if k not in OPTIONAL_COLUMNS):
        raise ValueError(f"{where}: expected {len(CSV_COLUMNS)} cells")
    row: dict[str, Any] = {}
    for k, v in raw.items():
        if k in _TEXT_COLUMNS:
            row[k] = None if k in OPTIONAL_COLUMNS and k in SLAM_COLUMNS and v == "" else v
        elif k in _BOOL_COLUMNS and not (k in OPTIONAL_COLUMNS and v in ("", "None")):
            if v not in ("True", "False"):
                raise ValueError(f"{where}: {k} must be True or False, got {short_repr(v)}")
            row[k] = v == "True"
        elif v in ("", "None"):
            if k in ("world", "policy", "seed"):
                raise ValueError(f"{where}: empty {k}")
            row[k] = None
        else:
            try:
                row[k] = _count(v) if k in _INT_COLUMNS else float(v)
            except ValueError:
                raise ValueError(f"{where}: {k} is not a number: {short_repr(v)}") from None
    return row


def _count(v: str) -> int:
    """An integer cell; ``"3.0"`` (a whole number written as a float) reads as 3."""
    try:
        return int(v)
    except ValueError:
        f = float(v)
        if not f.is_integer():
            raise
        return int(f)


def complete_csv_bytes(path: Path) -> int:
    """Length of ``path`` up to its last newline: a row cut by a kill has no newline yet."""
    data = path.read_bytes()
    return data.rfind(b"\n") + 1


def read_runs(path: str | os.PathLike) -> list[dict[str, Any]]:
    """Rows of a ``runs.csv`` with numbers parsed (empty cells become None).

    A last line without its newline (the process was killed while writing it) is not a
    finished mission and is ignored; any other malformed row raises a ValueError naming it.
    """
    p = Path(path)
    if not p.exists():
        return []
    text = p.read_bytes()[: complete_csv_bytes(p)].decode("utf-8", errors="replace")
    reader = csv.DictReader(io.StringIO(text, newline=""))
    return [parse_cells(raw, f"{p} line {i}") for i, raw in enumerate(reader, start=2)]


def finite_or_none(v: Any) -> float | None:
    """``v`` as a finite float, or None (not a number, inf or nan)."""
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None
