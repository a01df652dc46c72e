"""Every reachable frontier (the frontier student's options) and their features."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.features.frontier_option_features import (
    OPTION_FEATURE_NAMES,
    frontier_option_features,
)
from semexplore_gym.core.frontiers.options import reachable_frontier_options
from semexplore_gym.core.frontiers.reachable import (
    FrontierFilter,
    clearance_field_m,
    nearest_reachable_frontier,
)
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, parse_ascii_grid

# 0.1 m cells. A corridor with unknown at both ends (left end near, right end far) and a
# side slot too narrow for the robot at the top.
MAP = """
#####.##################
?......................?
?......................?
?......................?
?......................?
?......................?
########################
"""


def _options(grid, geom, start, **filt):
    return reachable_frontier_options(
        grid, geom, start, clearance_m=0.2, frontiers=FrontierFilter(**filt)
    )


def test_every_reachable_frontier_is_an_option_nearest_first():
    grid = parse_ascii_grid(MAP)
    geom = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    start = (0.55, 0.45)  # row 5, col 4: near the left end
    opts = _options(grid, geom, start, min_frontier_cells=3, reach_m=0.0)
    # The two corridor ends; the top slot is a frontier of one cell (filtered) too narrow anyway.
    assert len(opts) == 2
    assert opts.path_cost_m[0] < opts.path_cost_m[1]
    cols = [int(geom.world_to_grid(*g)[1]) for g in opts.goal_xy_m]
    assert cols == [1, 22]
    assert [len(c) for c in opts.frontier_cells] == [5, 5]
    dist = clearance_field_m(grid, 0.1)
    for i in range(len(opts)):
        path = opts.path_m(i)
        np.testing.assert_allclose(path[0], start)
        np.testing.assert_allclose(path[-1], opts.goal_xy_m[i])
        r, c = geom.world_to_grid(path[1:, 0], path[1:, 1])
        assert (dist[r, c] >= 0.2 - 1e-9).all()
        length = float(np.hypot(*np.diff(path[1:], axis=0).T).sum())
        assert length <= opts.path_cost_m[i] + 1e-9  # the cost adds the wall penalty
    # The nearest option is the grid fallback's goal (or a cell beside it).
    near = nearest_reachable_frontier(grid, geom, start, 0.2, FrontierFilter(3, reach_m=0.0))
    assert near is not None
    assert math.dist(near.goal_xy_m, opts.goal_xy_m[0]) <= 0.1 * math.sqrt(2) + 1e-9


def test_filters_drop_options():
    grid = parse_ascii_grid(MAP)
    geom = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    start = (0.55, 0.45)
    left = (0.3, 0.1)  # the left end's frontier, blacklisted
    opts = _options(grid, geom, start, reach_m=0.0, excluded_xy_m=[left], excluded_radius_m=0.5)
    assert len(opts) == 1 and int(geom.world_to_grid(*opts.goal_xy_m[0])[1]) == 22
    assert len(_options(grid, geom, start, min_frontier_cells=6)) == 0
    known = np.where(grid == UNKNOWN, np.uint8(OCCUPIED), grid)
    assert len(_options(known, geom, start)) == 0
    with pytest.raises(ValueError, match="clearance_m"):
        reachable_frontier_options(grid, geom, start, clearance_m=-1.0)
    with pytest.raises(ValueError, match="shape"):
        reachable_frontier_options(grid[:3], geom, start, clearance_m=0.2)


def test_options_on_random_maps_match_the_fallback_nearest():
    """On random maps the cheapest option is the grid fallback's goal or a cell beside it,
    and every option's goal is a usable cell its own path reaches."""
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(30):
        h, w = (int(v) for v in rng.integers(40, 90, 2))
        coarse = rng.choice([FREE, OCCUPIED, UNKNOWN], size=(h // 4, w // 4), p=[0.7, 0.1, 0.2])
        grid = np.kron(coarse, np.ones((4, 4), dtype=np.uint8)).astype(np.uint8)
        geom = GridGeometry(0.05, 0.0, 0.0, *grid.shape)
        free = np.argwhere(grid == FREE)
        r, c = free[int(rng.integers(len(free)))]
        start = tuple(float(v) for v in geom.grid_to_world(r, c))
        filt = FrontierFilter(2, reach_m=0.1)
        opts = reachable_frontier_options(grid, geom, start, 0.1, filt)
        near = nearest_reachable_frontier(grid, geom, start, 0.1, filt)
        assert (near is None) == (len(opts) == 0)
        if near is None:
            continue
        checked += 1
        assert math.dist(near.goal_xy_m, opts.goal_xy_m[0]) <= 0.05 * 1.5
        assert np.all(np.diff(opts.path_cost_m) >= 0)
        for i in range(len(opts)):
            np.testing.assert_allclose(opts.path_m(i)[-1], opts.goal_xy_m[i])
    assert checked >= 10


def test_features_read_the_options():
    grid = parse_ascii_grid(MAP)
    geom = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    opts = _options(grid, geom, (0.55, 0.45), reach_m=0.0)
    far_goal = tuple(opts.goal_xy_m[1])
    feats = frontier_option_features(grid, geom, (0.55, 0.45, 0.0), opts, far_goal, 0.5)
    col = {n: feats[:, i] for i, n in enumerate(OPTION_FEATURE_NAMES)}
    assert feats.shape == (2, len(OPTION_FEATURE_NAMES))
    np.testing.assert_allclose(col["path_m"], opts.path_cost_m)
    assert col["extra_path_m"][0] == 0.0 and col["extra_path_m"][1] > 1.5
    assert list(col["nearest"]) == [1.0, 0.0] and list(col["current"]) == [0.0, 1.0]
    # Facing +x: the right end straight ahead, the left end behind.
    assert col["turn_rad"][1] < 0.3 and col["turn_rad"][0] > 2.5
    np.testing.assert_allclose(col["frontier_m"], [0.5, 0.5])
    assert np.all(col["isolation_m"] > 1.5)
    none = frontier_option_features(grid, geom, (0.55, 0.45, 0.0), opts)
    assert not none[:, OPTION_FEATURE_NAMES.index("current")].any()
