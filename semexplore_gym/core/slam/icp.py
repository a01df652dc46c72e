"""Point-to-line ICP in 2D: the sub-cell refinement of a correlative scan match.

The correlative matcher (:mod:`.matcher`) finds the right basin robustly but only to its finest
lattice step (a quarter of two field cells, and the field's cells quantise both point sets), so
each keyframe's pose is off by a few millimetres and milliradians, and the errors add up along
the chain. :func:`refine_point_to_line` starts from its pose and minimises the squared
distances of the scan's end points to the local lines of the submap: for each scan point the
nearest submap point within ``max_pair_m`` (scipy's KD-tree), the line through it along the
principal direction of its neighbours in its own scan (:func:`local_normals`), Gauss-Newton steps on
``(x, y, yaw)`` with Huber weights, damped towards the start so that a direction the lines do
not pin (a bare corridor's axis) stays where the correlative match put it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

#: Huber threshold of the point-to-line residuals (m).
_HUBER_M = 0.01
#: Damping added to the normal equations (pulls an unpinned direction towards the start).
_DAMPING = 1e-6
#: Neighbours (the point itself included) that fit a point's local line.
_LINE_NEIGHBOURS = 6
#: Neighbours farther than this do not take part in a point's line (m).
_LINE_RADIUS_M = 0.12


@dataclass(frozen=True)
class LineMap:
    """Submap points ``(n, 2)`` in the world frame with a unit normal per point (zero where the
    point has too few neighbours for a line) and their KD-tree."""

    points: np.ndarray
    normals: np.ndarray
    tree: cKDTree


def local_normals(points_m: np.ndarray) -> np.ndarray:
    """A unit normal ``(n, 2)`` per point of ``points_m``: the least principal direction of its
    nearest neighbours within ``_LINE_RADIUS_M`` (zero with fewer than three of them). One
    scan's end points sample its walls densely enough: the back end computes them once per
    keyframe, in the robot frame, and rotates them with the keyframe."""
    pts = np.ascontiguousarray(points_m, dtype=np.float64).reshape(-1, 2)
    if len(pts) < 3:
        return np.zeros_like(pts)
    k = min(_LINE_NEIGHBOURS, len(pts))
    dist, idx = cKDTree(pts).query(pts, k=k, distance_upper_bound=_LINE_RADIUS_M)
    ok = np.isfinite(dist)
    n_ok = ok.sum(axis=1)
    nb = pts[np.where(ok, idx, np.arange(len(pts))[:, None])]  # missing: the point itself
    w = ok.astype(np.float64)
    mean = (nb * w[..., None]).sum(axis=1) / np.maximum(n_ok, 1)[:, None]
    c = (nb - mean[:, None, :]) * w[..., None]
    sxx = (c[..., 0] ** 2).sum(axis=1)
    syy = (c[..., 1] ** 2).sum(axis=1)
    sxy = (c[..., 0] * c[..., 1]).sum(axis=1)
    theta = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)  # the principal (line) direction
    normals = np.stack([-np.sin(theta), np.cos(theta)], axis=1)
    normals[n_ok < 3] = 0.0
    return normals


def line_map(points_m: np.ndarray, normals: np.ndarray) -> LineMap:
    """The :class:`LineMap` of world-frame ``points_m`` with their ``normals``."""
    pts = np.ascontiguousarray(points_m, dtype=np.float64).reshape(-1, 2)
    return LineMap(pts, np.asarray(normals, dtype=np.float64).reshape(-1, 2), cKDTree(pts))


def refine_point_to_line(
    lines: LineMap,
    points: np.ndarray,
    pose: tuple[float, float, float],
    max_pair_m: float = 0.08,
    iterations: int = 8,
    min_pairs: int = 20,
) -> tuple[tuple[float, float, float], int]:
    """The pose near ``pose`` that best lays the robot-frame ``points`` on ``lines`` (see the
    module docstring) and the pairs it used; ``pose`` itself with 0 when fewer than
    ``min_pairs`` points find a line within ``max_pair_m``."""
    pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    x, y, yaw = (float(v) for v in pose)
    used = 0
    for _ in range(iterations):
        c, s = math.cos(yaw), math.sin(yaw)
        rx = c * pts[:, 0] - s * pts[:, 1]
        ry = s * pts[:, 0] + c * pts[:, 1]
        world = np.stack([rx + x, ry + y], axis=1)
        dist, idx = lines.tree.query(world, k=1, distance_upper_bound=max_pair_m)
        ok = np.isfinite(dist)
        if np.any(ok):
            normal = lines.normals[np.where(ok, idx, 0)]
            ok &= np.any(normal != 0.0, axis=1)
        n_pairs = int(np.count_nonzero(ok))
        if n_pairs < min_pairs:
            break
        used = n_pairs
        n = lines.normals[idx[ok]]
        q = lines.points[idx[ok]]
        r = np.einsum("ij,ij->i", n, world[ok] - q)
        # d(world)/d(yaw) = (-ry, rx)
        jac = np.stack([n[:, 0], n[:, 1], -n[:, 0] * ry[ok] + n[:, 1] * rx[ok]], axis=1)
        a = np.abs(r)
        w = np.where(a <= _HUBER_M, 1.0, _HUBER_M / np.maximum(a, 1e-12))
        h = (jac * w[:, None]).T @ jac + _DAMPING * n_pairs * np.eye(3)
        g = (jac * w[:, None]).T @ r
        step = -np.linalg.solve(h, g)
        x, y, yaw = x + float(step[0]), y + float(step[1]), yaw + float(step[2])
        if abs(step[0]) + abs(step[1]) < 1e-5 and abs(step[2]) < 1e-5:
            break
    if used == 0:
        return (float(pose[0]), float(pose[1]), float(pose[2])), 0
    return (x, y, math.atan2(math.sin(yaw), math.cos(yaw))), used
