"""Value-noise caves (``"noisecave:seed=1,size_m=12,threshold=0.44"``): blobby open space.

A cave of another kind than :mod:`.cave`'s: no passage is widened to a guaranteed width, so
the free space runs from wide chambers down to slits narrower than the robot, as in a raster
map of a real cave.

1. Uniform noise in ``[0, 1)`` is drawn on a coarse square lattice of pitch ``lattice_m``
   covering the ``size_m`` square (0.6 m by default, every 12 cells of the 0.05 m raster: at
   0.4 m, every 8 cells, most passages are narrower than the 0.21 m robot and it reaches only
   a small part of the free space; at 0.8 m the chambers are wide and few passages are narrow).
2. It is upsampled to the 0.05 m raster by bilinear interpolation (the value at each cell
   centre), so the field is smooth between lattice points and blobs are about a lattice pitch
   across.
3. Cells where the field exceeds ``threshold`` are free; the square's border cells never are.
   A lower threshold opens the cave up: 0.40 is open, with wide chambers joined in many
   places; 0.48 leaves a third of the square free, in chambers joined by narrow passages,
   many of them too narrow for the robot. :data:`THRESHOLD_RANGE` is the accepted range.
4. Only the largest 4-connected free component is kept, so the cave is one piece (a robot of
   a given size may still be unable to pass its narrowest parts: coverage counts only what it
   can reach).
5. The walls are the raster's cell edges between free and non-free cells, as for the other
   raster worlds (:func:`~semexplore_gym.core.worlds.build.world_from_free_mask`).

The start pose is a random cell of the largest 4-connected set of cells at least
``_START_CLEARANCE_M`` (0.25 m; less only where no cell of the cave has that much) from every
non-free cell, with a random heading.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy import ndimage

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.build import world_from_free_mask
from semexplore_gym.core.worlds.grid_maze import check_range
from semexplore_gym.core.worlds.world import World

_RES_M = 0.05
#: The world's start keeps this distance from the walls (more than the env's sampled starts
#: need: radius 0.105 m + margin 0.1 m).
_START_CLEARANCE_M = 0.25
_FOUR_CONNECTED = ndimage.generate_binary_structure(2, 1)

#: The accepted range of ``threshold``: below it the cave is one open hall with islands, above
#: it the largest connected piece is a small part of the square.
THRESHOLD_RANGE = (0.35, 0.55)


@dataclass(frozen=True)
class NoiseCaveParams:
    """Parameters of a value-noise cave.

    Attributes:
        seed: Random seed; the same seed gives the same cave.
        size_m: Side of the square the cave is carved from, in metres.
        threshold: Free where the noise exceeds it, in ``[0.35, 0.55]``; 0.40-0.48 is the
            useful band (lower is more open, higher has more narrow passages).
        lattice_m: Pitch of the noise lattice in metres (about the size of a blob), at least
            0.3 and at most ``size_m / 4``.
    """

    seed: int = 0
    size_m: float = 12.0
    threshold: float = 0.44
    lattice_m: float = 0.6

    def __post_init__(self) -> None:
        if (
            isinstance(self.seed, bool)
            or not isinstance(self.seed, (int, np.integer))
            or self.seed < 0
        ):
            raise ValueError(
                f"noisecave parameter seed={self.seed!r} must be a non-negative integer"
            )
        check_range("noisecave", "size_m", self.size_m, 4.0, 50.0)
        check_range("noisecave", "threshold", self.threshold, *THRESHOLD_RANGE)
        check_range("noisecave", "lattice_m", self.lattice_m, 0.3, self.size_m / 4.0)


def bilinear_weights(n_cells: int, resolution_m: float, lattice_m: float) -> np.ndarray:
    """``(n_cells, n_lattice)`` weights: row ``i`` interpolates the lattice at cell centre ``i``.

    Lattice point ``k`` lies at ``k * lattice_m`` from the raster's corner; each row has at most
    two non-zero weights and sums to 1.
    """
    u = (np.arange(n_cells) + 0.5) * resolution_m / lattice_m
    n_lattice = int(np.floor(u[-1])) + 2
    k = np.floor(u).astype(np.int64)
    t = u - k
    weights = np.zeros((n_cells, n_lattice))
    weights[np.arange(n_cells), k] = 1.0 - t
    weights[np.arange(n_cells), k + 1] = t
    return weights


def carve_noise_cave(params: NoiseCaveParams, rng: np.random.Generator) -> np.ndarray:
    """The cave's free raster at 0.05 m (origin at the square's corner): one 4-connected piece
    that never touches the square's border.

    Raises:
        ValueError: no free cell is left (a threshold far above the useful band).
    """
    n = int(round(params.size_m / _RES_M))
    weights = bilinear_weights(n, _RES_M, params.lattice_m)
    lattice = rng.random((weights.shape[1], weights.shape[1]))
    field = weights @ lattice @ weights.T
    free = field > params.threshold
    free[[0, -1], :] = False
    free[:, [0, -1]] = False
    labels, n_labels = ndimage.label(free, structure=_FOUR_CONNECTED)
    if n_labels == 0:
        raise ValueError(f"noisecave {params}: no free cell; lower threshold")
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    return labels == int(np.argmax(sizes))


def _start_pose(free: np.ndarray, rng: np.random.Generator) -> tuple[float, float, float]:
    """A random cell of the largest 4-connected set of cells with the most clearance up to
    ``_START_CLEARANCE_M`` (less where the whole cave is narrower), and a random heading."""
    # Centre-to-centre EDT; a centre's distance to the nearest non-free cell *edge* is half a
    # cell less.
    clearance = ndimage.distance_transform_edt(free) - 0.5
    need = min(_START_CLEARANCE_M / _RES_M, float(clearance.max()))
    labels, _ = ndimage.label(clearance >= need, structure=_FOUR_CONNECTED)
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    rows, cols = np.nonzero(labels == int(np.argmax(sizes)))
    k = int(rng.integers(len(rows)))
    return (
        float((cols[k] + 0.5) * _RES_M),
        float((rows[k] + 0.5) * _RES_M),
        float(rng.uniform(-np.pi, np.pi)),
    )


def generate_noise_cave(params: NoiseCaveParams, name: str | None = None) -> World:
    """A value-noise cave world (deterministic for ``params.seed``)."""
    rng = np.random.default_rng(params.seed)
    free = carve_noise_cave(params, rng)
    n = free.shape[0]
    spec = (
        f"noisecave:seed={params.seed},size_m={params.size_m:g},threshold={params.threshold:g},"
        f"lattice_m={params.lattice_m:g}"
    )
    return world_from_free_mask(
        name if name is not None else spec,
        free,
        GridGeometry(_RES_M, 0.0, 0.0, n, n),
        start_pose=_start_pose(free, rng),
        bounds_m=(0.0, 0.0, n * _RES_M, n * _RES_M),
        metadata={
            "source": "procedural",
            "family": "noisecave",
            "params": asdict(params),
            "spec": spec,
        },
    )
