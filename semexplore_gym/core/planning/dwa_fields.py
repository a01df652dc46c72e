"""The local window of the DWA planner (:mod:`.dwa`): obstacle clearance and the flood-filled
distances to the path, the local goal and the nose target, as ROS's ``MapGrid`` computes them."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from scipy import ndimage

from semexplore_gym.core.grid import OCCUPIED, GridGeometry
from semexplore_gym.core.planning.grid_search import distance_field


def local_clearance(
    grid: np.ndarray,
    geometry: GridGeometry,
    x0: float,
    y0: float,
    window_m: float,
    points: npt.ArrayLike | None,
) -> tuple[np.ndarray, np.ndarray, float, float]:
    res = geometry.resolution_m
    n = int(math.ceil(window_m / res))
    r_c, c_c = geometry.world_to_grid(x0, y0)
    r0 = int(r_c) - n // 2
    c0 = int(c_c) - n // 2
    win = np.zeros((n, n), dtype=bool)
    h, w = geometry.shape
    rs, re = max(r0, 0), min(r0 + n, h)
    cs, ce = max(c0, 0), min(c0 + n, w)
    if rs < re and cs < ce:
        win[rs - r0 : re - r0, cs - c0 : ce - c0] = np.asarray(grid)[rs:re, cs:ce] == OCCUPIED
    wx0 = geometry.origin_x_m + c0 * res
    wy0 = geometry.origin_y_m + r0 * res
    if points is not None:
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        pr = np.floor((pts[:, 1] - wy0) / res).astype(np.int64)
        pc = np.floor((pts[:, 0] - wx0) / res).astype(np.int64)
        ok = (pr >= 0) & (pr < n) & (pc >= 0) & (pc < n)
        win[pr[ok], pc[ok]] = True
    # Per window cell, the world position of its nearest obstacle cell centre; the rollouts
    # measure the exact distance from each trajectory point to it, which removes most of the
    # error of reading a per-cell distance at a point that may lie anywhere in the cell.
    near = np.full((2, n, n), np.nan)
    clear = np.full((n, n), np.inf)
    if win.any():
        d, idx = ndimage.distance_transform_edt(~win, return_indices=True)
        near[0] = wx0 + (idx[1] + 0.5) * res
        near[1] = wy0 + (idx[0] + 0.5) * res
        clear = d * res
    return np.ascontiguousarray(near), clear, wx0, wy0


def distance_maps(
    clear: np.ndarray,
    wx0: float,
    wy0: float,
    res: float,
    local_path: np.ndarray,
    robot_xy: tuple[float, float],
    robot_radius_m: float,
    forward_point_distance_m: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Flood fills over the local window (ROS MapGrid): to the path, the goal, the nose target.

    Obstacle cells block the flood and cells whose centre is within the robot radius of one
    cost 20 times more to cross, so distances are path lengths round obstacles rather than
    straight lines through them, yet stay finite where a robot that is already too close
    stands (ROS would mark them as obstacles and leave the robot to its recovery behaviours).
    """
    n = clear.shape[0]
    cost = np.where(clear > robot_radius_m, res, 20.0 * res)
    cost[clear <= 0.0] = np.inf

    def cells(points: np.ndarray) -> np.ndarray:
        r = np.floor((points[:, 1] - wy0) / res).astype(np.int64)
        c = np.floor((points[:, 0] - wx0) / res).astype(np.int64)
        ok = (r >= 0) & (r < n) & (c >= 0) & (c < n)
        return r[ok] * n + c[ok]  # flat indices; duplicates are harmless

    def flood(sources: np.ndarray, start_cost: np.ndarray | None = None) -> np.ndarray:
        rc = np.column_stack([sources // n, sources % n])
        return distance_field(cost, rc, start_cost)[0]

    def flood_from_point(p: np.ndarray) -> np.ndarray | None:
        # Seed the 3 x 3 cells round the point with their exact distance to it, so that with
        # bilinear lookups the field is close to Euclidean near the point, not cell-quantised.
        r0 = int(np.floor((p[1] - wy0) / res))
        c0 = int(np.floor((p[0] - wx0) / res))
        rr, cc = np.mgrid[r0 - 1 : r0 + 2, c0 - 1 : c0 + 2]
        ok = (rr >= 0) & (rr < n) & (cc >= 0) & (cc < n)
        rr, cc = rr[ok], cc[ok]
        if len(rr) == 0:
            return None
        idx = rr * n + cc
        keep = np.isfinite(cost.ravel()[idx])
        if not keep.any():
            return None
        idx, rr, cc = idx[keep], rr[keep], cc[keep]
        d0 = np.hypot(wx0 + (cc + 0.5) * res - p[0], wy0 + (rr + 0.5) * res - p[1])
        return flood(idx, d0)

    path_idx = cells(local_path)
    if len(path_idx) == 0:
        inf = np.full((n, n), np.inf)
        return inf, inf, inf
    path_field = flood(path_idx)
    goal = local_path[-1]
    goal_field = flood_from_point(goal)
    if goal_field is None:
        goal_field = flood(path_idx[-1:])
    # ROS aims the nose at a point beyond the local goal, along the robot-to-goal direction, so
    # the robot centre can settle on the goal itself (goal_front_costs).
    d = np.array([goal[0] - robot_xy[0], goal[1] - robot_xy[1]])
    norm = float(np.hypot(*d))
    front_field = goal_field
    if norm > 1e-9:
        front = goal + forward_point_distance_m * d / norm
        front_idx = cells(front[None, :])
        if len(front_idx) and cost.ravel()[front_idx[0]] == res:
            shifted = flood_from_point(front)
            if shifted is not None:
                front_field = shifted
    return path_field, goal_field, front_field
