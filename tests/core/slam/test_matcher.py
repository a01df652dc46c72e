"""The correlative scan matcher recovers a known offset on a synthetic scan and map."""

from __future__ import annotations

import math

import numpy as np

from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan
from semexplore_gym.core.slam.matcher import build_likelihood_field, match_scan, scan_points

BEAMS = np.arange(360) * (2 * math.pi / 360)
MAX_RANGE_M = 3.5


def _room_segments() -> np.ndarray:
    """A 4 x 3 m room with an L-shaped inner wall (no symmetry for the matcher to confuse)."""
    return np.array(
        [
            [0, 0, 4, 0],
            [4, 0, 4, 3],
            [4, 3, 0, 3],
            [0, 3, 0, 0],
            [1.0, 1.0, 2.2, 1.0],
            [2.2, 1.0, 2.2, 2.0],
        ],
        dtype=np.float64,
    )


def _scan(pose: tuple[float, float, float]) -> np.ndarray:
    index = SegmentIndex(_room_segments())
    r = cast_scan(index, pose[0], pose[1], pose[2], BEAMS, MAX_RANGE_M)
    return np.minimum(r, MAX_RANGE_M)


def _wall_points(spacing_m: float = 0.01) -> np.ndarray:
    """Points along every wall of the room: the synthetic map."""
    out = []
    for x0, y0, x1, y1 in _room_segments():
        t = np.linspace(0.0, 1.0, int(math.hypot(x1 - x0, y1 - y0) / spacing_m) + 1)
        out.append(np.stack([x0 + t * (x1 - x0), y0 + t * (y1 - y0)], axis=1))
    return np.concatenate(out)


def test_matcher_recovers_a_known_offset() -> None:
    map_points = _wall_points()
    field = build_likelihood_field(map_points, 0.025, 0.04)
    truth = (3.0, 0.6, 1.1)
    points = scan_points(_scan(truth), BEAMS, MAX_RANGE_M, (0, 0))
    prediction = (truth[0] + 0.13, truth[1] - 0.09, truth[2] + 0.12)
    result = match_scan(field, points, prediction, 0.2, 0.3)
    err_xy = math.hypot(result.pose[0] - truth[0], result.pose[1] - truth[1])
    err_before = math.hypot(0.13, 0.09)
    assert err_xy < 0.02, (result.pose, err_xy)
    assert abs(result.pose[2] - truth[2]) < 0.01
    assert err_xy < err_before / 4
    assert result.score > 0.8
    # The covariance is a symmetric positive-definite 3x3 matrix, tight around the match.
    cov = result.covariance
    assert cov.shape == (3, 3)
    assert np.allclose(cov, cov.T)
    assert np.all(np.linalg.eigvalsh(cov) > 0)
    assert cov[0, 0] < 0.05**2 and cov[2, 2] < 0.05**2


def test_matcher_scores_a_scan_of_another_place_low() -> None:
    map_points = np.array([[0.0, y] for y in np.arange(0, 3, 0.02)])
    field = build_likelihood_field(map_points, 0.025, 0.04)
    truth = (3.0, 0.6, 1.1)
    points = scan_points(_scan(truth), BEAMS, MAX_RANGE_M, (0, 0))
    assert match_scan(field, points, truth, 0.2, 0.3).score < 0.35


def test_the_field_names_the_point_nearest_each_cell() -> None:
    pts = np.array([[0.0, 0.0], [1.0, 0.0]])
    field = build_likelihood_field(pts, 0.05, 0.04)

    def at(x: float, y: float) -> int:
        col = int((x - field.origin_x_m) / field.resolution_m)
        row = int((y - field.origin_y_m) / field.resolution_m)
        return int(field.nearest[row, col])

    assert at(0.06, 0.02) == 0 and at(0.94, -0.03) == 1
    assert at(0.5, 0.0) == -1  # beyond the field's reach of both points
