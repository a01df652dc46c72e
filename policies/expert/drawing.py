"""What the expert's overlay draws from its topometric map (the env's render shows it)."""

from __future__ import annotations

import numpy as np

from semexplore_gym.core.topometric.types import TopometricMap

__all__ = ["area_type_raster"]


def area_type_raster(tmap: TopometricMap) -> np.ndarray:
    """``(H, W)`` int16 raster of :class:`AreaType` values of the map's areas; -1 elsewhere."""
    ids = tmap.area_ids
    out = np.full(ids.shape, -1, dtype=np.int16)
    inside = ids >= 0
    if not inside.any() or not tmap.areas:
        return out
    uniq, inv = np.unique(ids[inside], return_inverse=True)
    lut = np.array(
        [int(tmap.areas[int(a)].type) if int(a) in tmap.areas else -1 for a in uniq], dtype=np.int16
    )
    out[inside] = lut[inv]
    return out
