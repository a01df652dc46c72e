"""Every real map in ``<repo>/../shared/maps`` loads, with the statistics its README gives."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE
from semexplore_gym.core.worlds import (
    rasterize_free,
    sample_start_pose,
    validate_start_pose,
)
from semexplore_gym.core.worlds.geometry import crossed_links
from semexplore_gym.maps import load_ros_map, make_world

MAPS = Path(__file__).resolve().parents[2] / ".." / "shared" / "maps"

pytestmark = [
    pytest.mark.shared_maps,
    pytest.mark.skipif(not MAPS.is_dir(), reason=f"shared map collection not found at {MAPS}"),
]


def _map_files() -> list[Path]:
    if not MAPS.is_dir():
        return []
    return sorted(MAPS.rglob("*.yaml")) + sorted((MAPS / "houseexpo" / "json").glob("*.json"))


@pytest.fixture(scope="module")
def worlds() -> dict[str, object]:
    return {str(p.relative_to(MAPS)): make_world(p) for p in _map_files()}


def test_collection_is_complete() -> None:
    assert len(_map_files()) == 22


def test_every_map_loads(worlds: dict) -> None:
    for rel, world in worlds.items():
        assert world.n_segments > 0, rel
        assert world.free_mask.any(), rel
        xmin, ymin, xmax, ymax = world.bounds_m
        assert xmax > xmin and ymax > ymin, rel
        # Walls enclose free space: the mask's outer ring is never free.
        m = world.free_mask
        assert not (m[0].any() or m[-1].any() or m[:, 0].any() or m[:, -1].any()), rel


# Free / occupied / unknown percentages from shared/maps/README.md (rounded to 0.1 %).
README_STATS = {
    "turtlebot3/world/map.yaml": (5.4, 0.5, 94.1),
    "turtlebot3/office/map_office_raw.yaml": (38.9, 3.1, 58.0),
    "mas_domestic_robotics/brsu-c069/map.yaml": (14.0, 1.3, 84.7),
    "stage/cave.yaml": (97.9, 2.1, 0.0),
    "navigation2/depot.yaml": (96.8, 3.2, 0.0),
    "navigation2/warehouse.yaml": (84.5, 1.8, 13.7),
    "f1tenth_gym/stata_basement.yaml": (13.8, 86.2, 0.0),
    "stage_ros/willow-full.yaml": (43.6, 2.7, 53.8),
    "ipa_room_segmentation/intel_map.yaml": (56.3, 7.6, 36.1),
    "stage/SFU_1200x615.yaml": (91.3, 6.2, 2.5),
}


@pytest.mark.parametrize("rel", sorted(README_STATS))
def test_ros_fractions_match_readme(rel: str, worlds: dict) -> None:
    meta = worlds[rel].metadata
    got = (
        100 * meta["free_fraction"],
        100 * meta["occupied_fraction"],
        100 * meta["unknown_fraction"],
    )
    assert got == pytest.approx(README_STATS[rel], abs=0.06)


def test_image_orientation_and_origin() -> None:
    # skirk: outside the building is black, so the corners are occupied; its origin is as given.
    grid, geometry = load_ros_map(MAPS / "f1tenth_gym" / "skirk.yaml")
    assert geometry.shape == (602, 431)
    assert (geometry.origin_x_m, geometry.origin_y_m) == (-7.801, -16.388)
    from PIL import Image

    image = np.asarray(Image.open(MAPS / "f1tenth_gym" / "skirk.png"))
    # Row 0 of the grid is the image's last (bottom) row.
    assert np.array_equal(grid[0] == FREE, image[-1] > 250)
    assert np.array_equal(grid[-1] == FREE, image[0] > 250)


# HouseExpo rasters: free area in m^2 from the README (rounded to 1 m^2).
HOUSE_AREAS_M2 = {"1dfb7bd5d9a447175a9719096fbacea7": 39, "c4513f5dfd084681ed2d0c24e85b9cf7": 622}


@pytest.mark.parametrize("house", sorted(HOUSE_AREAS_M2))
def test_houseexpo_raster_areas(house: str, worlds: dict) -> None:
    world = worlds[f"houseexpo/png/{house}.yaml"]
    area = world.free_mask.sum() * world.free_geometry.resolution_m**2
    assert area == pytest.approx(HOUSE_AREAS_M2[house], abs=0.6)


def test_houseexpo_json(worlds: dict) -> None:
    world = worlds["houseexpo/json/house_expo_room_1451.json"]
    assert world.bounds_m == pytest.approx((0.1, 0.1, 11.38, 10.85))
    assert world.metadata["polygon_area_m2"] == pytest.approx(116.6, abs=0.05)
    assert world.metadata["room_num"] == 7 and "Living_Room" in world.metadata["room_category"]
    area = world.free_mask.sum() * world.free_geometry.resolution_m**2
    assert area == pytest.approx(116.6, rel=0.02)


def test_cave_one_pixel_outlines_stay_walls(worlds: dict) -> None:
    world = worlds["stage/cave.yaml"]
    free, geometry = world.free_mask, world.free_geometry
    cut_x, cut_y = crossed_links(world.segments_m, geometry)
    # Every link between a free and a non-free cell is crossed by a wall, and no link between
    # two free cells is.
    assert np.array_equal(cut_x, free[:, :-1] != free[:, 1:])
    assert np.array_equal(cut_y, free[:-1, :] != free[1:, :])
    # The outlines are thin (the README says 1 px; in the file they are mostly 2 px, 6.4 cm):
    # free | wall | wall | free runs are common, and walled on both sides.
    thin = free[:, :-3] & ~free[:, 1:-2] & ~free[:, 2:-1] & free[:, 3:]
    assert thin.sum() > 300
    r, c = np.nonzero(thin)
    assert cut_x[r, c].all() and cut_x[r, c + 2].all()
    # Resampled at 0.05 m (coarser than the 0.032 m pixels) no two free cells of the
    # resampled mask straddle a wall.
    from semexplore_gym.core.grid import GridGeometry

    coarse = GridGeometry.covering(*world.bounds_m, resolution_m=0.05, margin_m=0.1)
    f = rasterize_free(world, coarse)
    cx, cy = crossed_links(world.segments_m, coarse)
    assert not (cx & f[:, :-1] & f[:, 1:]).any()
    assert not (cy & f[:-1, :] & f[1:, :]).any()


@pytest.mark.parametrize("rel", ["turtlebot3/world/map.yaml", "f1tenth_gym/stata_basement.yaml"])
def test_start_sampling_on_real_maps(rel: str, worlds: dict) -> None:
    world = worlds[rel]
    rng = np.random.default_rng(0)
    for _ in range(5):
        pose = sample_start_pose(world, rng, 0.155)
        validate_start_pose(world, pose, 0.155)
