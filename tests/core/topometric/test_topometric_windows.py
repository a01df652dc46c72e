"""The segmentation's shortcuts for large, mostly unknown maps give the same results.

* ``scan_grid`` (eight cells at a time) equals the cell-by-cell ``scan_grid_cells``;
* the area raster kept as its labelled window (:class:`AreaRasterCrop`) reads like the full
  raster, point by point and once built;
* area ids matched by cell (same grid frame) equal those matched through world points.
"""

from __future__ import annotations

import dataclasses
import pickle

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.topometric import TopometricSegmenter, segment_map
from semexplore_gym.core.topometric.kernels.clean import scan_grid, scan_grid_cells
from semexplore_gym.core.topometric.stages import SegmentationStages
from semexplore_gym.core.topometric.types import AreaRasterCrop

CLEARANCE_M = 0.155


def _random_grid(rng: np.random.Generator) -> np.ndarray:
    h, w = int(rng.integers(1, 70)), int(rng.integers(1, 110))
    g = np.full((h, w), UNKNOWN, np.uint8)
    for _ in range(int(rng.integers(0, 5))):
        r, c = int(rng.integers(h)), int(rng.integers(w))
        g[r : r + int(rng.integers(1, 6)), c : c + int(rng.integers(1, 12))] = rng.choice(
            [FREE, OCCUPIED]
        )
    if rng.random() < 0.25:
        g[int(rng.integers(h)), int(rng.integers(w))] = rng.integers(0, 256)
    return g


def test_scan_grid_equals_the_cell_by_cell_pass() -> None:
    rng = np.random.default_rng(11)
    for _ in range(1500):
        g = _random_grid(rng)
        buf = np.zeros(g.size + 3, np.uint8)
        shifted = buf[3:].reshape(g.shape)  # data not word-aligned
        shifted[:] = g
        expected = scan_grid_cells(g)
        assert scan_grid(g) == expected
        assert scan_grid(shifted) == expected


def _exploration_chain(origin: tuple[float, float]) -> tuple[GridGeometry, list[np.ndarray]]:
    """A 260 x 240 map of crossing corridors revealed in growing discs (mostly unknown)."""
    rng = np.random.default_rng(5)
    full = np.full((260, 240), OCCUPIED, np.uint8)
    for s in range(30, 230, 45):
        full[s : s + 9, 10:230] = FREE
        full[10:250, s : s + 9] = FREE
    for _ in range(8):
        r, c = int(rng.integers(20, 240)), int(rng.integers(20, 220))
        full[r : r + 3, c : c + 3] = OCCUPIED
    rr, cc = np.mgrid[:260, :240]
    grids = []
    for radius in (25, 40, 60, 85, 110, 140):
        seen = (rr - 70) ** 2 + (cc - 60) ** 2 <= radius**2
        grids.append(np.where(seen, full, UNKNOWN).astype(np.uint8))
    return GridGeometry(0.05, origin[0], origin[1], 260, 240), grids


def test_area_raster_window_reads_like_the_full_raster() -> None:
    geo, grids = _exploration_chain((-3.21, 7.4))
    seg = TopometricSegmenter()
    prev = None
    for g in grids:
        m = seg(g, geo, CLEARANCE_M, previous=prev)
        prev = m
        window = m.__dict__["_area_ids"]
        assert isinstance(window, AreaRasterCrop)
        assert window.ids.size < g.size  # only the explored part is labelled
        lazy = pickle.loads(pickle.dumps(m))  # still a window after the round trip
        assert isinstance(lazy.__dict__["_area_ids"], AreaRasterCrop)
        cells = window.labelled_cells()
        rows, cols = np.mgrid[: g.shape[0], : g.shape[1]]
        ids_at = m.area_ids_at(rows.ravel(), cols.ravel())
        # points off the labelled window, then the nearest-cell fallback, before and after
        pts = [(-3.21 + 0.05 * c, 7.4 + 0.05 * r) for r, c in ((0, 0), (130, 120), (259, 5))]
        before = [lazy.area_at(x, y) for x, y in pts]
        full = m.area_ids  # built now
        assert full.shape == g.shape and full.dtype == np.int32
        assert isinstance(m.__dict__["_area_ids"], np.ndarray)
        assert np.array_equal(ids_at, full.ravel())
        assert np.array_equal(cells, np.argwhere(full >= 0))
        assert np.array_equal(lazy.area_ids, full)
        plain = dataclasses.replace(m, area_ids=full.copy())
        assert before == [plain.area_at(x, y) for x, y in pts]
        ref = segment_map(g, geo, CLEARANCE_M, previous=None)
        assert np.array_equal(full >= 0, ref.area_ids >= 0)


@pytest.mark.parametrize("origin", [(0.0, 0.0), (-3.21, 7.4), (1234.567, -89.01)])
def test_ids_matched_by_cell_equal_ids_matched_by_world_point(monkeypatch, origin) -> None:
    geo, grids = _exploration_chain(origin)

    def chain() -> list:
        seg, prev, out = TopometricSegmenter(), None, []
        for g in grids:
            prev = seg(g, geo, CLEARANCE_M, previous=prev)
            out.append(
                (
                    prev.area_ids.copy(),
                    {k: (a.type, a.centre_m) for k, a in prev.areas.items()},
                    prev.extras["next_area_id"],
                )
            )
        return out

    by_cell = chain()
    monkeypatch.setattr(SegmentationStages, "_same_frame", lambda self, other: False)
    by_point = chain()
    for (ra, aa, na), (rb, ab, nb) in zip(by_cell, by_point, strict=True):
        assert np.array_equal(ra, rb) and aa == ab and na == nb
