"""Raster <-> segment conversion and polyline merging, on tiny hand-made inputs."""

from __future__ import annotations

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, GridGeometry, parse_ascii_grid
from semexplore_gym.core.worlds import (
    raster_to_segments,
    rasterize_free,
    world_from_free_mask,
)
from semexplore_gym.core.worlds.geometry import merge_polyline_edges

# --------------------------------------------------------------------------- raster -> segments

WALL_ROOM = """
############
#..........#
#..........#
#..........#
#.########.#
#..........#
#..........#
############
"""


def test_one_pixel_wall_gives_one_merged_segment_per_side() -> None:
    free = parse_ascii_grid(WALL_ROOM) == FREE
    geometry = GridGeometry(0.1, 0.0, 0.0, *free.shape)
    segments = raster_to_segments(free, geometry)
    # The inner wall is row 3 (counting from the bottom), columns 2..9: faces at y = 0.3 and 0.4.
    for y in (0.3, 0.4):
        on_face = np.isclose(segments[:, 1], y) & np.isclose(segments[:, 3], y)
        assert on_face.sum() == 1
        x0, _, x1, _ = segments[on_face][0]
        assert (min(x0, x1), max(x0, x1)) == pytest.approx((0.2, 1.0))
    # Outer boundary: 4 long sides; inner wall: 2 faces + 2 end caps.
    assert len(segments) == 8


def test_one_pixel_wall_blocks_a_crossing(segments_block) -> None:
    free = parse_ascii_grid(WALL_ROOM) == FREE
    geometry = GridGeometry(0.1, 0.0, 0.0, *free.shape)
    segments = raster_to_segments(free, geometry)
    # From the centre of free cell (row 2, col 5) to that of (row 4, col 5), across the wall.
    assert segments_block(segments, (0.55, 0.25), (0.55, 0.45))
    # Around the wall's end (column 10 is free in rows 2..4) nothing is in the way.
    assert not segments_block(segments, (1.05, 0.25), (1.05, 0.45))


def test_raster_outside_counts_as_obstacle_and_specks_are_dropped() -> None:
    grid = parse_ascii_grid(
        """
        ....#.
        ....#.
        ......
        ###.##
        #.#...
        ###...
        """
    )
    free = grid == FREE
    geometry = GridGeometry(1.0, 10.0, 20.0, *free.shape)
    world = world_from_free_mask("t", free, geometry, min_free_cells=2)
    # The single free cell at (row 1, col 1) is a speck: gone, and no walls around it.
    assert world.free_mask.sum() == free.sum() - 1
    assert not any(np.allclose(s, (11.0, 21.0, 12.0, 21.0)) for s in world.segments_m)
    # Free cells on the raster's edge get a wall on that edge.
    assert any(np.allclose(s, (10.0, 26.0, 14.0, 26.0)) for s in world.segments_m)
    assert world.bounds_m == (10.0, 20.0, 16.0, 26.0)
    # Resampled on its own (or the original) grid, a raster world gives back its mask.
    assert np.array_equal(rasterize_free(world, world.free_geometry), world.free_mask)
    expected = free.copy()
    expected[1, 1] = False
    assert np.array_equal(rasterize_free(world, geometry), expected)


@pytest.mark.parametrize("min_cells", [2, 4, 9])
def test_remove_small_free_components_matches_labelling(min_cells: int) -> None:
    from scipy import ndimage

    from semexplore_gym.core.worlds.raster import remove_small_free_components

    rng = np.random.default_rng(min_cells)
    four = ndimage.generate_binary_structure(2, 1)
    for _ in range(10):
        free = rng.random((30, 40)) > rng.uniform(0.3, 0.7)
        labels, _ = ndimage.label(free, structure=four)
        sizes = np.bincount(labels.ravel())
        keep = sizes >= min_cells
        keep[0] = False
        assert np.array_equal(remove_small_free_components(free, min_cells), keep[labels])


def test_every_boundary_unit_edge_has_exactly_one_free_side() -> None:
    rng = np.random.default_rng(0)
    free = rng.random((30, 40)) > 0.4
    geometry = GridGeometry(0.05, -1.0, 2.0, 30, 40)
    segments = raster_to_segments(free, geometry)
    padded = np.pad(free, 1)
    n_unit = 0
    for x0, y0, x1, y1 in segments:
        if y0 == y1:
            k = round((y0 - 2.0) / 0.05)
            for c in range(round((min(x0, x1) + 1.0) / 0.05), round((max(x0, x1) + 1.0) / 0.05)):
                assert padded[k, c + 1] != padded[k + 1, c + 1]
                n_unit += 1
        else:
            k = round((x0 + 1.0) / 0.05)
            for r in range(round((min(y0, y1) - 2.0) / 0.05), round((max(y0, y1) - 2.0) / 0.05)):
                assert padded[r + 1, k] != padded[r + 1, k + 1]
                n_unit += 1
    expected = np.count_nonzero(padded[1:] != padded[:-1]) + np.count_nonzero(
        padded[:, 1:] != padded[:, :-1]
    )
    assert n_unit == expected


def test_rasterize_free_thin_vector_wall_separates() -> None:
    square = [(0, 0, 1, 0), (1, 0, 1, 1), (1, 1, 0, 1), (0, 1, 0, 0)]
    geometry = GridGeometry(0.1, 0.0, 0.0, 10, 10)
    # A wall along x = 0.5 (on cell edges) from bottom to top splits the room.
    split = np.array(square + [(0.5, 0.0, 0.5, 1.0)], dtype=float)
    free = rasterize_free(split, geometry, interior_points_m=[(0.25, 0.5)])
    assert free[:, :5].all() and not free[:, 5:].any()
    # Stopping at y = 0.6 leaves a gap: both sides are free, except a one-cell line marking the
    # wall on its +x side.
    door = np.array(square + [(0.5, 0.0, 0.5, 0.6)], dtype=float)
    free = rasterize_free(door, geometry, interior_points_m=[(0.25, 0.5)])
    expected = np.ones((10, 10), dtype=bool)
    expected[:6, 5] = False
    assert np.array_equal(free, expected)
    with pytest.raises(ValueError, match="interior_points_m"):
        rasterize_free(door, geometry)


def test_merge_polyline_edges() -> None:
    # Square with stair-free straight runs split into many vertices, and a repeated vertex.
    verts = [[0, 0], [0, 1], [0, 2], [0, 2], [1, 2], [2, 2], [2, 1], [2, 0], [1, 0]]
    segs = merge_polyline_edges(verts, closed=True)
    assert sorted(map(tuple, segs.tolist())) == sorted(
        [(0.0, 0.0, 0.0, 2.0), (0.0, 2.0, 2.0, 2.0), (2.0, 2.0, 2.0, 0.0), (2.0, 0.0, 0.0, 0.0)]
    )
    # A spike (going out and straight back) is not merged.
    assert len(merge_polyline_edges([[0, 0], [2, 0], [1, 0], [1, 1]], closed=True)) == 4
