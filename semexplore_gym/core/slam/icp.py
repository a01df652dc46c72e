"""Point-to-line ICP in 2D: the sub-cell refinement of a correlative scan match.

The correlative matcher (:mod:`.matcher`) finds the right basin robustly but only to its finest
lattice step, and its field's cells quantise both point sets, so each keyframe's pose is off by
a few millimetres and milliradians, and the errors add up along the chain.
:func:`refine_point_to_line` starts from its pose and minimises the squared distances of the
scan's end points to the local lines of the submap: each scan point is paired with the submap
point the likelihood field's ``nearest`` index gives for its cell (kept when within
``max_pair_m``), the line through that point along its normal (:func:`local_normals`), and
Gauss-Newton steps on ``(x, y, yaw)`` with Huber weights, damped towards the start so that a
direction the lines do not pin (a bare corridor's axis) stays where the correlative match put
it. Both kernels are compiled with numba.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from semexplore_gym.core.slam.matcher import LikelihoodField, transform_points

#: Huber threshold of the point-to-line residuals (m).
_HUBER_M = 0.01
#: Damping added to the normal equations, per pair (pulls an unpinned direction to the start).
_DAMPING = 1e-6
#: A point's line is fitted to the points up to this many places either side of it in its
#: scan (the beams' order) ...
_LINE_SPAN = 3
#: ... that lie within this distance of it (m); at least three points in all.
_LINE_RADIUS_M = 0.12
#: Steps smaller than this (m, and rad) end the iterations.
_CONVERGED = 1e-4


def local_normals(points_m: np.ndarray) -> np.ndarray:
    """A unit normal ``(n, 2)`` per end point of one scan (``points_m`` in the beams' order):
    the least principal direction of its neighbours in the scan within ``_LINE_RADIUS_M``
    (zero with fewer than three). The back end computes them once per keyframe, in the robot
    frame, and turns them with the keyframe."""
    pts = np.ascontiguousarray(points_m, dtype=np.float64).reshape(-1, 2)
    return _normals(pts, _LINE_SPAN, _LINE_RADIUS_M)


@njit(cache=True)
def _normals(pts, span, radius):  # noqa: ANN001, ANN202
    n = pts.shape[0]
    out = np.zeros((n, 2))
    for i in range(n):
        sx = 0.0
        sy = 0.0
        k = 0
        for j in range(max(0, i - span), min(n, i + span + 1)):
            if (pts[j, 0] - pts[i, 0]) ** 2 + (pts[j, 1] - pts[i, 1]) ** 2 <= radius * radius:
                sx += pts[j, 0]
                sy += pts[j, 1]
                k += 1
        if k < 3:
            continue
        mx = sx / k
        my = sy / k
        sxx = 0.0
        syy = 0.0
        sxy = 0.0
        for j in range(max(0, i - span), min(n, i + span + 1)):
            dx = pts[j, 0] - pts[i, 0]
            dy = pts[j, 1] - pts[i, 1]
            if dx * dx + dy * dy <= radius * radius:
                ex = pts[j, 0] - mx
                ey = pts[j, 1] - my
                sxx += ex * ex
                syy += ey * ey
                sxy += ex * ey
        theta = 0.5 * math.atan2(2.0 * sxy, sxx - syy)  # the line's direction
        out[i, 0] = -math.sin(theta)
        out[i, 1] = math.cos(theta)
    return out


def refine_point_to_line(
    field: LikelihoodField,
    cloud_m: np.ndarray,
    normals: np.ndarray,
    points: np.ndarray,
    pose: tuple[float, float, float],
    max_pair_m: float = 0.08,
    iterations: int = 8,
    min_pairs: int = 20,
) -> tuple[tuple[float, float, float], int]:
    """The pose near ``pose`` that best lays the robot-frame ``points`` on the lines of the
    submap (see the module docstring) and the pairs it used; ``pose`` itself with 0 when fewer
    than ``min_pairs`` points find a line within ``max_pair_m``.

    Args:
        field: The likelihood field of ``cloud_m`` (its ``nearest`` index pairs the points).
        cloud_m: ``(m, 2)`` the submap's end points, world frame.
        normals: ``(m, 2)`` their unit normals (zero: no line there).
        points: ``(n, 2)`` the scan's end points, robot frame.
        pose: The start, ``(x_m, y_m, yaw_rad)``.
    """
    out = _refine(
        field.nearest,
        field.origin_x_m,
        field.origin_y_m,
        field.resolution_m,
        np.ascontiguousarray(cloud_m, dtype=np.float64).reshape(-1, 2),
        np.ascontiguousarray(normals, dtype=np.float64).reshape(-1, 2),
        np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2),
        float(pose[0]),
        float(pose[1]),
        float(pose[2]),
        float(max_pair_m),
        int(iterations),
        int(min_pairs),
    )
    used = int(out[3])
    if used == 0:
        return (float(pose[0]), float(pose[1]), float(pose[2])), 0
    yaw = float(out[2])
    return (float(out[0]), float(out[1]), math.atan2(math.sin(yaw), math.cos(yaw))), used


def pair_residuals_m(
    field: LikelihoodField,
    cloud_m: np.ndarray,
    normals: np.ndarray,
    points: np.ndarray,
    pose: tuple[float, float, float],
    max_pair_m: float = 0.08,
) -> np.ndarray:
    """The point-to-line distances (m) of the robot-frame ``points`` placed at ``pose`` that
    pair with a submap line as :func:`refine_point_to_line` pairs them (empty when none do).
    After a refinement they say how well the scan fits: a match one yaw step off lays its far
    points centimetres beside the walls."""
    world = transform_points(np.asarray(points, dtype=np.float64).reshape(-1, 2), pose)
    col = np.floor((world[:, 0] - field.origin_x_m) / field.resolution_m).astype(np.int64)
    row = np.floor((world[:, 1] - field.origin_y_m) / field.resolution_m).astype(np.int64)
    n_rows, n_cols = field.nearest.shape
    inside = (row >= 0) & (row < n_rows) & (col >= 0) & (col < n_cols)
    k = field.nearest[row[inside], col[inside]]
    paired = k >= 0
    k = k[paired]
    offset = world[inside][paired] - cloud_m[k]
    normal = normals[k]
    near = (np.hypot(offset[:, 0], offset[:, 1]) <= max_pair_m) & normal.any(axis=1)
    return np.abs(np.sum(offset[near] * normal[near], axis=1))


@njit(cache=True)
def _refine(nearest, ox, oy, res, cloud, normals, pts, x, y, yaw, max_pair, iterations, min_pairs):  # noqa: ANN001, ANN202, E501
    n_rows, n_cols = nearest.shape
    used = 0
    for _ in range(iterations):
        c = math.cos(yaw)
        s = math.sin(yaw)
        h = np.zeros((3, 3))
        g = np.zeros(3)
        n_pairs = 0
        for i in range(pts.shape[0]):
            rx = c * pts[i, 0] - s * pts[i, 1]
            ry = s * pts[i, 0] + c * pts[i, 1]
            wx = rx + x
            wy = ry + y
            col = int(math.floor((wx - ox) / res))
            row = int(math.floor((wy - oy) / res))
            if row < 0 or row >= n_rows or col < 0 or col >= n_cols:
                continue
            k = nearest[row, col]
            if k < 0:
                continue
            nx = normals[k, 0]
            ny = normals[k, 1]
            if nx == 0.0 and ny == 0.0:
                continue
            dx = wx - cloud[k, 0]
            dy = wy - cloud[k, 1]
            if dx * dx + dy * dy > max_pair * max_pair:
                continue
            r = nx * dx + ny * dy
            a = abs(r)
            w = 1.0 if a <= _HUBER_M else _HUBER_M / a
            j0 = nx
            j1 = ny
            j2 = -nx * ry + ny * rx  # d(world)/d(yaw) = (-ry, rx)
            h[0, 0] += w * j0 * j0
            h[0, 1] += w * j0 * j1
            h[0, 2] += w * j0 * j2
            h[1, 1] += w * j1 * j1
            h[1, 2] += w * j1 * j2
            h[2, 2] += w * j2 * j2
            g[0] += w * j0 * r
            g[1] += w * j1 * r
            g[2] += w * j2 * r
            n_pairs += 1
        if n_pairs < min_pairs:
            break
        used = n_pairs
        h[1, 0] = h[0, 1]
        h[2, 0] = h[0, 2]
        h[2, 1] = h[1, 2]
        for d in range(3):
            h[d, d] += _DAMPING * n_pairs
        step = np.linalg.solve(h, -g)
        x += step[0]
        y += step[1]
        yaw += step[2]
        if abs(step[0]) + abs(step[1]) < _CONVERGED and abs(step[2]) < _CONVERGED:
            break
    return np.array([x, y, yaw, float(used)])
