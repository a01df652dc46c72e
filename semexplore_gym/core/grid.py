"""Occupancy-grid encoding and the metric frame of a grid.

The uint8 encoding of the env's ``map`` observation:

=========  =====  ============================================
name       value  meaning
=========  =====  ============================================
UNKNOWN    128    never observed
FREE       255    observed free
OCCUPIED   0      observed occupied
=========  =====  ============================================

The values read like a ROS map image (white free, black walls, grey unknown), so the
observation can be shown or fed to a CNN as it is. ROS ``OccupancyGrid`` values (-1 / 0 / 100)
convert with :func:`from_ros_values` and :func:`to_ros_values`. Angles are wrapped with
:func:`wrap_angle_rad`, the one angle helper of the package.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

UNKNOWN: int = 128
FREE: int = 255
OCCUPIED: int = 0

ROS_UNKNOWN: int = -1
ROS_FREE: int = 0
ROS_OCCUPIED: int = 100


def wrap_angle_rad(angle_rad: float) -> float:
    """Wrap an angle to ``[-pi, pi)``.

    Args:
        angle_rad: Any finite angle in radians (a float or numpy scalar).

    Returns:
        The same direction in ``[-pi, pi)``.
    """
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True)
class GridGeometry:
    """Where a grid lies in the world.

    Attributes:
        resolution_m: Edge length of one square cell in metres.
        origin_x_m: World x of the outer (lower-left) corner of cell ``(0, 0)``.
        origin_y_m: World y of the outer (lower-left) corner of cell ``(0, 0)``.
        height: Number of rows (along y).
        width: Number of columns (along x).
    """

    resolution_m: float
    origin_x_m: float
    origin_y_m: float
    height: int
    width: int

    def __post_init__(self) -> None:
        if not (np.isfinite(self.resolution_m) and self.resolution_m > 0):
            raise ValueError(
                f"resolution_m must be a positive finite number, got {self.resolution_m!r}"
            )
        if not (np.isfinite(self.origin_x_m) and np.isfinite(self.origin_y_m)):
            raise ValueError(
                f"grid origin must be finite, got ({self.origin_x_m!r}, {self.origin_y_m!r})"
            )
        if int(self.height) <= 0 or int(self.width) <= 0:
            raise ValueError(f"grid shape must be positive, got ({self.height!r}, {self.width!r})")

    @classmethod
    def covering(
        cls,
        xmin_m: float,
        ymin_m: float,
        xmax_m: float,
        ymax_m: float,
        resolution_m: float,
        margin_m: float = 0.0,
    ) -> GridGeometry:
        """The smallest grid of ``resolution_m`` cells covering a box plus ``margin_m`` on each side."""
        if not resolution_m > 0:
            raise ValueError(f"resolution_m must be positive, got {resolution_m!r}")
        if not (xmax_m > xmin_m and ymax_m > ymin_m):
            raise ValueError(f"empty bounds ({xmin_m}, {ymin_m}, {xmax_m}, {ymax_m})")
        x0 = xmin_m - margin_m
        y0 = ymin_m - margin_m
        width = int(np.ceil((xmax_m + margin_m - x0) / resolution_m - 1e-9))
        height = int(np.ceil((ymax_m + margin_m - y0) / resolution_m - 1e-9))
        return cls(float(resolution_m), float(x0), float(y0), height, width)

    @property
    def shape(self) -> tuple[int, int]:
        return (int(self.height), int(self.width))

    @property
    def extent_m(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the grid's outer border in metres."""
        return (
            self.origin_x_m,
            self.origin_y_m,
            self.origin_x_m + self.width * self.resolution_m,
            self.origin_y_m + self.height * self.resolution_m,
        )

    def world_to_grid(
        self, x_m: npt.ArrayLike, y_m: npt.ArrayLike
    ) -> tuple[np.ndarray, np.ndarray]:
        """(row, col) integer indices of the cells containing world points (may be out of range)."""
        col = np.floor(
            (np.asarray(x_m, dtype=np.float64) - self.origin_x_m) / self.resolution_m
        ).astype(np.int64)
        row = np.floor(
            (np.asarray(y_m, dtype=np.float64) - self.origin_y_m) / self.resolution_m
        ).astype(np.int64)
        return row, col

    def grid_to_world(
        self, row: npt.ArrayLike, col: npt.ArrayLike
    ) -> tuple[np.ndarray, np.ndarray]:
        """World (x, y) in metres of cell centres."""
        x = self.origin_x_m + (np.asarray(col, dtype=np.float64) + 0.5) * self.resolution_m
        y = self.origin_y_m + (np.asarray(row, dtype=np.float64) + 0.5) * self.resolution_m
        return x, y

    def contains(self, row: npt.ArrayLike, col: npt.ArrayLike) -> np.ndarray:
        r = np.asarray(row)
        c = np.asarray(col)
        return (r >= 0) & (r < self.height) & (c >= 0) & (c < self.width)

    def to_dict(self) -> dict[str, float | int]:
        return {
            "resolution_m": self.resolution_m,
            "origin_x_m": self.origin_x_m,
            "origin_y_m": self.origin_y_m,
            "height": int(self.height),
            "width": int(self.width),
        }

    @classmethod
    def from_dict(cls, d: dict) -> GridGeometry:
        return cls(
            float(d["resolution_m"]),
            float(d["origin_x_m"]),
            float(d["origin_y_m"]),
            int(d["height"]),
            int(d["width"]),
        )


def from_ros_values(grid: npt.ArrayLike) -> np.ndarray:
    """Convert a ROS-style grid (-1 unknown, 0..100 occupancy probability) to the uint8 encoding.

    Values >= 50 count as occupied, 0..49 as free, -1 as unknown; anything else is an error.
    """
    a = np.asarray(grid)
    if a.ndim != 2:
        raise ValueError(f"expected a 2-D grid, got shape {a.shape}")
    if not np.issubdtype(a.dtype, np.integer):
        raise TypeError(f"a ROS grid must have an integer dtype, got {a.dtype}")
    bad = (a < -1) | (a > 100)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise ValueError(f"ROS grid value {int(a[r, c])} at (row={r}, col={c}) is outside -1..100")
    out = np.full(a.shape, UNKNOWN, dtype=np.uint8)
    out[(a >= 0) & (a < 50)] = FREE
    out[a >= 50] = OCCUPIED
    return out


def to_ros_values(grid: npt.ArrayLike) -> np.ndarray:
    """Convert the uint8 encoding to ROS values (int8: -1 / 0 / 100)."""
    a = validate_encoded_grid(grid)
    out = np.full(a.shape, ROS_UNKNOWN, dtype=np.int8)
    out[a == FREE] = ROS_FREE
    out[a == OCCUPIED] = ROS_OCCUPIED
    return out


def validate_encoded_grid(grid: npt.ArrayLike, name: str = "grid") -> np.ndarray:
    """Return ``grid`` as a uint8 array after checking it uses only UNKNOWN / FREE / OCCUPIED."""
    a = np.asarray(grid)
    if a.ndim != 2:
        raise ValueError(f"{name} must be 2-D (rows, cols), got shape {a.shape}")
    if a.dtype != np.uint8:
        raise TypeError(
            f"{name} must have dtype uint8 (UNKNOWN={UNKNOWN}, FREE={FREE}, OCCUPIED={OCCUPIED}), got {a.dtype}"
        )
    if a.size == 0:
        raise ValueError(f"{name} is empty (shape {a.shape})")
    valid = (a == UNKNOWN) | (a == FREE) | (a == OCCUPIED)
    if not valid.all():
        r, c = np.argwhere(~valid)[0]
        raise ValueError(
            f"{name} value {int(a[r, c])} at (row={r}, col={c}) is not one of UNKNOWN={UNKNOWN}, FREE={FREE}, OCCUPIED={OCCUPIED}"
        )
    return a


def parse_ascii_grid(text: str) -> np.ndarray:
    """Build an encoded grid from ASCII art: ``#`` occupied, ``.`` free, ``?`` unknown.

    The *first* text line is the *top* of the map (largest y), as a person draws it, so the
    returned array is flipped to the row-grows-with-y convention of :mod:`semexplore_gym.core`.
    Blank lines at either end are ignored; every line must have the same length.
    """
    lines = [ln.strip() for ln in text.strip("\n").splitlines()]
    lines = [ln for ln in lines if ln]
    if not lines:
        raise ValueError("ASCII grid is empty")
    width = len(lines[0])
    table = {"#": OCCUPIED, ".": FREE, "?": UNKNOWN}
    out = np.empty((len(lines), width), dtype=np.uint8)
    for i, ln in enumerate(lines):
        if len(ln) != width:
            raise ValueError(f"ASCII grid line {i} has length {len(ln)}, expected {width}")
        for j, ch in enumerate(ln):
            if ch not in table:
                raise ValueError(
                    f"ASCII grid character {ch!r} at line {i}, column {j} is not one of '#', '.', '?'"
                )
            out[i, j] = table[ch]
    return out[::-1].copy()
