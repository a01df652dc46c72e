"""ROS map_server and HouseExpo loaders, on tiny hand-made files."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.worlds import rasterize_free
from semexplore_gym.maps import load_houseexpo_world, load_ros_map, make_world

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


def test_houseexpo_polygon_with_slit(tmp_path: Path, segments_block) -> None:
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
    assert segments_block(world.segments_m, (1.9, 1.0), (2.1, 1.0))
    assert not segments_block(world.segments_m, (1.9, 2.5), (2.1, 2.5))
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
