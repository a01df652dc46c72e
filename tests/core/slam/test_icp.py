"""Point-to-line ICP: the refinement of a correlative match on synthetic scans."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan
from semexplore_gym.core.slam.icp import local_normals, pair_residuals_m, refine_point_to_line
from semexplore_gym.core.slam.matcher import build_likelihood_field, scan_points, transform_points

BEAMS = np.arange(360) * (2 * math.pi / 360)
MAX_RANGE_M = 3.5


def _points(walls: list[list[float]], pose: tuple[float, float, float]) -> np.ndarray:
    ranges = cast_scan(SegmentIndex(np.array(walls, dtype=np.float64)), *pose, BEAMS, MAX_RANGE_M)
    return scan_points(np.minimum(ranges, MAX_RANGE_M), BEAMS, MAX_RANGE_M, (0.0, 0.0))


ROOM = [[0, 0, 4, 0], [4, 0, 4, 3], [4, 3, 0, 3], [0, 3, 0, 0], [1, 1, 2.2, 1], [2.2, 1, 2.2, 2]]
#: A corridor 1.4 m wide and 30 m long: from its middle no end is in range.
CORRIDOR = [[-15, 0, 15, 0], [-15, 1.4, 15, 1.4]]


def _refine(walls, map_pose, scan, start):  # noqa: ANN001, ANN202
    """``scan`` refined from ``start`` against the scan taken at ``map_pose``."""
    pts = _points(walls, map_pose)
    cloud = transform_points(pts, map_pose)
    field = build_likelihood_field(cloud, 0.025, 0.04)
    normals = transform_points(local_normals(pts), (0.0, 0.0, map_pose[2]))
    return refine_point_to_line(field, cloud, normals, scan, start)


def test_normals_are_perpendicular_to_the_walls() -> None:
    pts = _points(ROOM, (3.0, 2.0, 0.3))
    normals = local_normals(pts)
    world = transform_points(pts, (3.0, 2.0, 0.3))
    on_bottom = (np.abs(world[:, 1]) < 1e-6) & (world[:, 0] > 2.5) & (world[:, 0] < 3.5)
    n = transform_points(normals[on_bottom], (0.0, 0.0, 0.3))
    assert on_bottom.sum() >= 3
    assert np.allclose(np.abs(n[:, 1]), 1.0, atol=1e-6)  # the bottom wall's normal is +-y
    assert np.allclose(np.hypot(*normals[np.any(normals != 0, axis=1)].T), 1.0)


def test_a_small_offset_is_taken_out_to_a_millimetre() -> None:
    true = (2.8, 1.9, 0.25)
    start = (true[0] + 0.015, true[1] - 0.012, true[2] + 0.008)  # a correlative step off
    pose, pairs = _refine(ROOM, (3.0, 2.0, 0.3), _points(ROOM, true), start)
    assert pairs > 100
    assert math.hypot(pose[0] - true[0], pose[1] - true[1]) < 1e-3
    assert abs(pose[2] - true[2]) < 1e-3


def test_along_a_bare_corridor_the_axis_stays_at_the_start() -> None:
    true = (0.3, 0.7, 0.0)
    start = (0.35, 0.72, 0.01)  # 5 cm off along the axis, 2 cm across, 10 mrad
    pose, pairs = _refine(CORRIDOR, (0.0, 0.7, 0.0), _points(CORRIDOR, true), start)
    assert pairs > 100
    assert pose[1] == pytest.approx(true[1], abs=1e-3)  # across: pinned
    assert pose[2] == pytest.approx(true[2], abs=1e-3)
    assert pose[0] == pytest.approx(start[0], abs=1e-3)  # along: nothing pins it


def test_too_few_pairs_give_the_start_back() -> None:
    start = (3.0, 2.0, 0.3)
    far = np.array([[10.0, 10.0], [11.0, 10.0]])  # nothing of the map near these
    assert _refine(ROOM, start, far, start) == (start, 0)


def test_residuals_say_a_match_one_yaw_step_off_lies_beside_the_walls() -> None:
    map_pose = (3.0, 2.0, 0.3)
    pts = _points(ROOM, map_pose)
    cloud = transform_points(pts, map_pose)
    field = build_likelihood_field(cloud, 0.025, 0.04)
    normals = transform_points(local_normals(pts), (0.0, 0.0, map_pose[2]))
    true = (2.8, 1.9, 0.25)
    scan = _points(ROOM, true)
    right = pair_residuals_m(field, cloud, normals, scan, true)
    off = pair_residuals_m(field, cloud, normals, scan, (true[0], true[1], true[2] + 0.025))
    assert len(right) > 200 and np.quantile(right, 0.9) < 0.003
    assert np.quantile(off, 0.9) > 0.02  # the far walls, 2-3 m off, miss by centimetres
    assert len(pair_residuals_m(field, cloud, normals, scan, (true[0] + 2.0, *true[1:]))) < 50
