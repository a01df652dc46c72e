"""Numba kernel of the DWA planner (:mod:`.dwa`): scores every sampled velocity pair.

:func:`evaluate_trajectories` rolls each ``(v, omega)`` forward, rejects those that come too
close to an obstacle and scores the rest with ROS's path, goal and obstacle terms (the formula
is in :mod:`.dwa`'s docstring). Fields are read bilinearly on the local window.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def evaluate_trajectories(
    x0,
    y0,
    yaw0,
    vs,
    ws,
    n_steps,
    dt,
    near,
    path_field,
    goal_field,
    front_field,
    wx0,
    wy0,
    res,
    fwd,
    front_mode,
    ctrl_steps,
    gx,
    gy,
    min_clear,
    path_bias,
    goal_bias,
    occ_scale,
    inscribed,
    infl_radius,
    scaling,
    min_trans,
    min_rot,
    min_spin,
):  # pragma: no cover - numba
    n = near.shape[1]
    now_clear = _clearance(near, x0, y0, wx0, wy0, res)
    # A robot already too close may not get closer (give or take 5 mm, so that it can still
    # leave along a wall at a heading a hair off parallel); otherwise keep the full clearance.
    limit = min(min_clear, now_clear - 0.005)
    best_cost = np.inf
    best_i = -1
    best_j = -1
    # Faster samples first so that ties go to the faster trajectory.
    for ii in range(vs.shape[0]):
        i = vs.shape[0] - 1 - ii
        v = vs[i]
        for j in range(ws.shape[0]):
            w = ws[j]
            if abs(v) < min_trans and abs(w) < min_rot and not (v == 0.0 and abs(w) >= min_spin):
                continue
            x = x0
            y = y0
            yaw = yaw0
            lowest = np.inf
            ok = True
            xc = x0
            yc = y0
            for k in range(n_steps):
                x += v * math.cos(yaw) * dt
                y += v * math.sin(yaw) * dt
                yaw += w * dt
                if k + 1 == ctrl_steps:
                    xc = x
                    yc = y
                r = int(math.floor((y - wy0) / res))
                c = int(math.floor((x - wx0) / res))
                if r < 0 or r >= n or c < 0 or c >= n:
                    ok = False
                    break
                d = _clearance(near, x, y, wx0, wy0, res)
                if d < lowest:
                    lowest = d
                if d < limit:
                    ok = False
                    break
            if not ok:
                continue
            # Inside the margin a trajectory must end at least as far out as it started, so
            # that repeated small dips cannot ratchet the robot into the wall.
            if now_clear < min_clear and _clearance(near, x, y, wx0, wy0, res) < now_clear:
                continue
            pd_end = _lookup(path_field, x, y, wx0, wy0, res)
            gd_end = _lookup(goal_field, x, y, wx0, wy0, res)
            if not (pd_end < np.inf and gd_end < np.inf):
                continue  # end point cut off from the path or the goal (ROS: invalid)
            fx = x + fwd * math.cos(yaw)
            fy = y + fwd * math.sin(yaw)
            pd_front = _lookup(path_field, fx, fy, wx0, wy0, res)
            gd_front = _lookup(front_field, fx, fy, wx0, wy0, res)
            # A nose inside a wall or off the window scores as if it were one step further.
            if not pd_front < np.inf:
                pd_front = pd_end + fwd
            if not gd_front < np.inf:
                gd_front = _lookup(front_field, x, y, wx0, wy0, res) + fwd
                if not gd_front < np.inf:
                    gd_front = gd_end + fwd
            if lowest <= inscribed:
                occ = 253.0
            elif lowest > infl_radius:
                occ = 0.0
            else:
                occ = math.floor(252.0 * math.exp(-scaling * (lowest - inscribed)))
            if front_mode == 2:
                cost = 0.5 * path_bias * (pd_end + pd_front) + 0.5 * goal_bias * (gd_end + gd_front)
            elif front_mode == 1:
                cost = 0.5 * path_bias * pd_end + 0.5 * goal_bias * (gd_end + gd_front)
            else:
                # Settling: where the robot will be after this control period, as near the goal
                # as possible (the horizon's end point would overshoot at any admissible speed).
                # The obstacle cost is left out, or a goal in the inflated band next to a wall
                # could never be reached; the clearance test still applies.
                occ = 0.0
                cost = goal_bias * math.hypot(xc - gx, yc - gy)
            cost += occ_scale * occ
            if cost < best_cost - 1e-12:
                best_cost = cost
                best_i = i
                best_j = j
    return best_i, best_j, best_cost


@njit(cache=True, inline="always")
def _lookup(field, x, y, wx0, wy0, res):  # pragma: no cover - numba
    """Bilinear interpolation between cell centres; the nearest cell where a corner is inf."""
    n = field.shape[0]
    r = int(math.floor((y - wy0) / res))
    c = int(math.floor((x - wx0) / res))
    if r < 0 or r >= n or c < 0 or c >= n:
        return np.inf
    fy = (y - wy0) / res - 0.5
    fx = (x - wx0) / res - 0.5
    r0 = int(math.floor(fy))
    c0 = int(math.floor(fx))
    if r0 < 0 or c0 < 0 or r0 + 1 >= n or c0 + 1 >= n:
        return field[r, c]
    a = field[r0, c0]
    b = field[r0, c0 + 1]
    cc = field[r0 + 1, c0]
    d = field[r0 + 1, c0 + 1]
    if not (a < np.inf and b < np.inf and cc < np.inf and d < np.inf):
        return field[r, c]
    ty = fy - r0
    tx = fx - c0
    return (a * (1 - tx) + b * tx) * (1 - ty) + (cc * (1 - tx) + d * tx) * ty


@njit(cache=True, inline="always")
def _clearance(near, x, y, wx0, wy0, res):  # pragma: no cover - numba
    n = near.shape[1]
    r = int(math.floor((y - wy0) / res))
    c = int(math.floor((x - wx0) / res))
    if r < 0 or r >= n or c < 0 or c >= n:
        return np.inf
    ox = near[0, r, c]
    if not ox == ox:  # NaN: no obstacle in the window
        return np.inf
    return math.hypot(x - ox, y - near[1, r, c])
