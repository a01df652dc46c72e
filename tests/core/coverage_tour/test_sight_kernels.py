"""The shortcuts of the branch bound's visibility test (core/coverage_tour/sight_kernels.py):
each is a proof on its own (a point in a wall's umbra is blind to the whole rectangle; a sight
table never claims a clear segment that a wall meets), and together they leave the test's
answer exactly what :func:`box_blind` alone gives."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.coverage_tour.branch_kernels import coarse_region
from semexplore_gym.core.coverage_tour.lower_bound import mask_groups
from semexplore_gym.core.coverage_tour.lower_bound_kernels import box_blind, walls_near
from semexplore_gym.core.coverage_tour.sight_kernels import (
    SIGHT_BUCKETS,
    sees_clearly,
    sight_table,
    umbra_planes,
)

TOL = 1e-6


def _segment_gap(p, q, a, b) -> float:
    """Least distance between segments ``p q`` and ``a b`` (0 when they cross)."""
    p, q, a, b = (np.asarray(v, dtype=np.float64) for v in (p, q, a, b))

    def cross(u, v):
        return u[0] * v[1] - u[1] * v[0]

    d1, d2 = cross(q - p, a - p), cross(q - p, b - p)
    d3, d4 = cross(b - a, p - a), cross(b - a, q - a)
    if d1 * d2 < 0 and d3 * d4 < 0:
        return 0.0

    def to_segment(x, u, v):
        e = v - u
        t = np.clip(np.dot(x - u, e) / max(np.dot(e, e), 1e-300), 0.0, 1.0)
        return float(np.hypot(*(u + t * e - x)))

    return min(to_segment(p, a, b), to_segment(q, a, b), to_segment(a, p, q), to_segment(b, p, q))


def _random_walls(rng, n, centre, hair):
    """``n`` walls around ``centre``: axis-aligned ones, slanted ones, one on the point's row
    (along its line) and, with ``hair``, one half a millimetre from the point."""
    walls = []
    for _ in range(n):
        x, y = centre + rng.uniform(-3, 3, 2)
        length = rng.uniform(0.2, 3.0)
        if rng.random() < 0.6:
            horizontal = rng.random() < 0.5
            walls.append([x, y, x + length, y] if horizontal else [x, y, x, y + length])
        else:
            a = rng.uniform(0, 2 * math.pi)
            walls.append([x, y, x + length * math.cos(a), y + length * math.sin(a)])
    cx, cy = centre
    walls.append([cx + 1.0, cy, cx + 2.0, cy])  # on the point's row, ahead of it
    if hair:
        walls.append([cx - 1.0, cy + 5e-4, cx + 1.0, cy + 5e-4])
    return np.array(walls, dtype=np.float64)


def test_a_sight_table_never_exceeds_the_distance_to_a_wall_point_around_its_bucket():
    rng = np.random.default_rng(7)
    step = 2 * math.pi / SIGHT_BUCKETS
    claims = 0
    for trial in range(24):
        centre = rng.uniform(-5, 5, 2)
        walls = _random_walls(rng, 12, centre, hair=trial % 3 == 0)
        near = np.arange(walls.shape[0], dtype=np.int64)
        table = np.empty(SIGHT_BUCKETS)
        sight_table(walls, near, near.size, centre[0], centre[1], table)
        for x0, y0, x1, y1 in walls:
            t = rng.uniform(0, 1, 400)
            px, py = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
            dist = np.hypot(px - centre[0], py - centre[1])
            b = np.floor(np.arctan2(py - centre[1], px - centre[0]) / step).astype(int)
            for off in (-1, 0, 1):  # a bucket's entry covers its neighbours' walls too
                assert np.all(table[(b + off) % SIGHT_BUCKETS] <= dist + 1e-12)
        # a clear sight it claims is clear
        for _ in range(300):
            p = centre + rng.uniform(-3.5, 3.5, 2)
            if sees_clearly(table, centre[0], centre[1], p[0], p[1], 3.5, 4 * TOL):
                claims += 1
                assert min(_segment_gap(centre, p, w[:2], w[2:]) for w in walls) > TOL
    assert claims > 500  # and it claims many (a table of zeros would pass the rest)


def test_every_point_in_a_walls_umbra_is_blind_to_every_point_of_the_rectangle():
    rng = np.random.default_rng(11)
    planes = np.empty((9, 3))
    found = 0
    for _ in range(200):
        walls = np.array([[*rng.uniform(-1, 1, 2), *rng.uniform(-1, 1, 2)]])
        x0, y0 = rng.uniform(-2, 2, 2)
        rect = np.array([x0, y0, x0 + rng.uniform(0.05, 0.5), y0 + rng.uniform(0.05, 0.5)])
        if not umbra_planes(walls, 0, rect, TOL, planes):
            continue
        pts = rng.uniform(-4, 4, (400, 2))
        inside = np.all(pts @ planes[:, :2].T + planes[:, 2] > 0, axis=1)
        for p in pts[inside][:20]:
            found += 1
            for _ in range(10):
                q = rng.uniform(rect[:2], rect[2:])
                assert _segment_gap(p, q, walls[0, :2], walls[0, 2:]) == 0.0
    assert found > 100


@pytest.mark.parametrize("spec", ["maze:seed=1,size_m=5", "office:seed=2,size_m=10"])
def test_the_shortcuts_leave_the_region_exactly_what_box_blind_alone_gives(spec, bound_problem):
    """The region by definition: every block within reach that ``box_blind`` cannot prove
    blind. Umbras (then the exact single-wall test) and sight tables must change nothing."""
    facts, allowed, prob = bound_problem(spec, 3, 2, 8)
    geo = facts.geometry
    frame = np.array(
        [geo.origin_x_m, geo.origin_y_m, geo.resolution_m, prob.reach_m, 1e-6, TOL, 3, 10**6]
    )
    rects, _, _ = mask_groups(facts.reachable_mask, geo, 2)
    f, reach = 2, prob.reach_m
    h, w = -(-allowed.shape[0] // f), -(-allowed.shape[1] // f)
    work = np.empty((6, 4))
    kept = blind = 0
    for g in range(0, rects.shape[0], max(1, rects.shape[0] // 12)):
        rect = rects[g]
        near, m = walls_near(prob.walls, rect, reach + 1e-6)
        expected = []
        for r in range(h):
            for c in range(w):
                rows, cols = np.nonzero(allowed[r * f : r * f + f, c * f : c * f + f])
                if rows.size == 0:
                    continue
                x0 = geo.origin_x_m + (c * f + cols.min()) * geo.resolution_m - 1e-6
                x1 = geo.origin_x_m + (c * f + cols.max() + 1) * geo.resolution_m + 1e-6
                y0 = geo.origin_y_m + (r * f + rows.min()) * geo.resolution_m - 1e-6
                y1 = geo.origin_y_m + (r * f + rows.max() + 1) * geo.resolution_m + 1e-6
                gap_x = max(0.0, rect[0] - x1, x0 - rect[2])
                gap_y = max(0.0, rect[1] - y1, y0 - rect[3])
                if gap_x**2 + gap_y**2 > reach**2:
                    continue
                box = (x0, y0, x1, y1)
                if box_blind(prob.walls, near, m, 0, rect, box, reach, 3, TOL, work, prob.corners)[
                    0
                ]:
                    blind += 1
                else:
                    expected.append(r * w + c)
        ours = coarse_region(allowed, f, rect, prob.walls, frame, prob.corners)
        assert ours.tolist() == expected
        kept += len(expected)
    assert kept > 0 and blind > 0  # both answers occur: the comparison means something
