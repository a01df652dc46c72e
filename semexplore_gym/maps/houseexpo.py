"""HouseExpo floor plans (Li et al., "HouseExpo", arXiv:1903.09845) from the dataset's JSON.

A plan's ``verts`` are one simple polygon, the outline of the house's free space, given open
(the first vertex is not repeated) and in metres. There is no wall list: interior walls are
thin slits cut into the polygon (the outline runs along one face of a wall and back along the
other), doors are where a slit stops short, and everything outside the polygon is obstacle.
So the walls are exactly the polygon's edges; consecutive collinear edges are merged, but the
0.01 m stair-steps the dataset uses for diagonal walls are kept as they are.

Free space is the polygon's inside (even-odd rule at cell centres) minus the cells within half
a cell of a wall (with the tie rule of :func:`~semexplore_gym.core.worlds.raster.rasterize_free`). ``room_category`` boxes, ``id``, ``room_num`` and ``bbox`` go to
``metadata``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from semexplore_gym.config.loading import load_json_file
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.validation import one_line, short_repr
from semexplore_gym.core.worlds.build import (
    DEFAULT_VECTOR_RESOLUTION_M,
    check_wall_segments,
    check_world_cells,
)
from semexplore_gym.core.worlds.geometry import (
    crossed_links,
    merge_polyline_edges,
    polygon_inside_mask,
    segments_bounds_m,
)
from semexplore_gym.core.worlds.raster import cells_near_walls, mark_walls
from semexplore_gym.core.worlds.world import World

#: Largest coordinate of a plan (metres): a house is tens of metres across.
MAX_COORDINATE_M = 1e5


def read_houseexpo_json(path: str | os.PathLike) -> dict:
    """Read and check a HouseExpo JSON file.

    Returns:
        The parsed object, with ``verts`` converted to a ``(K, 2)`` float64 array.

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: not JSON, not an object, or ``verts`` missing or not >= 3 finite points.
    """
    p = Path(path)
    try:
        exists = p.is_file()
    except (OSError, ValueError):  # a name too long for the file system
        exists = False
    if not exists:
        raise FileNotFoundError(f"HouseExpo JSON not found: {short_repr(str(p), 200)}")
    doc = load_json_file(p, "HouseExpo JSON")
    if not isinstance(doc, dict):
        raise ValueError(
            f"{p}: expected a JSON object with a 'verts' key, got {type(doc).__name__}"
        )
    if "verts" not in doc:
        raise ValueError(f"{p}: missing required key 'verts'")
    try:
        verts = np.asarray(doc["verts"], dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ValueError(
            f"{p}: key 'verts' must be a list of [x, y] numbers: {one_line(str(exc))}"
        ) from None
    if verts.ndim != 2 or verts.shape[1] != 2 or verts.shape[0] < 3:
        raise ValueError(
            f"{p}: key 'verts' must hold at least 3 [x, y] points, got shape {verts.shape}"
        )
    if not np.isfinite(verts).all():
        raise ValueError(f"{p}: key 'verts' contains NaN or inf")
    if np.abs(verts).max() > MAX_COORDINATE_M:
        raise ValueError(
            f"{p}: key 'verts' has a coordinate beyond {MAX_COORDINATE_M:g} m "
            f"({np.abs(verts).max():.3g}); not a floor plan in metres"
        )
    out = dict(doc)
    out["verts"] = verts
    return out


def load_houseexpo_world(
    path: str | os.PathLike,
    name: str | None = None,
    *,
    resolution_m: float = DEFAULT_VECTOR_RESOLUTION_M,
) -> World:
    """A vector :class:`World` from a HouseExpo JSON plan.

    Args:
        path: The ``.json`` file.
        name: World name (default: the path).
        resolution_m: Resolution of the stored ground-truth ``free_mask``.
    """
    doc = read_houseexpo_json(path)
    verts = doc["verts"]
    segments = merge_polyline_edges(verts, closed=True, tol_m=1e-6)
    if segments.shape[0] < 3:
        raise ValueError(f"{path}: key 'verts' does not outline an area")
    bounds = segments_bounds_m(segments)
    check_wall_segments(str(path), segments.shape[0], resolution_m)
    check_world_cells(
        str(path),
        (bounds[3] - bounds[1]) / resolution_m + 3,
        (bounds[2] - bounds[0]) / resolution_m + 3,
        resolution_m,
    )
    geometry = GridGeometry.covering(*bounds, resolution_m=resolution_m, margin_m=resolution_m)
    inside = polygon_inside_mask(verts, geometry)
    free = mark_walls(
        inside & ~cells_near_walls(segments, geometry), *crossed_links(segments, geometry)
    )
    if not free.any():
        raise ValueError(f"{path}: the polygon has no free cell at {resolution_m} m resolution")
    x, y = verts[:, 0], verts[:, 1]
    area_m2 = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    metadata = {
        "source": "houseexpo_json",
        "path": str(path),
        "id": doc.get("id"),
        "room_num": doc.get("room_num"),
        "bbox": doc.get("bbox"),
        "room_category": doc.get("room_category", {}),
        "polygon_area_m2": area_m2,
        "n_vertices": int(verts.shape[0]),
    }
    return World(
        name=name if name is not None else str(path),
        segments_m=segments,
        bounds_m=bounds,
        free_mask=free,
        free_geometry=geometry,
        start_pose=None,
        metadata=metadata,
        free_space_source="vector",
    )
