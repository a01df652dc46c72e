"""The numba ray caster agrees with pymunk's ``segment_query_first`` on radius-0 walls."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_rays

pymunk = pytest.importorskip("pymunk")

SHARED = Path(__file__).resolve().parents[2] / ".." / "shared"
TOL_M = 1e-6


def pymunk_rays(
    segments_m: np.ndarray, x: float, y: float, angles: np.ndarray, max_range_m: float
) -> np.ndarray:
    space = pymunk.Space()
    space.add(
        *[pymunk.Segment(space.static_body, (a, b), (c, d), 0.0) for a, b, c, d in segments_m]
    )
    flt = pymunk.ShapeFilter()
    out = np.full(len(angles), np.inf)
    for j, th in enumerate(angles):
        end = (x + max_range_m * math.cos(th), y + max_range_m * math.sin(th))
        hit = space.segment_query_first((x, y), end, 0.0, flt)
        if hit is not None:
            out[j] = hit.alpha * max_range_m
    return out


def assert_same(ours: np.ndarray, ref: np.ndarray) -> None:
    miss = np.isinf(ref)
    assert np.array_equal(np.isinf(ours), miss), (
        f"hit/miss differs at beams {np.flatnonzero(np.isinf(ours) != miss)}"
    )
    np.testing.assert_allclose(ours[~miss], ref[~miss], rtol=0, atol=TOL_M)


@pytest.mark.parametrize("seed", range(6))
def test_random_worlds_and_poses(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 400))
    size_m = rng.uniform(2.0, 30.0)
    start = rng.uniform(0, size_m, (n, 2))
    length = rng.uniform(0.02, 6.0, n)
    heading = rng.uniform(0, 2 * np.pi, n)
    segs = np.c_[start, start + np.c_[length * np.cos(heading), length * np.sin(heading)]]
    segs[: n // 3, 3] = segs[: n // 3, 1]  # some axis-aligned walls, as in real maps
    segs[n // 3 : n // 2, 2] = segs[n // 3 : n // 2, 0]
    index = SegmentIndex(segs)
    for _ in range(8):
        x, y = rng.uniform(-1.0, size_m + 1.0, 2)
        max_range = rng.uniform(0.3, 12.0)
        angles = np.r_[
            np.arange(360) * (2 * np.pi / 360) + rng.uniform(-np.pi, np.pi), rng.uniform(-7, 7, 40)
        ]
        assert_same(
            cast_rays(index, x, y, angles, max_range), pymunk_rays(segs, x, y, angles, max_range)
        )


def test_maze_corners_and_end_points() -> None:
    """Grid-aligned maze walls seen from cell centres: rays through shared end points."""
    segs = []
    for i in range(5):
        for j in range(5):
            if (i + j) % 2 == 0:
                segs.append((i * 2.0, j * 2.0, i * 2.0 + 2.0, j * 2.0))
            else:
                segs.append((i * 2.0, j * 2.0, i * 2.0, j * 2.0 + 2.0))
    segs_m = np.array(segs)
    index = SegmentIndex(segs_m)
    angles = np.arange(360) * (2 * np.pi / 360)
    for x, y in [(1.0, 1.0), (3.0, 5.0), (5.0, 5.0), (7.0, 3.0)]:
        assert_same(cast_rays(index, x, y, angles, 6.0), pymunk_rays(segs_m, x, y, angles, 6.0))


@pytest.mark.shared_maps
def test_houseexpo_floor_plan() -> None:
    path = SHARED / "maps" / "houseexpo" / "json" / "house_expo_room_1451.json"
    if not path.exists():
        pytest.skip(f"shared maps not found at {path}")
    verts = np.asarray(json.loads(path.read_text())["verts"], dtype=np.float64)
    segs = np.c_[verts, np.roll(verts, -1, axis=0)]
    index = SegmentIndex(segs)
    rng = np.random.default_rng(0)
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    angles = np.arange(360) * (2 * np.pi / 360)
    for _ in range(10):
        x, y = rng.uniform(lo, hi)
        assert_same(cast_rays(index, x, y, angles, 3.5), pymunk_rays(segs, x, y, angles, 3.5))
