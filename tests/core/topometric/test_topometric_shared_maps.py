"""Every ROS map in ``../shared/maps`` segments without error into a consistent map."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE
from semexplore_gym.core.topometric import AreaType, SegmentationParams, segment_map

MAPS = Path(__file__).resolve().parents[3] / ".." / "shared" / "maps"
FILES = sorted(MAPS.rglob("*.yaml")) if MAPS.is_dir() else []
CLEARANCE_M = 0.155
SMALL_CELLS = 1_000_000  # maps above this run in the slow test


def _load(path: Path):
    from semexplore_gym.maps.ros_map import load_ros_map

    return load_ros_map(path)


def _check(path: Path) -> None:
    grid, geometry = _load(path)
    m = segment_map(grid, geometry, CLEARANCE_M, params=SegmentationParams(keep_debug=True))
    r0, c0, filtered = m.extras["filtered_grid_crop"]  # the grid after the noise filter
    assert m.areas, path
    labelled = m.area_ids >= 0
    # only erased specks and closed unknown holes (the noise filter) may be labelled besides free cells
    assert (grid[labelled] != FREE).sum() <= 0.02 * labelled.sum()
    assert [o.id for o in m.openings] == list(range(len(m.openings)))
    for a in m.areas.values():
        for oid in a.opening_ids:
            assert a.id in m.openings[oid].area_ids
        if a.type == AreaType.INTERSECTION:
            assert len(a.opening_ids) >= 3
    for f in m.frontiers:
        assert m.areas[f.area_id].type == AreaType.FRONTIER_PATHWAY
        r, c = geometry.world_to_grid(*f.midpoint_m)
        assert filtered[int(r) - r0, int(c) - c0] == FREE
    assert np.isfinite([e.length_m for e in m.edges]).all()


def _ids(files):
    return [str(p.relative_to(MAPS)) for p in files]


@pytest.mark.shared_maps
@pytest.mark.skipif(
    not FILES, reason=f"shared maps not found at {MAPS} (../shared beside the repository)"
)
@pytest.mark.parametrize(
    "path",
    [p for p in FILES if p.stat().st_size < 400_000],
    ids=_ids([p for p in FILES if p.stat().st_size < 400_000]),
)
def test_shared_map_segments(path):
    grid, _ = _load(path)
    if grid.size > SMALL_CELLS:
        pytest.skip("large map: covered by the slow test")
    _check(path)


@pytest.mark.slow
@pytest.mark.shared_maps
@pytest.mark.skipif(
    not FILES, reason=f"shared maps not found at {MAPS} (../shared beside the repository)"
)
def test_every_shared_map_segments():
    for path in FILES:
        _check(path)
