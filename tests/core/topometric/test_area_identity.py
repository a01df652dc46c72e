"""Stage 10 (identity) on hand-made previous maps: ids by skeleton overlap and by position."""

from __future__ import annotations

import numpy as np

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.topometric import Area, AreaType, TopometricMap
from semexplore_gym.core.topometric.area_identity import match_area_ids, next_area_id

RES_M = 0.5
GEO = GridGeometry(RES_M, 0.0, 0.0, 4, 6)


def _previous(area_ids: np.ndarray, areas: list[Area], next_id: int | None) -> TopometricMap:
    extras = {} if next_id is None else {"next_area_id": next_id}
    return TopometricMap(
        geometry=GEO,
        area_ids=area_ids,
        areas={a.id: a for a in areas},
        openings=[],
        frontiers=[],
        edges=[],
        mean_intersection_path_m=float("nan"),
        clearance_m=0.2,
        time_ms=0.0,
        extras=extras,
    )


def _area(area_id: int, kind: AreaType, centre_m: tuple[float, float], n_cells: int) -> Area:
    return Area(area_id, kind, centre_m, (), {}, n_cells)


def _cell_centres_m(cells: list[tuple[int, int]]) -> np.ndarray:
    return np.array([((c + 0.5) * RES_M, (r + 0.5) * RES_M) for r, c in cells])


# previous map: area 7 on columns 0-2 (area 5 in their top row), area 3 on columns 3-5
PREV_RASTER = np.full((4, 6), 7, dtype=np.int32)
PREV_RASTER[:, 3:] = 3
PREV_RASTER[3, :3] = 5
PREV_AREAS = [
    _area(7, AreaType.PATHWAY, (0.75, 1.0), 12),
    _area(3, AreaType.INTERSECTION, (2.25, 1.0), 12),
    _area(5, AreaType.DEAD_END, (0.75, 1.75), 3),
    _area(9, AreaType.FRONTIER_PATHWAY, (2.9, 1.9), 0),
]


def test_next_id_is_past_every_previous_id_and_the_recorded_counter():
    assert next_area_id(None) == 0
    assert next_area_id(_previous(PREV_RASTER, PREV_AREAS, None)) == 10
    assert next_area_id(_previous(PREV_RASTER, PREV_AREAS, 25)) == 25
    assert next_area_id(_previous(PREV_RASTER, [], 4)) == 4


def test_without_previous_ids_are_consecutive_from_zero():
    ids, next_id = match_area_ids(
        None, 2, 3, np.zeros((3, 2)), np.zeros(0, np.int64), np.zeros((0, 2)), 1.0
    )
    assert ids.tolist() == [0, 1, 2]
    assert next_id == 3


def test_regions_inherit_the_id_under_most_of_their_skeleton():
    prev = _previous(PREV_RASTER, PREV_AREAS, 12)
    # region 0 lies on area 3 (3 pixels), region 1 mostly on area 7 (3 pixels, 1 on area 3),
    # region 2 touches area 5 with a single pixel: too little to inherit an id
    cells = [(1, 3), (1, 4), (1, 5), (2, 0), (2, 1), (2, 2), (2, 3), (3, 0)]
    regions = np.array([0, 0, 0, 1, 1, 1, 1, 2], dtype=np.int64)
    ids, next_id = match_area_ids(
        prev, 3, 3, np.zeros((3, 2)), regions, _cell_centres_m(cells), 0.5
    )
    assert ids.tolist() == [3, 7, 12]
    assert next_id == 13


def test_an_id_goes_to_one_region_only():
    prev = _previous(PREV_RASTER, PREV_AREAS, 12)
    # both regions lie on area 7; the one with more overlap keeps it, the other gets a fresh id;
    # the winner keeps its first match although it also overlaps area 3 (less)
    cells = [(0, 0), (0, 1), (1, 0), (1, 1), (0, 2), (1, 2), (0, 3), (1, 3)]
    regions = np.array([1, 1, 1, 1, 0, 0, 1, 1], dtype=np.int64)
    ids, _ = match_area_ids(prev, 2, 2, np.zeros((2, 2)), regions, _cell_centres_m(cells), 0.5)
    assert ids.tolist() == [12, 7]


def test_zero_area_frontier_pathways_match_by_position_within_the_radius():
    prev = _previous(PREV_RASTER, PREV_AREAS, 12)
    centres = np.array([[0.0, 0.0], [3.0, 2.0], [3.0, 2.0]])
    empty = np.zeros(0, np.int64), np.zeros((0, 2))
    # provisional area 0 is a region, 1 and 2 zero-area frontier pathways at the same spot:
    # only the first takes the previous one's id
    ids, next_id = match_area_ids(prev, 1, 3, centres, *empty, 0.2)
    assert ids.tolist() == [12, 9, 13]
    assert next_id == 14
    # out of reach of the match radius: fresh id
    ids, _ = match_area_ids(prev, 1, 2, centres[:2], *empty, 0.1)
    assert ids.tolist() == [12, 13]
