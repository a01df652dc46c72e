"""The team settings of ``SemanticExploreMulti-v0`` (the rest is the single-robot :class:`EnvConfig`)."""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from semexplore_gym.config import build_params

#: Largest team: the env steps every robot in one space and one map.
MAX_ROBOTS = 8
START_MODES = ("near", "spread")
MAP_SHARING_MODES = ("team", "range")


@dataclass(frozen=True)
class TeamParams:
    """How many robots, where they start, how they share their maps and rewards.

    Attributes:
        n_robots: Team size, 1 to 8.
        start: ``"near"`` (default, the common field setting): robot 0 starts where the
            single-robot env would start, the others at free poses sampled within
            ``start_spread_m`` of it; ``"spread"``: every teammate at a pose sampled uniformly
            in the free space robot 0 can reach.
        start_spread_m: Largest distance of a ``"near"`` teammate's start from robot 0's.
        start_gap_m: Smallest free gap between two robots' discs at the start.
        map_sharing: ``"team"`` (default): one occupancy grid fed by every robot's scans
            (relative start poses known, maps shared at once). ``"range"``: each robot maps
            alone; robots within ``comm_range_m`` of each other (chains of them included)
            merge their maps after every step (cell by cell, the more certain log-odds wins,
            :func:`~semexplore_gym.core.mapping.map_merge.merge_grids`). A small range, e.g.
            1 m, is "merge when they meet". Coverage and the end of the episode are measured
            on the union of all scans either way.
        comm_range_m: Communication range of ``"range"`` map sharing, metres.
        map_teammates: Fuse LiDAR returns from teammates as obstacles. False (default): beams
            ending on a teammate are left out of the map; the scans in the observations show
            teammates either way.
        team_reward_weight: Weight of the ``team`` reward term, the free area the *other*
            robots added to the team map this step (m^2): 1 makes every robot's reward the
            team's whole gain; 0 leaves only its own.
        end_on_coverage: End the episode (terminate every agent) at
            ``episode.coverage_goal``. False: only the time limit ends it, so that a team
            policy's own stop can be measured (``--env-set team.end_on_coverage=false`` in
            ``semexplore benchmark --robots``).
    """

    n_robots: int = 2
    start: str = "near"
    start_spread_m: float = 1.0
    start_gap_m: float = 0.1
    map_sharing: str = "team"
    comm_range_m: float = 3.0
    map_teammates: bool = False
    team_reward_weight: float = 1.0
    end_on_coverage: bool = True

    def __post_init__(self) -> None:
        if isinstance(self.n_robots, bool) or not 1 <= int(self.n_robots) <= MAX_ROBOTS:
            raise ValueError(f"team.n_robots must be in 1..{MAX_ROBOTS}, got {self.n_robots!r}")
        if self.start not in START_MODES:
            raise ValueError(f"team.start must be one of {START_MODES}, got {self.start!r}")
        if self.map_sharing not in MAP_SHARING_MODES:
            raise ValueError(
                f"team.map_sharing must be one of {MAP_SHARING_MODES}, got {self.map_sharing!r}"
            )
        for name in ("start_spread_m", "start_gap_m", "comm_range_m"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"team.{name} must be a finite distance >= 0, got {v!r}")
        if not math.isfinite(self.team_reward_weight) or abs(self.team_reward_weight) > 1e6:
            raise ValueError(
                f"team.team_reward_weight must be finite, got {self.team_reward_weight!r}"
            )


def split_team_overrides(overrides: Iterable[str] | None) -> tuple[list[str], list[str]]:
    """``(team overrides without the "team." prefix, the env's overrides)``."""
    team: list[str] = []
    env: list[str] = []
    for text in overrides or ():
        if text.strip().startswith("team."):
            team.append(text.strip()[len("team.") :])
        else:
            env.append(text)
    return team, env


def load_team_params(
    team: TeamParams | str | os.PathLike | Mapping[str, Any] | None = None,
    overrides: Iterable[str] = (),
) -> TeamParams:
    """Resolve the team settings (None, a YAML path, a mapping or TeamParams) plus ``key=value``
    overrides, through the project's one config path."""
    return build_params(TeamParams, team, overrides=overrides)
