"""Numba kernels of the potential-field path follower (:mod:`.potential_field`).

All points and forces are in the robot frame (x ahead, y to the left); beams are given by the
cosines and sines of their angles.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from semexplore_gym.core.grid import OCCUPIED


@njit(cache=True)
def field_force_xy(scan, cos_a, sin_a, max_range, goal_angle, f_g, f_o):  # pragma: no cover - numba
    sx = 0.0
    sy = 0.0
    for i in range(scan.shape[0]):
        r = scan[i]
        if r > 0.0 and r < max_range:
            sx += cos_a[i] / r
            sy += sin_a[i] / r
    return f_g * math.cos(goal_angle) - f_o * sx, f_g * math.sin(goal_angle) - f_o * sy


@njit(cache=True)
def free_along(px, py, heading, soft, hard):  # pragma: no cover - numba
    # See free_distance_along; hard < 0 means no contact rule.
    c = math.cos(heading)
    s = math.sin(heading)
    best = math.inf
    soft2 = soft * soft
    hard2 = hard * hard
    for i in range(px.shape[0]):
        x = c * px[i] + s * py[i]
        if x <= 0.0:
            continue
        y = -s * px[i] + c * py[i]
        ay = abs(y)
        if ay >= soft:
            continue
        free = x - math.sqrt(soft2 - y * y)
        if free < 0.0 and hard >= 0.0:
            if ay >= hard:
                continue
            free = x - math.sqrt(max(hard2 - y * y, 0.0))
        if free < best:
            best = free
    return max(best, 0.0)


@njit(cache=True)
def guarded_velocity(
    fx,
    fy,
    px,
    py,
    soft,
    hard,
    steer_max,
    steer_step,
    need,
    turn_in_place,
    gain,
    vmax,
    wmax,
    braking,
    brake,
):  # pragma: no cover - numba
    phi = math.atan2(fy, fx) if (fx != 0.0 or fy != 0.0) else 0.0
    front = free_along(px, py, 0.0, soft, hard)
    if steer_max > 0.0 and abs(phi) <= turn_in_place:
        # Guard steering: the way along F is blocked within the braking distance: aim at the
        # nearest open heading, alternating sides.
        if free_along(px, py, phi, soft, hard) < need:
            n = int(steer_max / steer_step + 1e-9)
            found = False
            for k in range(1, n + 1):
                for sign in (1.0, -1.0):
                    cand = phi + sign * k * steer_step
                    if free_along(px, py, cand, soft, hard) >= need:
                        phi = cand
                        found = True
                        break
                if found:
                    break
    omega = max(-wmax, min(wmax, gain * phi))
    if abs(phi) > turn_in_place:
        v = 0.0
    else:
        v = vmax * max(0.0, math.cos(phi))
    if brake:
        v = min(v, front / braking)
    return v, omega, front


@njit(cache=True)
def min_valid_range(scan, max_range):  # pragma: no cover - numba
    best = math.inf
    for i in range(scan.shape[0]):
        r = scan[i]
        if r > 0.0 and r < max_range and r < best:
            best = r
    return best


@njit(cache=True)
def scan_points_xy(scan, cos_a, sin_a, max_range):  # pragma: no cover - numba
    n = 0
    for i in range(scan.shape[0]):
        if scan[i] > 0.0 and scan[i] < max_range:
            n += 1
    px = np.empty(n)
    py = np.empty(n)
    k = 0
    for i in range(scan.shape[0]):
        r = scan[i]
        if r > 0.0 and r < max_range:
            px[k] = r * cos_a[i]
            py[k] = r * sin_a[i]
            k += 1
    return px, py


@njit(cache=True)
def map_points_xy(grid, ox, oy, res, x, y, yaw, radius):  # pragma: no cover - numba
    h, w = grid.shape
    r0 = max(int(math.floor((y - radius - oy) / res)), 0)
    r1 = min(int(math.floor((y + radius - oy) / res)), h - 1)
    c0 = max(int(math.floor((x - radius - ox) / res)), 0)
    c1 = min(int(math.floor((x + radius - ox) / res)), w - 1)
    c = math.cos(yaw)
    s = math.sin(yaw)
    cap = max(0, (r1 - r0 + 1) * (c1 - c0 + 1))
    px = np.empty(cap)
    py = np.empty(cap)
    k = 0
    for r in range(r0, r1 + 1):
        for cc in range(c0, c1 + 1):
            if grid[r, cc] != OCCUPIED:
                continue
            dx = ox + (cc + 0.5) * res - x
            dy = oy + (r + 0.5) * res - y
            if dx * dx + dy * dy > radius * radius:
                continue
            px[k] = c * dx + s * dy
            py[k] = -s * dx + c * dy
            k += 1
    return px[:k], py[:k]
