"""ROS ``map_server`` maps: a ``.yaml`` metadata file plus a greyscale image.

Keys read from the yaml:

==================  ========  ==================================================================
key                 required  meaning
==================  ========  ==================================================================
``image``           yes       image file, relative to the yaml's directory (an absolute path that
                              does not exist falls back to its basename next to the yaml)
``resolution``      yes       metres per (square) cell, > 0
``origin``          yes       ``[x, y, yaw]`` of the lower-left corner of the image; yaw must be 0
``negate``          no (0)    0: white = free; 1: black = free
``occupied_thresh`` no (0.65)  occupied when p > occupied_thresh
``free_thresh``     no (0.196) free when p < free_thresh
``mode``            no        ``trinary`` (default), ``scale`` or ``raw``
==================  ========  ==================================================================

With grey value ``v`` in 0..255, ``p = (255 - v) / 255`` (``v / 255`` when negated). A cell is
occupied if ``p > occupied_thresh``, free if ``p < free_thresh`` and unknown otherwise. The
``scale`` and ``raw`` modes exist to publish graded occupancy probabilities, which a
simulator cannot use (a wall is there or not), so they are read with the same trinary
thresholds. RGB(A) images use the mean of R, G and B (alpha is ignored: in the maps we know it
only carries anti-aliasing); 16-bit images are scaled to 0..255. Image row 0 is the *top*
(largest y) of the map, so rows are flipped into the row-grows-with-y convention.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image

from semexplore_gym.config.loading import load_yaml_file
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.validation import one_line, short_repr
from semexplore_gym.core.worlds.build import (
    DEFAULT_MIN_FREE_CELLS,
    MAX_WORLD_CELLS,
    WorldTooLargeError,
    world_from_free_mask,
)
from semexplore_gym.core.worlds.world import World

_MODES = ("trinary", "scale", "raw")


@dataclass(frozen=True)
class RosMapMetadata:
    """The parsed contents of a map_server yaml.

    Attributes:
        yaml_path: The yaml file.
        image_path: The resolved image file (it exists).
        resolution_m: Cell edge in metres.
        origin_x_m: World x of the image's lower-left corner.
        origin_y_m: World y of the image's lower-left corner.
        negate: Whether black means free.
        occupied_thresh: Occupancy probability above which a cell is occupied.
        free_thresh: Occupancy probability below which a cell is free.
        mode: ``"trinary"``, ``"scale"`` or ``"raw"`` (all read as trinary).
    """

    yaml_path: Path
    image_path: Path
    resolution_m: float
    origin_x_m: float
    origin_y_m: float
    negate: bool
    occupied_thresh: float
    free_thresh: float
    mode: str


#: A map_server yaml holds a handful of keys; anything larger is not one.
MAX_MAP_YAML_BYTES = 64 << 10


#: Cell sizes accepted from a map yaml: a robot of ~0.1 m needs cells well below a metre.
MIN_RESOLUTION_M = 1e-3
MAX_RESOLUTION_M = 1.0
#: Largest origin coordinate (metres) kept exact enough in float64 at millimetre cells.
MAX_ORIGIN_M = 1e6


def _is_file(p: Path) -> bool:
    """``p.is_file()``, False instead of an OSError for a name too long or otherwise unusable."""
    try:
        return p.is_file()
    except (OSError, ValueError):
        return False


def _number(doc: dict, key: str, path: Path, default: float | None = None) -> float:
    if key not in doc:
        if default is None:
            raise ValueError(f"{path}: missing required key {key!r}")
        return default
    value = doc[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{path}: key {key!r} must be a number, got {short_repr(value)}")
    if not np.isfinite(value):
        raise ValueError(f"{path}: key {key!r} must be finite, got {short_repr(value)}")
    return float(value)


def read_ros_map_yaml(path: str | os.PathLike) -> RosMapMetadata:
    """Parse and check a map_server yaml, resolving its image path.

    Raises:
        FileNotFoundError: the yaml or its image does not exist (the message names both).
        ValueError: malformed yaml, a missing or ill-typed key, a non-positive resolution,
            a non-zero origin yaw, thresholds outside ``0 <= free <= occupied <= 1``, an unknown
            mode. The message names the file and the key.
    """
    yaml_path = Path(path)
    if not _is_file(yaml_path):
        raise FileNotFoundError(f"ROS map yaml not found: {short_repr(str(yaml_path), 200)}")
    doc = load_yaml_file(yaml_path, "ROS map yaml", max_bytes=MAX_MAP_YAML_BYTES)
    if not isinstance(doc, dict):
        raise ValueError(
            f"{yaml_path}: expected a mapping of map_server keys, got {type(doc).__name__}"
        )

    if "image" not in doc:
        raise ValueError(f"{yaml_path}: missing required key 'image'")
    image = doc["image"]
    if not isinstance(image, str) or not image.strip():
        raise ValueError(f"{yaml_path}: key 'image' must be a file name, got {short_repr(image)}")
    image_path = _resolve_image(yaml_path, image.strip())

    resolution_m = _number(doc, "resolution", yaml_path)
    if not (MIN_RESOLUTION_M <= resolution_m <= MAX_RESOLUTION_M):
        raise ValueError(
            f"{yaml_path}: key 'resolution' must be positive, between {MIN_RESOLUTION_M} and "
            f"{MAX_RESOLUTION_M} m per cell, got {resolution_m!r}"
        )

    origin = _origin(doc, yaml_path)

    negate_raw = doc.get("negate", 0)
    if negate_raw not in (0, 1):
        raise ValueError(f"{yaml_path}: key 'negate' must be 0 or 1, got {short_repr(negate_raw)}")
    occupied_thresh = _number(doc, "occupied_thresh", yaml_path, default=0.65)
    free_thresh = _number(doc, "free_thresh", yaml_path, default=0.196)
    if not (0.0 <= free_thresh <= occupied_thresh <= 1.0):
        raise ValueError(
            f"{yaml_path}: keys 'free_thresh' ({free_thresh}) and 'occupied_thresh' ({occupied_thresh}) "
            "must satisfy 0 <= free_thresh <= occupied_thresh <= 1"
        )
    mode = doc.get("mode", "trinary")
    if not isinstance(mode, str) or mode.strip().lower() not in _MODES:
        raise ValueError(
            f"{yaml_path}: key 'mode' must be one of {', '.join(_MODES)}, got {short_repr(mode)}"
        )
    return RosMapMetadata(
        yaml_path=yaml_path,
        image_path=image_path,
        resolution_m=resolution_m,
        origin_x_m=float(origin[0]),
        origin_y_m=float(origin[1]),
        negate=bool(negate_raw),
        occupied_thresh=occupied_thresh,
        free_thresh=free_thresh,
        mode=mode.strip().lower(),
    )


def _origin(doc: dict, yaml_path: Path) -> list | tuple:
    """The yaml's ``origin``, checked: ``[x, y]`` or ``[x, y, 0]`` finite numbers near 0."""
    if "origin" not in doc:
        raise ValueError(f"{yaml_path}: missing required key 'origin'")
    origin = doc["origin"]
    if (
        not isinstance(origin, (list, tuple))
        or len(origin) not in (2, 3)
        or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
            for v in origin
        )
    ):
        raise ValueError(
            f"{yaml_path}: key 'origin' must be [x, y, yaw] numbers, got {short_repr(origin)}"
        )
    if max(abs(float(v)) for v in origin[:2]) > MAX_ORIGIN_M:
        raise ValueError(
            f"{yaml_path}: key 'origin' {short_repr(origin)} is more than {MAX_ORIGIN_M:g} m "
            "from 0 (float precision); move the origin"
        )
    if len(origin) == 3 and abs(float(origin[2])) > 1e-9:
        raise ValueError(
            f"{yaml_path}: key 'origin' has yaw {short_repr(origin[2])}; only yaw 0 maps are supported"
        )
    return origin


def _resolve_image(yaml_path: Path, image: str) -> Path:
    given = Path(image)
    candidates = [given] if given.is_absolute() else [yaml_path.parent / given]
    # A yaml copied from another computer often keeps its author's absolute image path.
    fallback = yaml_path.parent / given.name
    if fallback not in candidates:
        candidates.append(fallback)
    for candidate in candidates:
        if _is_file(candidate):
            return candidate
    tried = ", ".join(short_repr(str(c), 120) for c in candidates)
    raise FileNotFoundError(f"{yaml_path}: image {short_repr(image)} not found (tried {tried})")


def read_grey_image(path: str | os.PathLike) -> np.ndarray:
    """Grey values of an image file, as stored (row 0 = top of the image).

    Returns:
        ``(H, W)`` grey values in 0..255: the uint8 pixels of an 8-bit greyscale image as they
        are, otherwise float32 (RGB(A): the mean of R, G and B, alpha ignored; 16-bit: scaled).
    """
    try:
        with warnings.catch_warnings(), Image.open(path) as im:
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            # Checked before decoding: a small compressed file can hold a huge image.
            w, h = im.size
            if w * h > MAX_WORLD_CELLS:
                raise WorldTooLargeError(
                    f"{path}: image of {w} x {h} pixels is more than the {MAX_WORLD_CELLS:,} "
                    "pixel limit; crop it or scale it down (and scale the yaml's resolution up)"
                )
            im.load()
            mode = im.mode
            if mode in ("P", "PA"):
                im = im.convert("RGBA")
                mode = "RGBA"
            elif mode in ("1", "LA"):
                im = im.convert("L")
                mode = "L"
            arr = np.asarray(im)
    except WorldTooLargeError:
        raise
    except Exception as exc:  # noqa: BLE001 - PIL raises many types on a corrupt file
        raise ValueError(
            f"{path}: cannot read image: {type(exc).__name__}: {one_line(str(exc))}"
        ) from None
    if mode == "L":
        grey = arr
    elif mode in ("RGB", "RGBA", "RGBX"):
        grey = arr[..., :3].astype(np.float32).mean(axis=-1)
    elif mode.startswith("I"):
        # 16-bit (or 32-bit integer) greys: scale the type's range onto 0..255.
        top = (
            65535.0
            if (mode.startswith("I;16") or arr.max(initial=0) <= 65535)
            else float(arr.max())
        )
        grey = arr.astype(np.float32) * np.float32(255.0 / top)
    elif mode == "F":
        grey = np.clip(arr.astype(np.float32), 0.0, 255.0)
    else:
        raise ValueError(f"{path}: unsupported image mode {mode!r}")
    if grey.ndim != 2 or grey.size == 0:
        raise ValueError(f"{path}: expected a 2-D image, got shape {grey.shape}")
    return grey


def load_ros_map(path: str | os.PathLike) -> tuple[np.ndarray, GridGeometry]:
    """Read a map_server map as an encoded grid.

    Args:
        path: The ``.yaml`` file.

    Returns:
        ``(grid, geometry)``: ``grid`` is ``(H, W)`` uint8 with FREE / OCCUPIED / UNKNOWN
        (see :mod:`semexplore_gym.core.grid`), row 0 = lowest y; ``geometry`` its frame.
    """
    meta = read_ros_map_yaml(path)
    return _encode(meta)


def _classify(grey: np.ndarray, meta: RosMapMetadata) -> np.ndarray:
    p = grey / np.float32(255.0) if meta.negate else (np.float32(255.0) - grey) / np.float32(255.0)
    out = np.full(grey.shape, UNKNOWN, dtype=np.uint8)
    out[p > meta.occupied_thresh] = OCCUPIED
    out[p < meta.free_thresh] = FREE
    return out


def _encode(meta: RosMapMetadata) -> tuple[np.ndarray, GridGeometry]:
    grey = read_grey_image(meta.image_path)
    if grey.dtype == np.uint8:
        # 256-entry table: the same float rule as below, applied once per grey level.
        table = _classify(np.arange(256, dtype=np.float32)[None, :], meta)[0]
        grid = table[grey[::-1]]
    else:
        grid = _classify(grey[::-1], meta)
    geometry = GridGeometry(
        meta.resolution_m, meta.origin_x_m, meta.origin_y_m, grid.shape[0], grid.shape[1]
    )
    return grid, geometry


def load_ros_map_world(
    path: str | os.PathLike,
    name: str | None = None,
    *,
    min_free_cells: int = DEFAULT_MIN_FREE_CELLS,
) -> World:
    """A raster :class:`World` from a map_server map.

    Only FREE cells are free space; occupied and unknown cells are obstacles, so the map is
    closed. ``metadata`` holds the yaml fields and the free / occupied / unknown fractions of
    the whole image.
    """
    meta = read_ros_map_yaml(path)
    grid, geometry = _encode(meta)
    n = grid.size
    metadata = {
        "source": "ros_map",
        "yaml_path": str(meta.yaml_path),
        "image_path": str(meta.image_path),
        "resolution_m": meta.resolution_m,
        "origin_m": (meta.origin_x_m, meta.origin_y_m),
        "negate": meta.negate,
        "occupied_thresh": meta.occupied_thresh,
        "free_thresh": meta.free_thresh,
        "mode": meta.mode,
        "image_shape": grid.shape,
        "free_fraction": float(np.count_nonzero(grid == FREE)) / n,
        "occupied_fraction": float(np.count_nonzero(grid == OCCUPIED)) / n,
        "unknown_fraction": float(np.count_nonzero(grid == UNKNOWN)) / n,
    }
    return world_from_free_mask(
        name if name is not None else str(path),
        grid == FREE,
        geometry,
        metadata=metadata,
        min_free_cells=min_free_cells,
    )
