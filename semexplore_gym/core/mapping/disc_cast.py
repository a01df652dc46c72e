"""Rays against discs: what a LiDAR sees of other robots (numpy only)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt


def cast_discs(
    x_m: float,
    y_m: float,
    cos_b: np.ndarray,
    sin_b: np.ndarray,
    centres_m: npt.ArrayLike,
    radius_m: float,
) -> np.ndarray:
    """Distance along each ray from ``(x_m, y_m)`` to the first of some discs.

    Args:
        x_m: Ray origin x in metres.
        y_m: Ray origin y in metres.
        cos_b: ``(n,)`` world-frame ray direction cosines.
        sin_b: ``(n,)`` world-frame ray direction sines.
        centres_m: ``(k, 2)`` disc centres.
        radius_m: Disc radius (all discs alike).

    Returns:
        ``(n,)`` float64 distances, ``np.inf`` where a ray meets no disc ahead of it. A ray
        that starts inside a disc meets it at its exit point (as a LiDAR inside a body
        would see its far side; it does not happen between robots that cannot overlap).
    """
    out = np.full(cos_b.shape[0], np.inf)
    centres = np.asarray(centres_m, dtype=np.float64).reshape(-1, 2)
    r2 = float(radius_m) ** 2
    for cx, cy in centres:
        dx, dy = cx - x_m, cy - y_m
        along = dx * cos_b + dy * sin_b  # distance to the foot of the perpendicular
        miss2 = dx * dx + dy * dy - along * along  # squared distance of the centre from the ray
        half = np.sqrt(np.maximum(r2 - miss2, 0.0))
        near = along - half
        t = np.where(near > 0.0, near, along + half)
        hit = (miss2 <= r2) & (t > 0.0)
        np.minimum(out, np.where(hit, t, np.inf), out=out)
    return out
