"""ROS map_server and HouseExpo loaders, raster <-> segment conversion, on tiny hand-made inputs."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, parse_ascii_grid
from semexplore_gym.core.worlds import (
    load_houseexpo_world,
    load_ros_map,
    make_world,
    raster_to_segments,
    rasterize_free,
    world_from_free_mask,
)
from semexplore_gym.core.worlds.geometry import merge_polyline_edges


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _segments_intersect(p0, p1, q0, q1) -> bool:
    """Closed segments p0-p1 and q0-q1 share a point (independent of the package's kernels)."""
    p0, p1, q0, q1 = (np.asarray(v, dtype=float) for v in (p0, p1, q0, q1))
    d1 = _cross(p1 - p0, q0 - p0)
    d2 = _cross(p1 - p0, q1 - p0)
    d3 = _cross(q1 - q0, p0 - q0)
    d4 = _cross(q1 - q0, p1 - q0)
    if (
        ((d1 > 0) != (d2 > 0))
        and ((d3 > 0) != (d4 > 0))
        and d1 != 0
        and d2 != 0
        and d3 != 0
        and d4 != 0
    ):
        return True

    def on(a, b, c) -> bool:
        return (
            abs(_cross(b - a, c - a)) < 1e-12
            and min(a[0], b[0]) - 1e-12 <= c[0] <= max(a[0], b[0]) + 1e-12
            and (min(a[1], b[1]) - 1e-12 <= c[1] <= max(a[1], b[1]) + 1e-12)
        )

    return on(p0, p1, q0) or on(p0, p1, q1) or on(q0, q1, p0) or on(q0, q1, p1)


def _blocked(segments: np.ndarray, a, b) -> bool:
    return any(_segments_intersect(a, b, s[:2], s[2:]) for s in segments)


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


def test_one_pixel_wall_blocks_a_crossing() -> None:
    free = parse_ascii_grid(WALL_ROOM) == FREE
    geometry = GridGeometry(0.1, 0.0, 0.0, *free.shape)
    segments = raster_to_segments(free, geometry)
    # From the centre of free cell (row 2, col 5) to that of (row 4, col 5), across the wall.
    assert _blocked(segments, (0.55, 0.25), (0.55, 0.45))
    # Around the wall's end (column 10 is free in rows 2..4) nothing is in the way.
    assert not _blocked(segments, (1.05, 0.25), (1.05, 0.45))


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


# --------------------------------------------------------------------------- ROS map_server


def _write_map(
    tmp_path: Path, pixels: np.ndarray, yaml_text: str, image_name: str = "m.pgm"
) -> Path:
    Image.fromarray(pixels).save(tmp_path / image_name)
    path = tmp_path / "m.yaml"
    path.write_text(yaml_text)
    return path


# Image rows, top first: 0 = black, 100 = dark grey, 205 = map_saver unknown, 254/255 = white.
PIXELS = np.array([[0, 100, 205], [254, 255, 0]], dtype=np.uint8)
YAML = "image: m.pgm\nresolution: 0.5\norigin: [1.0, -2.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"


def test_ros_trinary_thresholds_and_flip(tmp_path: Path) -> None:
    grid, geometry = load_ros_map(_write_map(tmp_path, PIXELS, YAML))
    assert geometry == GridGeometry(0.5, 1.0, -2.0, 2, 3)
    # Row 0 of the result is the image's *bottom* row. p(205) = 0.19608 > 0.196: unknown.
    assert grid.tolist() == [[FREE, FREE, OCCUPIED], [OCCUPIED, UNKNOWN, UNKNOWN]]


def test_ros_negate_and_thresholds(tmp_path: Path) -> None:
    grid, _ = load_ros_map(_write_map(tmp_path, PIXELS, YAML.replace("negate: 0", "negate: 1")))
    assert grid.tolist() == [[OCCUPIED, OCCUPIED, FREE], [FREE, UNKNOWN, OCCUPIED]]
    loose = YAML.replace("free_thresh: 0.196", "free_thresh: 0.25")
    grid, _ = load_ros_map(_write_map(tmp_path, PIXELS, loose))
    assert grid[1].tolist() == [OCCUPIED, UNKNOWN, FREE]


def test_ros_rgb_uses_mean_and_modes_read_as_trinary(tmp_path: Path) -> None:
    rgb = np.zeros((1, 2, 3), dtype=np.uint8)
    rgb[0, 0] = (255, 255, 240)  # mean 250: free
    rgb[0, 1] = (255, 0, 0)  # mean 85: p = 0.67 > 0.65: occupied
    text = YAML.replace("m.pgm", "m.png") + "mode: scale\n"
    grid, _ = load_ros_map(_write_map(tmp_path, rgb, text, image_name="m.png"))
    assert grid.tolist() == [[FREE, OCCUPIED]]


def test_ros_absolute_image_path_falls_back_to_basename(tmp_path: Path) -> None:
    text = YAML.replace("image: m.pgm", "image: /home/someone/catkin_ws/maps/m.pgm")
    grid, _ = load_ros_map(_write_map(tmp_path, PIXELS, text))
    assert grid.shape == (2, 3)


@pytest.mark.parametrize(
    ("text", "error", "message"),
    [
        ("image: [m.pgm\nresolution: 0.5", ValueError, "m.yaml: malformed YAML"),
        ("- just\n- a list\n", ValueError, "m.yaml: expected a mapping"),
        (
            "resolution: 0.5\norigin: [0, 0, 0]\n",
            ValueError,
            "m.yaml: missing required key 'image'",
        ),
        (
            "image: m.pgm\norigin: [0, 0, 0]\n",
            ValueError,
            "m.yaml: missing required key 'resolution'",
        ),
        ("image: m.pgm\nresolution: 0.5\n", ValueError, "m.yaml: missing required key 'origin'"),
        (
            "image: m.pgm\nresolution: 0\norigin: [0, 0, 0]\n",
            ValueError,
            "key 'resolution' must be positive",
        ),
        (
            "image: m.pgm\nresolution: -1\norigin: [0, 0, 0]\n",
            ValueError,
            "key 'resolution' must be positive",
        ),
        (
            "image: m.pgm\nresolution: fine\norigin: [0, 0, 0]\n",
            ValueError,
            "key 'resolution' must be a number",
        ),
        ("image: m.pgm\nresolution: 0.5\norigin: [0, 0, 0.3]\n", ValueError, "only yaw 0"),
        (
            "image: m.pgm\nresolution: 0.5\norigin: [0, 0, 0]\nnegate: 2\n",
            ValueError,
            "key 'negate' must be 0 or 1",
        ),
        (
            "image: m.pgm\nresolution: 0.5\norigin: [0, 0, 0]\nmode: fuzzy\n",
            ValueError,
            "key 'mode' must be one of",
        ),
        (
            "image: m.pgm\nresolution: 0.5\norigin: [0, 0, 0]\nfree_thresh: 0.9\noccupied_thresh: 0.5\n",
            ValueError,
            "must satisfy 0 <= free_thresh <= occupied_thresh <= 1",
        ),
        (
            "image: other.pgm\nresolution: 0.5\norigin: [0, 0, 0]\n",
            FileNotFoundError,
            "image 'other.pgm' not found",
        ),
    ],
)
def test_ros_yaml_errors_name_file_and_key(
    tmp_path: Path, text: str, error: type, message: str
) -> None:
    path = _write_map(tmp_path, PIXELS, text)
    with pytest.raises(error, match=message):
        load_ros_map(path)


def test_ros_map_world_via_make_world(tmp_path: Path) -> None:
    pixels = np.full((6, 8), 205, dtype=np.uint8)  # unknown all round
    pixels[1:5, 1:7] = 254
    pixels[2, 3] = 0  # one occupied pixel inside
    path = _write_map(tmp_path, pixels, YAML.replace("resolution: 0.5", "resolution: 0.1"))
    world = make_world(path)
    assert world.name == str(path)
    assert world.free_space_source == "raster"
    assert world.free_mask.sum() == 4 * 6 - 1
    # Outer boundary (4) + the 4 sides of the one-pixel obstacle.
    assert world.n_segments == 8
    assert world.bounds_m == pytest.approx((1.1, -1.9, 1.7, -1.5))
    assert world.metadata["unknown_fraction"] == pytest.approx(1 - 24 / 48)


# --------------------------------------------------------------------------- HouseExpo JSON


def _plan(tmp_path: Path, verts: list) -> Path:
    doc = {
        "id": "0" * 32,
        "room_num": 2,
        "bbox": {"min": [0, 0], "max": [4, 3]},
        "verts": verts,
        "room_category": {"Bedroom": [[0, 0, 2, 3]], "Kitchen": [[2, 0, 4, 3]]},
    }
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(doc))
    return path


# A 4 x 3 m house, clockwise, with a 0.1 m thick interior wall slit from the bottom up to
# y = 2.0 at x = 1.95..2.05, and an extra collinear vertex in the top edge.
SLIT_HOUSE = [
    [0, 0],
    [0, 3],
    [2, 3],
    [4, 3],
    [4, 0],
    [2.05, 0],
    [2.05, 2.0],
    [1.95, 2.0],
    [1.95, 0],
]


def test_houseexpo_polygon_with_slit(tmp_path: Path) -> None:
    world = load_houseexpo_world(_plan(tmp_path, SLIT_HOUSE), resolution_m=0.025)
    assert world.free_space_source == "vector"
    assert world.n_segments == 8  # the collinear top vertex is merged away
    assert world.bounds_m == (0.0, 0.0, 4.0, 3.0)
    assert world.metadata["room_category"]["Kitchen"] == [[2, 0, 4, 3]]
    assert world.metadata["polygon_area_m2"] == pytest.approx(12.0 - 0.2)
    # Every vertex lies on a cell edge of the 0.025 m grid, so the free cells tile the polygon.
    assert world.free_mask.sum() == round(11.8 / 0.025**2)
    # The slit wall separates left and right below y = 2.0 (its inside is not free) ...
    g = world.free_geometry
    rows, cols = g.world_to_grid(np.array([1.9, 2.0, 2.1]), np.full(3, 1.0))
    assert world.free_mask[rows, cols].tolist() == [True, False, True]
    assert _blocked(world.segments_m, (1.9, 1.0), (2.1, 1.0))
    assert not _blocked(world.segments_m, (1.9, 2.5), (2.1, 2.5))
    # ... and on another grid too.
    coarse = GridGeometry(0.1, -0.3, -0.3, 36, 46)
    free = rasterize_free(world, coarse)
    r, c = coarse.world_to_grid(2.0, 1.0)
    assert (
        not free[r, c]
        and free[coarse.world_to_grid(1.5, 1.0)]
        and free[coarse.world_to_grid(2.5, 1.0)]
    )
    assert not free[[0, -1]].any() and not free[:, [0, -1]].any()


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("{not json", "malformed JSON"),
        ('{"id": "x"}', "missing required key 'verts'"),
        ('{"verts": [[0, 0], [1, 1]]}', "at least 3"),
        ('{"verts": [[0, 0], [1, "a"], [2, 2]]}', "must be a list of"),
    ],
)
def test_houseexpo_errors(tmp_path: Path, content: str, message: str) -> None:
    path = tmp_path / "bad.json"
    path.write_text(content)
    with pytest.raises(ValueError, match=message):
        load_houseexpo_world(path)


def test_merge_polyline_edges() -> None:
    # Square with stair-free straight runs split into many vertices, and a repeated vertex.
    verts = [[0, 0], [0, 1], [0, 2], [0, 2], [1, 2], [2, 2], [2, 1], [2, 0], [1, 0]]
    segs = merge_polyline_edges(verts, closed=True)
    assert sorted(map(tuple, segs.tolist())) == sorted(
        [(0.0, 0.0, 0.0, 2.0), (0.0, 2.0, 2.0, 2.0), (2.0, 2.0, 2.0, 0.0), (2.0, 0.0, 0.0, 0.0)]
    )
    # A spike (going out and straight back) is not merged.
    assert len(merge_polyline_edges([[0, 0], [2, 0], [1, 0], [1, 1]], closed=True)) == 4
