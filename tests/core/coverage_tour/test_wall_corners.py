"""Corners in the certified bound's visibility proof (``LowerBoundParams.wall_corners``, on):
two walls that end at one shared point block, together, every segment that leaves the sector
between them. The proof rests on the env's ray cast counting a beam through the shared point
as a hit; these tests hold that, the proof's own cases, and the bound with corners on
hand-made worlds whose drives are known."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.coverage_tour.bound_geometry import merge_walls, wall_corners
from semexplore_gym.core.coverage_tour.lower_bound_kernels import (
    corner_blocks,
    rect_blind,
    wall_blocks,
)
from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_rays

TOL = 1e-6


def _corners_of(x0, y0, x1, y1):
    return np.array([x0, x1, x1, x0], dtype=np.float64), np.array([y0, y0, y1, y1], np.float64)


def _l_corner(v=(0.0, 0.0), a_m=1.0, b_m=1.0):
    """Walls from ``v`` along +x (``a_m`` long) and +y (``b_m``): the sector is the quadrant."""
    vx, vy = v
    segs = np.array([[vx, vy, vx + a_m, vy], [vx, vy, vx, vy + b_m]], dtype=np.float64)
    return segs, wall_corners(segs, merge_walls(segs))


def _crosses(p, q, a, b) -> bool:
    """Whether segments ``p q`` and ``a b`` meet (touching counts)."""

    def cross(o, u, v):
        return (u[0] - o[0]) * (v[1] - o[1]) - (u[1] - o[1]) * (v[0] - o[0])

    d1, d2 = cross(p, q, a), cross(p, q, b)
    d3, d4 = cross(a, b, p), cross(a, b, q)
    return d1 * d2 <= 0 and d3 * d4 <= 0


def test_a_beam_through_the_shared_end_of_two_walls_hits_them():
    """The env's ray cast (an end on the beam's line counts as a crossing, and both walls
    hold the same floats at the shared end) never lets a beam slip between two walls that meet,
    for beams aimed exactly at the end and a hair to either side."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        v = rng.uniform(-5, 5, 2)
        a_dir = rng.uniform(0, 2 * math.pi)
        b_dir = a_dir + rng.uniform(0.3, math.pi - 0.3)  # the sector between is under half a turn
        a_end = v + rng.uniform(0.5, 3) * np.array([math.cos(a_dir), math.sin(a_dir)])
        b_end = v + rng.uniform(0.5, 3) * np.array([math.cos(b_dir), math.sin(b_dir)])
        segs = np.array([[*v, *a_end], [*b_end, *v]])
        index = SegmentIndex(segs)
        # a sensor inside the sector, aiming at the corner
        mid = 0.5 * (a_dir + b_dir)
        origin = v + rng.uniform(0.2, 2.5) * np.array([math.cos(mid), math.sin(mid)])
        origin += rng.normal(0, 0.05, 2)
        to_v = v - origin
        aim = math.atan2(to_v[1], to_v[0])
        angles = aim + np.array([0.0, 1e-15, -1e-15, 1e-12, -1e-12, 1e-9, -1e-9])
        hits = cast_rays(index, float(origin[0]), float(origin[1]), angles, 10.0)
        assert np.all(hits <= math.hypot(*to_v) + 1e-6), (v, origin, hits)


def test_a_corner_blocks_a_view_around_it_that_neither_wall_blocks_alone():
    segs, corners = _l_corner()
    assert corners.shape == (1, 8)
    box = _corners_of(0.3, 0.3, 0.4, 0.4)  # inside the quadrant
    rect = _corners_of(-0.5, -0.5, -0.4, -0.4)  # diagonally behind the corner
    fa, fu, px, py = np.empty(4), np.empty(4), np.empty(8), np.empty(8)
    walls = merge_walls(segs)
    assert not any(wall_blocks(walls, q, *rect, *box, TOL, fa, fu) for q in range(2))
    assert corner_blocks(corners, 0, *rect, *box, TOL, px, py)
    assert corner_blocks(corners, 0, *box, *rect, TOL, px, py)  # either way round
    work = np.empty((4, 4))
    near = np.arange(2, dtype=np.int64)
    rect_box = np.array([-0.5, -0.5, -0.4, -0.4])
    args = (walls, near, 2, 0, rect_box, *box, 5.0, 3, TOL, work)
    assert not rect_blind(*args, np.zeros((0, 8)))[0]
    assert rect_blind(*args, corners)[0]


@pytest.mark.parametrize(
    ("box", "a_m", "why"),
    [
        ((0.5, 0.1, 0.6, 0.2), 0.2, "the view passes beyond the short wall's far end"),
        ((-0.1, 0.3, 0.1, 0.4), 1.0, "the box straddles a wall's line: not inside the sector"),
        ((0.3, 0.3, 0.4, 0.4), 1.0, "the rectangle is inside the sector too"),
    ],
)
def test_a_corner_proves_nothing_where_a_view_can_pass(box, a_m, why):
    _, corners = _l_corner(a_m=a_m)
    rect = (-0.5, -0.5, -0.4, -0.4) if "inside the sector too" not in why else (0.6, 0.6, 0.7, 0.7)
    px, py = np.empty(8), np.empty(8)
    assert not corner_blocks(corners, 0, *_corners_of(*rect), *_corners_of(*box), TOL, px, py)


def test_every_segment_a_corner_blocks_meets_one_of_its_walls():
    """Random corners and rectangles: wherever the proof holds, sampled segments between the
    two rectangles all meet a wall (the shared end counts: it lies on both)."""
    rng = np.random.default_rng(5)
    px, py = np.empty(8), np.empty(8)
    proven = 0
    for _ in range(3000):
        v = rng.uniform(-1, 1, 2)
        t_a = rng.uniform(0, 2 * math.pi)
        t_b = t_a + rng.choice([-1, 1]) * rng.uniform(0.2, math.pi - 0.2)
        a_end = v + rng.uniform(0.2, 2) * np.array([math.cos(t_a), math.sin(t_a)])
        b_end = v + rng.uniform(0.2, 2) * np.array([math.cos(t_b), math.sin(t_b)])
        segs = np.array([[*v, *a_end], [*v, *b_end]])
        corners = wall_corners(segs, merge_walls(segs))
        lo1, lo2 = rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 2)
        r1 = (*lo1, *(lo1 + rng.uniform(0.05, 0.4, 2)))
        r2 = (*lo2, *(lo2 + rng.uniform(0.05, 0.4, 2)))
        if not corner_blocks(corners, 0, *_corners_of(*r1), *_corners_of(*r2), TOL, px, py):
            continue
        proven += 1
        for _ in range(20):
            p = rng.uniform(r1[:2], r1[2:])
            q = rng.uniform(r2[:2], r2[2:])
            assert _crosses(p, q, v, a_end) or _crosses(p, q, v, b_end)
    assert proven > 50


def test_only_ends_the_env_shares_exactly_make_corners():
    segs = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    assert wall_corners(segs, merge_walls(segs)).shape == (1, 8)
    apart = segs.copy()
    apart[1, :2] = [1e-12, 0.0]  # the same point to 1e-12 m, not the same floats: a gap
    assert wall_corners(apart, merge_walls(apart)).shape == (0, 8)
    straight = np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 2.0, 0.0]])  # one wall, merged
    assert wall_corners(straight, merge_walls(straight)).shape == (0, 8)
    # the walls are the merged ones: a corner's legs run to the merged walls' far ends
    bent = np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 2.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    corner = wall_corners(bent, merge_walls(bent))
    assert corner.shape == (1, 8) and sorted(corner[0, [4, 7]].tolist()) == [1.0, 2.0]


@pytest.mark.slow
@pytest.mark.parametrize("spec", ["maze:seed=1,size_m=5", "maze:seed=8,size_m=6,braid=0.3"])
def test_with_corners_the_branch_bound_is_as_high_and_no_mission_beats_it(spec, short_mission):
    from semexplore_gym.cli.oracle import certified_bound

    seed = 5
    overrides = ["episode.random_start=true"]
    plain = certified_bound(spec, seed, env_overrides=overrides, params={"wall_corners": False})
    bound = certified_bound(spec, seed, env_overrides=overrides)  # corners by default
    # regions only shrink, so the branches hide as much or more (to rounding in the sums)
    assert bound.branch_m >= plain.branch_m * (1 - 1e-12)
    reached = 0
    for policy in ("semantic", "nearest"):
        res, _ = short_mission(spec, policy, seed, 600.0)
        if res.t99_s is None:
            continue
        reached += 1
        assert res.t99_s >= bound.time_s, (spec, policy, res.t99_s, bound.time_s)
        hit = next(i for i, (_, c, _) in enumerate(res.coverage_trace) if c >= 0.99 - 1e-12)
        steps = np.diff(res.trajectory[: hit + 1, :2], axis=0)
        assert float(np.hypot(steps[:, 0], steps[:, 1]).sum()) >= bound.distance_m
    assert reached >= 1
