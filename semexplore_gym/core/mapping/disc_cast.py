"""Rays against discs: what a LiDAR sees of other robots."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
from numba import njit


class DiscObstacles(NamedTuple):
    """Discs a scan also sees (other robots), for :class:`~.scan_fusion.ScanFuser`.

    Attributes:
        centres_m: ``(k, 2)`` float64 disc centres.
        radius_m: Disc radius (all discs alike).
        map_hits: Fuse returns from the discs into the map; False: such beams are left out
            of the map (the scan still holds them).
    """

    centres_m: np.ndarray
    radius_m: float
    map_hits: bool


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
    centres = np.ascontiguousarray(centres_m, dtype=np.float64).reshape(-1, 2)
    out = np.full(cos_b.shape[0], np.inf)
    cast_discs_into(
        float(x_m),
        float(y_m),
        np.ascontiguousarray(cos_b, dtype=np.float64),
        np.ascontiguousarray(sin_b, dtype=np.float64),
        centres,
        float(radius_m) ** 2,
        out,
    )
    return out


@njit(cache=True)
def cast_discs_into(x, y, cos_b, sin_b, centres, r2, out):  # pragma: no cover - numba
    """:func:`cast_discs`'s kernel: lowers ``out[j]`` (start it at inf) to the distance along
    ray ``j`` to the first disc of squared radius ``r2`` ahead of ``(x, y)``."""
    for k in range(centres.shape[0]):
        dx = centres[k, 0] - x
        dy = centres[k, 1] - y
        dd = dx * dx + dy * dy
        for j in range(cos_b.shape[0]):
            along = dx * cos_b[j] + dy * sin_b[j]  # distance to the foot of the perpendicular
            miss2 = dd - along * along  # squared distance of the centre from the ray
            if miss2 > r2:
                continue
            half = math.sqrt(max(r2 - miss2, 0.0))
            t = along - half
            if t <= 0.0:
                t = along + half
            if 0.0 < t < out[j]:
                out[j] = t
