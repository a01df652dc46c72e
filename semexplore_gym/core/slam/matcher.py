"""A correlative scan matcher (Olson's method, as Karto uses it), compiled with numba.

The local map is a *likelihood field*: a grid at ``resolution_m`` whose value at a cell is
``exp(-d^2 / (2 sigma^2))``, ``d`` the distance from its centre to the centre of the nearest
cell holding an occupied point of the map (0 beyond ``4 sigma``).
A candidate pose scores the mean field value at the scan's end points transformed by it
(cells off the field score 0), so 1 is a perfect overlap. :func:`match_scan` searches an
``(x, y, yaw)`` window around a predicted pose exhaustively on a coarse lattice, then refines
twice around the best candidate on lattices of half and a quarter of its steps. The
covariance of the estimate is the spread of the coarse score surface: each candidate weighted
by ``exp((score - best) / temperature)`` (Olson 2009, "Real-time correlative scan matching").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

#: The coarse lattice scores every this many end points of a scan (of 20 or more per step).
_COARSE_EVERY = 4
#: Score temperature of the covariance weights (score units, 0..1).
_COV_TEMPERATURE = 0.02


@dataclass(frozen=True)
class LikelihoodField:
    """A likelihood field over a rectangle: ``values[row, col]`` at cell centre
    ``(origin_x_m + (col + 0.5) * resolution_m, origin_y_m + (row + 0.5) * resolution_m)``;
    ``nearest[row, col]`` the index of the point whose kernel set the value there (the point
    nearest the cell's centre within the field's reach; -1 where none reaches)."""

    values: np.ndarray
    origin_x_m: float
    origin_y_m: float
    resolution_m: float
    nearest: np.ndarray


@dataclass(frozen=True)
class MatchResult:
    """The best pose ``(x_m, y_m, yaw_rad)``, its score (0..1) and a 3x3 covariance."""

    pose: tuple[float, float, float]
    score: float
    covariance: np.ndarray


def build_likelihood_field(
    points_m: np.ndarray, resolution_m: float, sigma_m: float, margin_m: float = 0.0
) -> LikelihoodField:
    """The likelihood field of occupied ``points_m`` (``(n, 2)`` world x, y) over their
    bounding box padded by ``margin_m`` plus the field's reach (``4 sigma``; beyond it the
    field is taken as 0). With no points the field is one zero cell."""
    pts = np.ascontiguousarray(points_m, dtype=np.float64).reshape(-1, 2)
    if len(pts) == 0:
        none = np.full((1, 1), -1, dtype=np.int32)
        return LikelihoodField(np.zeros((1, 1), dtype=np.float32), 0.0, 0.0, resolution_m, none)
    reach = int(math.ceil(4.0 * sigma_m / resolution_m))
    lo = pts.min(axis=0) - margin_m - (reach + 1) * resolution_m
    hi = pts.max(axis=0) + margin_m + (reach + 1) * resolution_m
    n_cols = int(math.ceil((hi[0] - lo[0]) / resolution_m)) + 1
    n_rows = int(math.ceil((hi[1] - lo[1]) / resolution_m)) + 1
    offsets = np.arange(-reach, reach + 1, dtype=np.float64) * resolution_m
    d2 = offsets[:, None] ** 2 + offsets[None, :] ** 2
    kernel = np.exp(-d2 / (2.0 * sigma_m**2)).astype(np.float32)
    values = np.zeros((n_rows, n_cols), dtype=np.float32)
    nearest = np.full((n_rows, n_cols), -1, dtype=np.int32)
    _stamp(values, nearest, pts, float(lo[0]), float(lo[1]), float(resolution_m), kernel, reach)
    return LikelihoodField(values, float(lo[0]), float(lo[1]), float(resolution_m), nearest)


@njit(cache=True)
def _stamp(values, nearest, pts, origin_x, origin_y, res, kernel, reach):  # noqa: ANN001, ANN202
    """The max of the kernel centred on the cell of each point (cell-centre distances), and
    the point that set it (the first of equals)."""
    n_rows, n_cols = values.shape
    for i in range(pts.shape[0]):
        col = int(math.floor((pts[i, 0] - origin_x) / res))
        row = int(math.floor((pts[i, 1] - origin_y) / res))
        for a in range(-reach, reach + 1):
            r = row + a
            if r < 0 or r >= n_rows:
                continue
            for b in range(-reach, reach + 1):
                c = col + b
                if 0 <= c < n_cols:
                    v = kernel[a + reach, b + reach]
                    if v > values[r, c]:
                        values[r, c] = v
                        nearest[r, c] = i


def scan_points(
    ranges_m: np.ndarray,
    beam_angles_rad: np.ndarray,
    max_range_m: float,
    mount_xy_m: tuple[float, float],
) -> np.ndarray:
    """The end points ``(n, 2)`` of the returns of a scan in the robot frame (no-return and
    invalid beams dropped)."""
    r = np.asarray(ranges_m, dtype=np.float64)
    keep = (r > 0.0) & (r < max_range_m)
    a = beam_angles_rad[keep]
    return np.stack(
        [mount_xy_m[0] + r[keep] * np.cos(a), mount_xy_m[1] + r[keep] * np.sin(a)], axis=1
    )


def transform_points(points: np.ndarray, pose: tuple[float, float, float]) -> np.ndarray:
    """Robot-frame ``points`` ``(n, 2)`` in the world frame at ``pose``."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    x, y = points[:, 0], points[:, 1]
    return np.stack([pose[0] + c * x - s * y, pose[1] + s * x + c * y], axis=1)


@njit(cache=True)
def _score_lattice(values, origin_x, origin_y, res, pts, x0, y0, yaw0, dxs, dys, dyaws):  # noqa: ANN001, ANN202
    n_rows, n_cols = values.shape
    out = np.zeros((dyaws.shape[0], dys.shape[0], dxs.shape[0]), dtype=np.float64)
    n = pts.shape[0]
    if n == 0:
        return out
    rx = np.empty(n)
    ry = np.empty(n)
    for k in range(dyaws.shape[0]):
        c = math.cos(yaw0 + dyaws[k])
        s = math.sin(yaw0 + dyaws[k])
        for i in range(n):
            rx[i] = c * pts[i, 0] - s * pts[i, 1] - origin_x
            ry[i] = s * pts[i, 0] + c * pts[i, 1] - origin_y
        for j in range(dys.shape[0]):
            ty = y0 + dys[j]
            for m in range(dxs.shape[0]):
                tx = x0 + dxs[m]
                total = 0.0
                for i in range(n):
                    col = int(math.floor((rx[i] + tx) / res))
                    row = int(math.floor((ry[i] + ty) / res))
                    if 0 <= row < n_rows and 0 <= col < n_cols:
                        total += values[row, col]
                out[k, j, m] = total / n
    return out


def _steps(half_width: float, step: float) -> np.ndarray:
    n = int(math.floor(half_width / step + 1e-9))
    return np.arange(-n, n + 1, dtype=np.float64) * step


def _best(
    scores: np.ndarray, dxs: np.ndarray, dys: np.ndarray, dyaws: np.ndarray
) -> tuple[float, float, float, float]:
    # The first maximum in (yaw, y, x) order: deterministic on ties.
    k, j, m = np.unravel_index(int(np.argmax(scores)), scores.shape)
    return float(dxs[m]), float(dys[j]), float(dyaws[k]), float(scores[k, j, m])


def _covariance(
    scores: np.ndarray, dxs: np.ndarray, dys: np.ndarray, dyaws: np.ndarray, floor: np.ndarray
) -> np.ndarray:
    w = np.exp((scores - scores.max()) / _COV_TEMPERATURE)
    w /= w.sum()
    yaw_g, y_g, x_g = np.meshgrid(dyaws, dys, dxs, indexing="ij")
    d = np.stack([x_g.ravel(), y_g.ravel(), yaw_g.ravel()], axis=1)
    mean = w.ravel() @ d
    centred = d - mean
    cov = (centred * w.ravel()[:, None]).T @ centred
    return cov + np.diag(floor)


def match_scan(
    field: LikelihoodField,
    points: np.ndarray,
    prediction: tuple[float, float, float],
    search_xy_m: float,
    search_yaw_rad: float,
) -> MatchResult:
    """The pose within the search window around ``prediction`` whose transform of the
    robot-frame ``points`` (``(n, 2)``) best overlaps ``field`` (see the module docstring)."""
    pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    res = field.resolution_m
    step_xy = 2.0 * res
    # A yaw step that moves a point at 2 m by about the xy step.
    step_yaw = step_xy / 2.0
    args = (field.values, field.origin_x_m, field.origin_y_m, res, pts)
    x0, y0, yaw0 = prediction
    dxs, dys = _steps(search_xy_m, step_xy), _steps(search_xy_m, step_xy)
    dyaws = _steps(search_yaw_rad, step_yaw)
    # The coarse lattice scores every fourth end point: it only has to find the basin (and
    # spread its scores for the covariance); the fine steps and ICP use them all.
    coarse = (*args[:4], pts[::_COARSE_EVERY] if len(pts) >= 20 * _COARSE_EVERY else pts)
    scores = _score_lattice(*coarse, x0, y0, yaw0, dxs, dys, dyaws)
    bx, by, byaw, best = _best(scores, dxs, dys, dyaws)
    floor = np.array([res**2, res**2, (step_yaw / 2.0) ** 2])
    cov = _covariance(scores, dxs, dys, dyaws, floor)
    for _ in range(2):
        step_xy, step_yaw = step_xy / 2.0, step_yaw / 2.0
        fx = np.array([-step_xy, 0.0, step_xy])
        fyaw = np.array([-step_yaw, 0.0, step_yaw])
        fine = _score_lattice(*args, x0 + bx, y0 + by, yaw0 + byaw, fx, fx, fyaw)
        ex, ey, eyaw, s = _best(fine, fx, fx, fyaw)
        if s > best:
            bx, by, byaw, best = bx + ex, by + ey, byaw + eyaw, s
    pose = (x0 + bx, y0 + by, math.atan2(math.sin(yaw0 + byaw), math.cos(yaw0 + byaw)))
    return MatchResult(pose, best, cov)
