"""DungeonMaps (Chen et al. 2019, "Self-Learning Exploration and Mapping for Mobile Robots via
Deep Reinforcement Learning"): the learning community's exploration maps, as worlds.

Each map is a 640 x 480 px RGB(A) PNG with three colours:

==================  ==================  =====================================================
colour (R, G, B)    meaning             here
==================  ==================  =====================================================
(127, 127, 127)     wall / outside      obstacle
(195, 195, 194)     free space          free
(255, 216, 0)       start marker        free; its centroid is the world's start position
anything else       (not in the data)   obstacle, counted in ``metadata["other_pixels"]``
==================  ==================  =====================================================

Alpha is ignored (every published map is opaque). Their own simulator reads the same split
(grey level above 150 is free, so the marker is free too) and starts the robot on the marker.
The start heading is 0 (their robot has none). Image row 0 is the top of the map, flipped into
the row-grows-with-y convention, with the lower-left image corner at (0, 0).

**Scale.** Their robot senses 80 px around it; at the default :data:`DUNGEON_M_PER_PX`
(0.04375 m per pixel) that is our LiDAR's 3.5 m, so a map is 28 x 21 m. The scale is a parameter
(``m_per_px``; in a world spec ``map:dungeon-test-img-9900,m_per_px=0.05``).
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
from PIL import Image
from scipy import ndimage

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.validation import one_line
from semexplore_gym.core.worlds.build import (
    DEFAULT_MIN_FREE_CELLS,
    MAX_WORLD_CELLS,
    WorldTooLargeError,
    world_from_free_mask,
)
from semexplore_gym.core.worlds.world import World

#: Metres per pixel: their 80 px sensor range becomes our 3.5 m LiDAR range.
DUNGEON_M_PER_PX = 0.04375
#: Their sensor range in pixels (``sensor_range`` of their ``robot_simulation.py``).
DUNGEON_SENSOR_RANGE_PX = 80
WALL_RGB = (127, 127, 127)
FREE_RGB = (195, 195, 194)
START_RGB = (255, 216, 0)
#: Scales accepted: a pixel between a millimetre and half a metre.
MIN_M_PER_PX = 1e-3
MAX_M_PER_PX = 0.5


def read_dungeon_png(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """The RGB pixels of a DungeonMaps image, as stored (row 0 = top).

    Returns:
        ``(rgb, marker)``: ``(H, W, 3)`` uint8 and the ``(H, W)`` bool start-marker pixels.

    Raises:
        FileNotFoundError: no such file.
        ValueError: not an image Pillow can read, or too large.
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"DungeonMaps image not found: {p}")
    try:
        with warnings.catch_warnings(), Image.open(p) as im:
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            w, h = im.size  # checked before decoding: a small file can hold a huge image
            if w * h > MAX_WORLD_CELLS:
                raise WorldTooLargeError(
                    f"{p}: image of {w} x {h} pixels is more than the {MAX_WORLD_CELLS:,} "
                    "pixel limit"
                )
            rgb = np.asarray(im.convert("RGB"), dtype=np.uint8)
    except WorldTooLargeError:
        raise
    except Exception as exc:  # noqa: BLE001 - PIL raises many types on a corrupt file
        raise ValueError(
            f"{p}: cannot read image: {type(exc).__name__}: {one_line(str(exc))}"
        ) from None
    marker = np.all(rgb == np.array(START_RGB, dtype=np.uint8), axis=-1)
    return rgb, marker


def _start_xy(marker: np.ndarray, geometry: GridGeometry, path: Path) -> tuple[float, float]:
    """Centroid of the largest 8-connected blob of marker pixels (rows already flipped)."""
    labels, n = ndimage.label(marker, structure=np.ones((3, 3), dtype=bool))
    if n == 0:
        raise ValueError(
            f"{path}: no start marker (pixels of colour {START_RGB}); not a DungeonMaps image"
        )
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    rows, cols = np.nonzero(labels == int(np.argmax(sizes)))
    x, y = geometry.grid_to_world(float(rows.mean()), float(cols.mean()))
    return float(x), float(y)


def load_dungeon_map_world(
    path: str | os.PathLike,
    name: str | None = None,
    *,
    m_per_px: float = DUNGEON_M_PER_PX,
    min_free_cells: int = DEFAULT_MIN_FREE_CELLS,
) -> World:
    """A raster :class:`World` from a DungeonMaps PNG, starting on its marker (see the module
    docstring for the colours).

    Args:
        path: The ``.png`` file.
        name: World name (default: the path).
        m_per_px: Metres per pixel (default 0.04375: their 80 px sensor range is 3.5 m).
        min_free_cells: Free specks smaller than this are dropped.

    Raises:
        FileNotFoundError: no such file.
        ValueError: unreadable image, no start marker, no free space, a scale out of range.
    """
    m = float(m_per_px)
    if not MIN_M_PER_PX <= m <= MAX_M_PER_PX:
        raise ValueError(
            f"m_per_px must be in [{MIN_M_PER_PX}, {MAX_M_PER_PX}] m per pixel, got {m_per_px!r}"
        )
    p = Path(path)
    rgb, marker = read_dungeon_png(p)
    rgb, marker = rgb[::-1], marker[::-1]  # row 0 = lowest y
    is_free = np.all(rgb == np.array(FREE_RGB, dtype=np.uint8), axis=-1)
    is_wall = np.all(rgb == np.array(WALL_RGB, dtype=np.uint8), axis=-1)
    free = is_free | marker
    geometry = GridGeometry(m, 0.0, 0.0, free.shape[0], free.shape[1])
    x, y = _start_xy(marker, geometry, p)
    metadata = {
        "source": "dungeon_maps",
        "path": str(p),
        "m_per_px": m,
        "image_shape": free.shape,
        "sensor_range_m": DUNGEON_SENSOR_RANGE_PX * m,
        "free_fraction": float(free.mean()),
        "other_pixels": int(np.count_nonzero(~(free | is_wall))),
    }
    return world_from_free_mask(
        name if name is not None else str(p),
        free,
        geometry,
        start_pose=(x, y, 0.0),
        metadata=metadata,
        min_free_cells=min_free_cells,
    )


__all__ = ["DUNGEON_M_PER_PX", "load_dungeon_map_world", "read_dungeon_png"]
