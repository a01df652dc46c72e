"""The :class:`World`: what the simulator needs to know about a building."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from semexplore_gym.core.grid import GridGeometry


@dataclass(frozen=True)
class World:
    """Static wall geometry of one environment, in metres.

    Attributes:
        name: The spelling that made it (``"maze1"``, ``"office:seed=3,size_m=20"``, a file path).
        segments_m: ``(N, 4)`` float64 wall segments ``x0, y0, x1, y1``. They are the only
            obstacles: physics and LiDAR both use them, so what the robot sees is what it hits.
        bounds_m: ``(xmin, ymin, xmax, ymax)`` box containing every segment and all free space.
        free_mask: Ground-truth free space rasterised on ``free_geometry`` (True = free,
            False = wall or outside the building). Used for start sampling and coverage.
        free_geometry: Frame of ``free_mask``.
        start_pose: ``(x_m, y_m, yaw_rad)`` given by the world, or ``None`` to sample one.
        metadata: Free-form facts about the source (file, generator parameters, licence).
        free_space_source: How ``free_mask`` relates to the walls. ``"raster"``: the world was
            built from ``free_mask`` and every wall lies on the edge of one of its cells, so the
            mask is exact and can be resampled at any cell centre. ``"vector"``: the walls came
            first (mazes, HouseExpo polygons, caves) and ``free_mask`` is their rasterisation;
            on another grid free space is found again by flood fill from the mask's inner cells
            (see :func:`semexplore_gym.core.worlds.raster.rasterize_free`).
    """

    name: str
    segments_m: np.ndarray
    bounds_m: tuple[float, float, float, float]
    free_mask: np.ndarray
    free_geometry: GridGeometry
    start_pose: tuple[float, float, float] | None = None
    metadata: dict = field(default_factory=dict)
    free_space_source: str = "raster"
    # Derived rasters (e.g. start-sampling masks), filled on first use by the functions that
    # need them; never part of the world's identity.
    _derived: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        seg = np.asarray(self.segments_m, dtype=np.float64)
        if seg.ndim != 2 or seg.shape[1] != 4:
            raise ValueError(
                f"world {self.name!r}: segments_m must have shape (N, 4), got {seg.shape}"
            )
        if not np.isfinite(seg).all():
            raise ValueError(f"world {self.name!r}: segments_m contains NaN or inf")
        if self.free_mask.shape != self.free_geometry.shape:
            raise ValueError(
                f"world {self.name!r}: free_mask shape {self.free_mask.shape} != free_geometry shape {self.free_geometry.shape}"
            )
        if self.free_space_source not in ("raster", "vector"):
            raise ValueError(
                f"world {self.name!r}: free_space_source must be 'raster' or 'vector', got {self.free_space_source!r}"
            )
        object.__setattr__(self, "segments_m", np.ascontiguousarray(seg))
        object.__setattr__(self, "free_mask", np.ascontiguousarray(self.free_mask, dtype=bool))

    @property
    def n_segments(self) -> int:
        return int(self.segments_m.shape[0])

    def derived(self, key: tuple, compute: Callable[[], Any]) -> Any:
        """Return ``compute()``, computed once per world and ``key`` and kept on the world.

        The result is shared: callers must not modify it.
        """
        if key not in self._derived:
            self._derived[key] = compute()
        return self._derived[key]

    def __getstate__(self) -> dict:
        # The derived cache can be large (start-cell indices of big maps) and is cheap to
        # rebuild, so it does not travel with a pickled world.
        state = dict(self.__dict__)
        state["_derived"] = {}
        return state

    def __setstate__(self, state: dict) -> None:
        for key, value in state.items():
            object.__setattr__(self, key, value)

    @property
    def size_m(self) -> tuple[float, float]:
        xmin, ymin, xmax, ymax = self.bounds_m
        return (xmax - xmin, ymax - ymin)
