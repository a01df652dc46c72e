"""Rays against robot discs, and merging robots' occupancy grids."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.mapping.disc_cast import cast_discs
from semexplore_gym.core.mapping.map_merge import merge_grids
from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid


def test_cast_discs_against_geometry() -> None:
    th = np.deg2rad(np.arange(360.0))
    d = cast_discs(0.0, 0.0, np.cos(th), np.sin(th), [[1.0, 0.0], [0.0, -2.0]], 0.1)
    assert d[0] == pytest.approx(0.9)
    assert d[270] == pytest.approx(1.9)
    assert math.isinf(d[90]) and math.isinf(d[180])
    # A ray at angle a meets the disc of radius r at distance c at along - sqrt(r^2 - miss^2).
    a = math.radians(3.0)
    assert d[3] == pytest.approx(math.cos(a) - math.sqrt(0.01 - math.sin(a) ** 2))
    # The nearer disc wins.
    d2 = cast_discs(0.0, 0.0, np.ones(1), np.zeros(1), [[2.0, 0.0], [1.0, 0.0]], 0.1)
    assert d2[0] == pytest.approx(0.9)


def test_merge_grids_keeps_the_more_certain_cell() -> None:
    g = GridGeometry(origin_x_m=0.0, origin_y_m=0.0, resolution_m=0.1, height=20, width=20)
    a, b = OccupancyGrid(g), OccupancyGrid(g)
    beams = np.array([0.0])
    a.integrate_scan(0.05, 0.55, 0.0, beams, np.array([1.0]), 3.0)  # free row, wall at x=1.05
    b.integrate_scan(0.05, 1.55, 0.0, beams, np.array([0.5]), 3.0)
    merge_grids([a, b])
    assert np.array_equal(a.encoded, b.encoded)
    assert a.encoded[5, 3] == FREE and a.encoded[15, 3] == FREE
    assert a.encoded[5, 10] == OCCUPIED and a.encoded[15, 5] == OCCUPIED
    assert a.encoded[10, 3] == UNKNOWN
    assert a.n_free_cells == int((a.encoded == FREE).sum()) == b.n_free_cells
    before = a.encoded.copy()
    merge_grids([a, b])  # merging again changes nothing
    assert np.array_equal(a.encoded, before)


@pytest.mark.parametrize("map_hits", [False, True])
def test_fused_scan_with_discs_matches_the_separate_steps(map_hits: bool) -> None:
    from semexplore_gym.core.mapping.disc_cast import DiscObstacles
    from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan
    from semexplore_gym.core.mapping.scan_fusion import ScanFootprint, ScanFuser

    segs = np.array([(0, 0, 4, 0), (4, 0, 4, 3), (4, 3, 0, 3), (0, 3, 0, 0)], dtype=float)
    index = SegmentIndex(segs)
    g = GridGeometry(origin_x_m=-0.5, origin_y_m=-0.5, resolution_m=0.05, height=80, width=100)
    beams = np.arange(360) * (2 * np.pi / 360)
    max_r, min_r, radius = 3.5, 0.12, 0.105
    # One disc in sight, one beyond range + radius (it must not clip no-return beams).
    centres = np.array([[2.0, 1.6], [-3.0, -3.0]])
    sensor, est = (1.0, 1.2, 0.3), (1.02, 1.19, 0.31)
    rng = np.random.default_rng(0)
    noise, dropped = rng.normal(0, 0.01, 360), rng.random(360) < 0.05

    # The reference: walls, then discs, the sensor's post-processing, then the map update.
    ref = OccupancyGrid(g)
    ranges = cast_scan(index, *sensor, beams, max_r)
    th = beams + sensor[2]
    disc = cast_discs(sensor[0], sensor[1], np.cos(th), np.sin(th), centres[:1], radius)
    hit = disc < ranges
    ranges = np.where(hit, disc, ranges)
    ranges = np.where(np.isfinite(ranges), ranges + noise, ranges)
    np.minimum(ranges, max_r, out=ranges)
    ranges[(ranges < min_r) | dropped] = 0.0
    scan_ref = ranges.astype(np.float32)
    map_ranges = scan_ref.astype(np.float64)
    if not map_hits:
        map_ranges[hit] = 0.0
    ref.integrate_scan(*est, beams, map_ranges, max_r)
    touched_ref = ref._stamp == ref._scan_id

    grid = OccupancyGrid(g)
    bits = np.zeros(g.shape, dtype=np.uint8)
    fuser = ScanFuser(index, beams, max_r, min_r)
    scan = fuser.scan_and_integrate(
        grid,
        sensor,
        est,
        noise,
        dropped,
        DiscObstacles(centres, radius, map_hits),
        ScanFootprint(bits, 2),
    )
    assert hit.any() and np.array_equal(scan, scan_ref)
    assert np.array_equal(grid.encoded, ref.encoded) and grid.n_free_cells == ref.n_free_cells
    assert np.array_equal(bits, touched_ref.astype(np.uint8) << 2)
