"""Metric helpers on polylines (``(K, 2)`` arrays of map-frame points, metres)."""

from __future__ import annotations

import math

import numpy as np

from semexplore_gym.core.grid import wrap_angle_rad


def polyline_length(poly: np.ndarray) -> float:
    if len(poly) < 2:
        return 0.0
    d = poly[1:] - poly[:-1]
    return float(np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]).sum())


def heading_angle(
    poly: np.ndarray, robot_xy: tuple[float, float], yaw: float, lookahead_m: float
) -> float:
    """Angle in [0, pi] between the heading and the direction to the point ``lookahead_m`` along ``poly``."""
    target = point_along(poly, lookahead_m)
    dx, dy = target[0] - robot_xy[0], target[1] - robot_xy[1]
    if math.hypot(dx, dy) < 1e-9:
        # The leg has no length: the path starts where the robot is, along its first segment
        # beyond the robot, or (none) straight ahead.
        rest = poly[np.hypot(poly[:, 0] - robot_xy[0], poly[:, 1] - robot_xy[1]) > 1e-9]
        if len(rest) == 0:
            return 0.0
        dx, dy = rest[0, 0] - robot_xy[0], rest[0, 1] - robot_xy[1]
    return abs(wrap_angle_rad(math.atan2(dy, dx) - yaw))


def point_along(poly: np.ndarray, s_m: float) -> np.ndarray:
    """The point at arc length ``s_m`` along a polyline (clamped to its ends)."""
    if len(poly) == 1 or s_m <= 0.0:
        return poly[0].copy()
    seg = np.hypot(*np.diff(poly, axis=0).T)
    cum = np.concatenate(([0.0], np.cumsum(seg)))
    if s_m >= cum[-1]:
        return poly[-1].copy()
    i = int(np.searchsorted(cum, s_m, side="right") - 1)
    t = (s_m - cum[i]) / seg[i] if seg[i] > 0 else 0.0
    return poly[i] + t * (poly[i + 1] - poly[i])


def project_onto_polyline(
    poly: np.ndarray, xy: tuple[float, float]
) -> tuple[float, np.ndarray, int, float]:
    """Nearest point of a polyline to ``xy``.

    Returns:
        ``(distance, point, segment_index, arc_length)`` where the point lies on segment
        ``segment_index`` (from vertex ``i`` to ``i + 1``) at ``arc_length`` from the start.
    """
    p = np.asarray(xy, dtype=np.float64)
    if len(poly) == 1:
        return float(np.hypot(*(poly[0] - p))), poly[0].copy(), 0, 0.0
    a = poly[:-1]
    b = poly[1:]
    ab = b - a
    den = np.einsum("ij,ij->i", ab, ab)
    t = np.where(den > 0, np.einsum("ij,ij->i", p - a, ab) / np.where(den > 0, den, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    q = a + t[:, None] * ab
    dist = np.hypot(q[:, 0] - p[0], q[:, 1] - p[1])
    i = int(np.argmin(dist))
    seg = np.sqrt(den)
    s = float(seg[:i].sum() + t[i] * seg[i])
    return float(dist[i]), q[i], i, s


def dedupe_polyline(poly: np.ndarray, tol_m: float = 1e-6) -> np.ndarray:
    if len(poly) < 2:
        return poly
    d = poly[1:] - poly[:-1]
    keep = np.empty(len(poly), dtype=bool)
    keep[0] = True
    keep[1:] = (np.abs(d[:, 0]) > tol_m) | (np.abs(d[:, 1]) > tol_m)
    return poly if keep.all() else poly[keep]


def oriented_polyline(
    path_m: np.ndarray, start_xy: tuple[float, float], end_xy: tuple[float, float]
) -> np.ndarray:
    """``path_m`` ordered so that it starts at the end nearer ``start_xy`` (ties: ``end_xy`` decides)."""
    p = np.asarray(path_m, dtype=np.float64).reshape(-1, 2)
    x0, y0 = float(p[0, 0]), float(p[0, 1])
    x1, y1 = float(p[-1, 0]), float(p[-1, 1])
    sx, sy = float(start_xy[0]), float(start_xy[1])
    ex, ey = float(end_xy[0]), float(end_xy[1])
    d_fwd = math.hypot(x0 - sx, y0 - sy) + math.hypot(x1 - ex, y1 - ey)
    d_rev = math.hypot(x1 - sx, y1 - sy) + math.hypot(x0 - ex, y0 - ey)
    return p if d_fwd <= d_rev else p[::-1].copy()
