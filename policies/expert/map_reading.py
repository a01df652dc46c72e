"""How the expert reads the observed map: as observed, or with a SLAM map's wall slivers filled.

A recipe's ``map_reading`` part (:class:`WallSliverFill`, or None for the map as observed)
decides what the plan sources, the goal checks and the navigation of an expert see as
``grid``. The env's SLAM mode renders its map from keyframe scans at estimated poses: walls come
out one cell thin in places, their faces have gaps where a beam from a pose a centimetre off
passed the wall's edge, and the inside of a wall shows as a strip of UNKNOWN beside FREE cells
(:mod:`semexplore_gym.core.frontiers.wall_slivers`). No scan clears such a strip, and where it
meets the unknown outside of the building at a corner it passes every test for unknown space
behind a frontier, so an expert that reads the SLAM map as observed drives to these strips
after the floor is done. :class:`WallSliverFill` reads them as wall.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from semexplore_gym.core.frontiers.wall_slivers import (
    sliver_context_cells,
    wall_sliver_mask,
    wall_sliver_mask_box,
)
from semexplore_gym.core.grid import OCCUPIED

__all__ = ["SLAM_INFO_MARK", "SLIVER_MAPS", "MapReader", "WallSliverFill"]

#: The ``info`` entry by which an env says its map comes from its SLAM back end.
SLAM_INFO_MARK = "slam_pose"


#: The maps :class:`WallSliverFill` reads (the expert's ``sliver_maps``).
SLIVER_MAPS = ("slam", "all")


@dataclass(frozen=True)
class WallSliverFill:
    """Recipe part: read UNKNOWN strips narrower than the expert's ``sliver_max_width_m``
    that lie along walls (within two cells of an OCCUPIED cell) as OCCUPIED, on the maps its
    ``sliver_maps`` names: ``"slam"`` (the default), only on a map the env's SLAM back end
    builds (its ``info`` carries ``slam_pose``), so that on the perfect map the expert is its
    version before, mission for mission; ``"all"``, on every map."""

    def applies(self, info: Mapping[str, Any], maps: str = "slam") -> bool:
        """Whether it reads the map of the env whose reset ``info`` this is.

        Raises:
            ValueError: ``maps`` is not one of :data:`SLIVER_MAPS`.
        """
        if maps not in SLIVER_MAPS:
            raise ValueError(f"sliver_maps must be one of {SLIVER_MAPS}, got {maps!r}")
        return maps == "all" or SLAM_INFO_MARK in info


class MapReader:
    """One episode's reading of the observed map: the grid with its wall slivers filled.

    The reading changes only where the observed map changed: the last observed map is kept as
    a copy (so a map the env shares and updates in place is read right), and after a change the
    mask is computed again over the changed cells' box and the cells it reaches
    (:func:`~semexplore_gym.core.frontiers.wall_slivers.wall_sliver_mask_box`); a change over
    more than half the grid (a SLAM loop closure re-renders it all) reads the whole grid again.
    The reading is the same as reading the whole grid each time, cell for cell (tested).
    """

    def __init__(self, max_width_m: float, resolution_m: float, wall_gap_cells: int = 2) -> None:
        self.max_width_cells = float(max_width_m) / float(resolution_m)
        self.wall_gap_cells = int(wall_gap_cells)
        self._reach = sliver_context_cells(self.max_width_cells, self.wall_gap_cells)
        self._raw: np.ndarray | None = None
        self._filled: np.ndarray | None = None

    def _read_all(self, grid: np.ndarray) -> None:
        self._raw = np.array(grid, copy=True)
        self._filled = self._raw.copy()
        self._filled[wall_sliver_mask(self._raw, self.max_width_cells, self.wall_gap_cells)] = (
            OCCUPIED
        )

    def __call__(self, grid: np.ndarray) -> np.ndarray:
        raw, filled = self._raw, self._filled
        if raw is None or filled is None or raw.shape != grid.shape:
            self._read_all(grid)
        else:
            changed = raw != grid
            rows = np.flatnonzero(changed.any(axis=1))
            if rows.size:
                cols = np.flatnonzero(changed.any(axis=0))
                h, w = grid.shape
                r0, r1 = max(0, rows[0] - self._reach), min(h, rows[-1] + self._reach + 1)
                c0, c1 = max(0, cols[0] - self._reach), min(w, cols[-1] + self._reach + 1)
                if 2 * (r1 - r0) * (c1 - c0) > h * w:
                    self._read_all(grid)
                else:
                    np.copyto(raw, grid)
                    box = raw[r0:r1, c0:c1]
                    mask = wall_sliver_mask_box(
                        raw, (r0, r1), (c0, c1), self.max_width_cells, self.wall_gap_cells
                    )
                    filled[r0:r1, c0:c1] = np.where(mask, np.uint8(OCCUPIED), box)
        assert self._filled is not None
        return self._filled
