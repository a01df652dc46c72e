"""Features of the learned frontier value (``core/features/frontier_features.py``)."""

from __future__ import annotations

import numpy as np
import pytest

from semexplore_gym.core.features.frontier_features import (
    FEATURE_NAMES,
    frontier_value_features,
    unknown_fraction_near,
)
from semexplore_gym.core.grid import FREE, UNKNOWN, GridGeometry

GEO = GridGeometry(resolution_m=0.1, width=40, height=40, origin_x_m=0.0, origin_y_m=0.0)


def _half_known() -> np.ndarray:
    """Columns 0-19 (x < 2 m) free, the rest unknown."""
    grid = np.full((40, 40), UNKNOWN, dtype=np.uint8)
    grid[:, :20] = FREE
    return grid


def test_unknown_fraction_counts_the_disc_and_the_map_edge() -> None:
    grid = _half_known()
    assert unknown_fraction_near(grid, GEO, (0.95, 2.0), 0.5) == 0.0
    assert unknown_fraction_near(grid, GEO, (3.05, 2.0), 0.5) == 1.0
    on_edge = unknown_fraction_near(grid, GEO, (2.0, 2.0), 0.5)
    assert 0.35 < on_edge < 0.65
    # Beyond the map's edge nothing is known: a free corner is partly "unknown".
    grid[:] = FREE
    corner = unknown_fraction_near(grid, GEO, (0.05, 0.05), 0.5)
    assert 0.6 < corner < 0.8


def test_feature_rows_path_isolation_spread_and_detour() -> None:
    grid = _half_known()
    goals = [(1.0, 1.0), (1.0, 1.5), (3.5, 3.5)]
    paths = [2.0, 2.0, 6.0]
    feats = frontier_value_features(grid, GEO, (0.5, 1.0), goals, paths, unknown_radius_m=0.3)
    assert feats.shape == (3, len(FEATURE_NAMES))
    col = {n: i for i, n in enumerate(FEATURE_NAMES)}
    np.testing.assert_allclose(feats[:, col["path_m"]], paths)
    assert feats[0, col["unknown_frac"]] == 0.0 and feats[2, col["unknown_frac"]] == 1.0
    np.testing.assert_allclose(feats[:2, col["isolation_m"]], [0.5, 0.5])
    assert feats[2, col["isolation_m"]] == pytest.approx(np.hypot(2.5, 2.0))
    # The far goal is the one away from the others' centroid.
    assert feats[2, col["spread_m"]] > feats[0, col["spread_m"]]
    # Goal 0 is 0.5 m away in a straight line but 2 m along its path.
    assert feats[0, col["detour"]] == pytest.approx(2.0 / 0.5 - 1.0)


def test_a_lone_candidate_has_no_isolation_or_spread_and_lengths_must_match() -> None:
    feats = frontier_value_features(_half_known(), GEO, (0.5, 0.5), [(1.0, 1.0)], [1.0])
    assert feats[0, FEATURE_NAMES.index("isolation_m")] == 0.0
    assert feats[0, FEATURE_NAMES.index("spread_m")] == 0.0
    assert frontier_value_features(_half_known(), GEO, (0.5, 0.5), [], []).shape == (0, 5)
    with pytest.raises(ValueError, match="path lengths"):
        frontier_value_features(_half_known(), GEO, (0.5, 0.5), [(1.0, 1.0)], [])
