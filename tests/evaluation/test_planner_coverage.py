"""Coverage at the planner's clearance (``coverage_at_planner_clearance``) and the env's
coverage clearance as a config value (``episode.coverage_clearance_margin_m``)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.registry import make_policy

import semexplore_gym  # noqa: F401  (registers the env)
from semexplore_gym.config import ConfigError
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.build import world_from_free_mask
from semexplore_gym.envs.coverage_mask import coverage_mask, map_coverage
from semexplore_gym.envs.env_config import load_env_config
from semexplore_gym.evaluation.harness import CSV_COLUMNS, OPTIONAL_COLUMNS, Task, run_task
from semexplore_gym.evaluation.planner_coverage import (
    coverage_at_planner_clearance,
    planner_clearance_margin_m,
)

RES_M = 0.05
# Two 1.5 m rooms joined by a 0.5 m long passage 0.25 m wide: wider than the env's coverage
# clearance needs (2 * (0.105 + 0.01) = 0.23 m), narrower than the expert plans through
# (2 * (0.105 + 0.05) = 0.31 m).
ROOM, PASSAGE_LEN, PASSAGE_W = 30, 10, 5


def _two_rooms():
    h = ROOM + 2
    w = 2 * ROOM + PASSAGE_LEN + 2
    free = np.zeros((h, w), dtype=bool)
    free[1:-1, 1 : 1 + ROOM] = True
    free[1:-1, 1 + ROOM + PASSAGE_LEN : 1 + 2 * ROOM + PASSAGE_LEN] = True
    mid = h // 2
    free[mid - PASSAGE_W // 2 : mid + PASSAGE_W // 2 + 1, 1 + ROOM : 1 + ROOM + PASSAGE_LEN] = True
    world = world_from_free_mask(
        "two-rooms", free, GridGeometry(RES_M, 0.0, 0.0, h, w), start_pose=(0.8, 0.8, 0.0)
    )
    return world, (1 + ROOM) * RES_M  # the x where the passage begins


def _env_with_first_room_seen(overrides: list[str] | None = None):
    """An env on the two rooms whose map shows the first room (up to the passage) free and
    everything else unknown."""
    world, x_passage = _two_rooms()
    env = gym.make("SemanticExplore-v0", world=world, overrides=overrides)
    env.reset(seed=0)
    base = env.unwrapped
    g = base.map_geometry
    xs, _ = g.grid_to_world(0, np.arange(g.width))
    log_odds = np.zeros(g.shape, dtype=np.float32)
    log_odds[:, xs < x_passage] = -5.0  # FREE; the env's coverage counts only reachable cells
    base.grid.load_log_odds(log_odds)
    return env


def test_a_passage_between_the_two_clearances_splits_the_two_coverages() -> None:
    env = _env_with_first_room_seen()
    try:
        base = env.unwrapped
        env_coverage = base.info_numbers()[0]
        expert = make_policy("semantic")
        at_planner = coverage_at_planner_clearance(env, expert)
        # The env counts the second room (reachable through the 0.25 m passage), unseen.
        assert 0.4 < env_coverage < 0.6
        # At the expert's clearance only the first room is reachable, and it is all seen.
        assert at_planner == pytest.approx(1.0)
        # The same function at the env's own margin is the env's coverage.
        own = coverage_mask(base.world, base.map_geometry, base.start_pose[:2], base.config)
        assert np.array_equal(own, base.grid.count_mask)
        assert map_coverage(base.grid.encoded, own) == env_coverage
        # Seeing the second room too completes both.
        base.grid.load_log_odds(np.where(base.grid.count_mask, -5.0, 0.0).astype(np.float32))
        assert base.info_numbers()[0] == 1.0
        assert coverage_at_planner_clearance(env, expert) == 1.0
    finally:
        env.close()


def test_the_env_coverage_clearance_is_a_config_value() -> None:
    assert load_env_config().episode.coverage_clearance_margin_m == 0.01
    # At the expert's clearance as the env's, the second room no longer counts.
    narrow = _env_with_first_room_seen(["episode.coverage_clearance_margin_m=0.05"])
    default = _env_with_first_room_seen()
    try:
        assert narrow.unwrapped.info_numbers()[0] == pytest.approx(1.0)
        n_first_room = narrow.unwrapped.grid.n_mask_cells
        assert default.unwrapped.grid.n_mask_cells > 2 * n_first_room
    finally:
        narrow.close()
        default.close()
    for bad in ("-0.01", "nan", "2"):
        with pytest.raises(ConfigError, match="episode.coverage_clearance_margin_m"):
            load_env_config(overrides=[f"episode.coverage_clearance_margin_m={bad}"])


def test_each_policy_is_measured_at_the_expert_margin_its_own_or_the_default() -> None:
    assert planner_clearance_margin_m(make_policy("semantic")) == 0.05
    assert planner_clearance_margin_m(make_policy("semantic[clearance_margin_m=0.08]")) == 0.08
    assert planner_clearance_margin_m(make_policy("nearest")) == 0.05
    assert planner_clearance_margin_m(make_policy("random")) == 0.05


def test_the_benchmark_row_carries_the_column_for_every_policy() -> None:
    assert "coverage_at_planner_clearance" in CSV_COLUMNS
    assert "coverage_at_planner_clearance" in OPTIONAL_COLUMNS
    for policy in ("nearest", "semantic"):
        row = run_task(Task("maze:seed=1,size_m=4", policy, 0, max_time_s=20.0))["row"]
        value = row["coverage_at_planner_clearance"]
        assert isinstance(value, float) and 0.0 < value <= 1.0
