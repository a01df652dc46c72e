"""Procedural caves (``"cave:seed=1,size_m=15"``): unstructured free space with no straight walls.

1. White noise on a 0.05 m raster of the ``size_m`` square is smoothed by a Gaussian of
   ``feature_size_m`` and pushed down near the square's border, so the cave never touches it.
2. The ``free_fraction`` highest cells are free.
3. A morphological opening by a disk of radius ``min_passage_m / 2`` closes every passage
   narrower than ``min_passage_m``; only the largest connected part of the opened space is kept,
   so the whole cave is one piece a robot of diameter up to ``min_passage_m`` can sweep.
   Obstacle islands smaller than 0.25 m^2 are filled.
4. The walls are the marching-squares contours of the raster (level 0.5, between free and
   non-free cell centres), simplified to within 0.03 m, so they run at any angle.

The world is a vector world: its free mask is re-derived from the contour walls.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy import ndimage

from semexplore_gym.core.worlds.build import world_from_segments
from semexplore_gym.core.worlds.grid_maze import check_range
from semexplore_gym.core.worlds.world import World

_RES_M = 0.05
_SIMPLIFY_TOLERANCE_M = 0.03
_MIN_ISLAND_AREA_M2 = 0.25
_FOUR_CONNECTED = ndimage.generate_binary_structure(2, 1)


@dataclass(frozen=True)
class CaveParams:
    """Parameters of a procedural cave.

    Attributes:
        seed: Random seed; the same seed gives the same cave.
        size_m: Side of the square the cave is carved from, in metres.
        feature_size_m: Length scale of the noise (Gaussian sigma): larger = wider chambers.
        free_fraction: Fraction of the square that is free before the opening.
        min_passage_m: Narrowest passage kept (the opening disk's diameter).
    """

    seed: int = 0
    size_m: float = 15.0
    feature_size_m: float = 0.8
    free_fraction: float = 0.55
    min_passage_m: float = 0.6

    def __post_init__(self) -> None:
        if (
            isinstance(self.seed, bool)
            or not isinstance(self.seed, (int, np.integer))
            or self.seed < 0
        ):
            raise ValueError(f"cave parameter seed={self.seed!r} must be a non-negative integer")
        check_range("cave", "size_m", self.size_m, 4.0, 50.0)
        check_range("cave", "feature_size_m", self.feature_size_m, 0.2, self.size_m / 4.0)
        check_range("cave", "free_fraction", self.free_fraction, 0.2, 0.8)
        check_range("cave", "min_passage_m", self.min_passage_m, 0.4, 3.0)


def carve_cave(params: CaveParams, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """The cave raster at 0.05 m: ``(free, core)`` bool arrays, origin at the square's corner.

    ``core`` marks the free cells at least ``min_passage_m / 2`` from every non-free cell (the
    opening's centres), all in one 4-connected piece.
    """
    n = int(round(params.size_m / _RES_M))
    sigma = params.feature_size_m / _RES_M
    field = ndimage.gaussian_filter(rng.standard_normal((n, n)), sigma=sigma, mode="reflect")
    field /= max(float(field.std()), 1e-12)
    # Distance to the square's border, in feature sizes: below ~1 the field is pushed down.
    idx = np.arange(n)
    edge = np.minimum(idx, n - 1 - idx) * _RES_M / params.feature_size_m
    border = np.minimum.outer(edge, edge)
    field -= 4.0 * np.clip(1.0 - border, 0.0, 1.0) ** 2
    threshold = np.quantile(field, 1.0 - params.free_fraction)
    free = field > threshold
    free[[0, -1], :] = False
    free[:, [0, -1]] = False

    radius_cells = 0.5 * params.min_passage_m / _RES_M
    # Centre-to-centre EDT; a free centre's clearance to the nearest non-free *cell edge* is
    # half a cell less.
    clearance = ndimage.distance_transform_edt(free) - 0.5
    core = clearance >= radius_cells
    labels, n_labels = ndimage.label(core, structure=_FOUR_CONNECTED)
    if n_labels == 0:
        raise ValueError(
            f"cave {params}: no room for a {params.min_passage_m} m passage; raise free_fraction or feature_size_m"
        )
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    core = labels == int(np.argmax(sizes))
    free = ndimage.distance_transform_edt(~core) <= radius_cells

    # Fill small obstacle islands (components of non-free that do not touch the border).
    solid = ~free
    labels, n_labels = ndimage.label(solid, structure=_FOUR_CONNECTED)
    sizes = np.bincount(labels.ravel(), minlength=n_labels + 1)
    touches_border = np.zeros(n_labels + 1, dtype=bool)
    for edge_labels in (labels[0], labels[-1], labels[:, 0], labels[:, -1]):
        touches_border[edge_labels] = True
    small = (sizes * _RES_M**2 < _MIN_ISLAND_AREA_M2) & ~touches_border
    small[0] = False
    free |= small[labels]
    return free, core


def contour_segments(free: np.ndarray, resolution_m: float, tolerance_m: float) -> np.ndarray:
    """Closed marching-squares contours of a bool raster (origin at its corner) as segments."""
    # imported here: scikit-image pulls in scipy.signal (1.5 s), which only caves need
    from skimage.measure import approximate_polygon, find_contours

    padded = np.pad(free.astype(np.float64), 1)
    segments = []
    for contour in find_contours(padded, 0.5):
        simple = approximate_polygon(contour, tolerance=tolerance_m / resolution_m)
        if len(simple) < 3:
            continue
        # Padded pixel (i, j) has its centre at (j - 0.5, i - 0.5) cells from the corner.
        xy = (simple[:, ::-1] - 0.5) * resolution_m
        segments.append(np.hstack([xy[:-1], xy[1:]]))
    return np.vstack(segments)


def generate_cave(params: CaveParams, name: str | None = None) -> World:
    """A procedural cave world (deterministic for ``params.seed``).

    The start pose is a random core cell (at least ``min_passage_m / 2`` from any wall) with a
    random heading.
    """
    rng = np.random.default_rng(params.seed)
    free, core = carve_cave(params, rng)
    segments = contour_segments(free, _RES_M, _SIMPLIFY_TOLERANCE_M)
    size_m = free.shape[0] * _RES_M
    rows, cols = np.nonzero(core)
    interior = np.column_stack([(cols + 0.5) * _RES_M, (rows + 0.5) * _RES_M])
    k = int(rng.integers(len(rows)))
    start = (float(interior[k, 0]), float(interior[k, 1]), float(rng.uniform(-np.pi, np.pi)))
    spec = (
        f"cave:seed={params.seed},size_m={params.size_m:g},feature_size_m={params.feature_size_m:g},"
        f"free_fraction={params.free_fraction:g},min_passage_m={params.min_passage_m:g}"
    )
    return world_from_segments(
        name if name is not None else spec,
        segments,
        interior,
        start_pose=start,
        bounds_m=(0.0, 0.0, size_m, size_m),
        metadata={"source": "procedural", "family": "cave", "params": asdict(params), "spec": spec},
    )
