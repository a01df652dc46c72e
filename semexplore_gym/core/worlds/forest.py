"""Procedural forests (``"forest:seed=1,size_m=12,density=8"``): open ground with round trunks.

An outdoor-like world with no corridors and no rooms: a fenced square scattered with round
obstacles (tree trunks, bollards, pillars of a plaza). It is the opposite of a maze: every
frontier is reachable from many sides and structure-based semantics have little to work with.

1. Trunk centres are drawn uniformly in the square, radii uniformly in
   ``[trunk_radius_min_m, trunk_radius_max_m]``; a trunk is kept only when its surface is at
   least ``min_gap_m`` from every kept trunk and from the fence (dart throwing), until
   ``density`` trunks per 100 m^2 are placed or the attempts run out. Every gap is therefore at
   least ``min_gap_m`` wide, so all free space is one piece a robot narrower than the gap can
   sweep.
2. Each trunk is a regular polygon of ``_SIDES`` sides circumscribing the circle (walls run at
   every angle); the fence is the square's four walls.
3. The start pose is a random point at least ``min_gap_m / 2`` from every trunk and the fence.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from semexplore_gym.core.worlds.build import world_from_segments
from semexplore_gym.core.worlds.grid_maze import check_range
from semexplore_gym.core.worlds.world import World

_SIDES = 12
_ATTEMPTS_PER_TRUNK = 60


@dataclass(frozen=True)
class ForestParams:
    """Parameters of a procedural forest.

    Attributes:
        seed: Random seed; the same seed gives the same forest.
        size_m: Side of the fenced square, in metres.
        density: Trunks per 100 m^2 (fewer when the gaps leave no room for more).
        trunk_radius_min_m: Smallest trunk radius.
        trunk_radius_max_m: Largest trunk radius.
        min_gap_m: Narrowest gap between two trunks or a trunk and the fence.
    """

    seed: int = 0
    size_m: float = 12.0
    density: float = 8.0
    trunk_radius_min_m: float = 0.1
    trunk_radius_max_m: float = 0.4
    min_gap_m: float = 0.6

    def __post_init__(self) -> None:
        if (
            isinstance(self.seed, bool)
            or not isinstance(self.seed, (int, np.integer))
            or self.seed < 0
        ):
            raise ValueError(f"forest parameter seed={self.seed!r} must be a non-negative integer")
        check_range("forest", "size_m", self.size_m, 4.0, 60.0)
        check_range("forest", "density", self.density, 0.0, 40.0)
        check_range("forest", "trunk_radius_min_m", self.trunk_radius_min_m, 0.05, 2.0)
        check_range(
            "forest", "trunk_radius_max_m", self.trunk_radius_max_m, self.trunk_radius_min_m, 2.0
        )
        check_range("forest", "min_gap_m", self.min_gap_m, 0.4, 4.0)


def place_trunks(params: ForestParams, rng: np.random.Generator) -> np.ndarray:
    """Trunks as an ``(N, 3)`` array of ``x_m, y_m, radius_m`` (origin at the square's corner)."""
    size = params.size_m
    target = int(round(params.density * size * size / 100.0))
    kept = np.empty((0, 3))
    for _ in range(target * _ATTEMPTS_PER_TRUNK):
        if len(kept) >= target:
            break
        r = rng.uniform(params.trunk_radius_min_m, params.trunk_radius_max_m)
        lo = r + params.min_gap_m
        if size - 2 * lo <= 0:
            continue
        x, y = rng.uniform(lo, size - lo, 2)
        if len(kept):
            d = np.hypot(kept[:, 0] - x, kept[:, 1] - y) - kept[:, 2] - r
            if d.min() < params.min_gap_m:
                continue
        kept = np.vstack([kept, [x, y, r]])
    return kept


def trunk_segments(trunks: np.ndarray) -> np.ndarray:
    """Each trunk as a regular polygon circumscribing its circle, as ``(N * _SIDES, 4)`` walls."""
    if len(trunks) == 0:
        return np.empty((0, 4))
    angles = np.linspace(0.0, 2 * np.pi, _SIDES + 1)
    # The polygon's vertices lie outside the circle so its sides touch it (circumscribed).
    scale = 1.0 / np.cos(np.pi / _SIDES)
    vx = trunks[:, :1] + scale * trunks[:, 2:3] * np.cos(angles)
    vy = trunks[:, 1:2] + scale * trunks[:, 2:3] * np.sin(angles)
    return np.stack([vx[:, :-1], vy[:, :-1], vx[:, 1:], vy[:, 1:]], axis=-1).reshape(-1, 4)


def sample_clear_point(
    trunks: np.ndarray, size_m: float, clearance_m: float, rng: np.random.Generator
) -> tuple[float, float]:
    """A uniform random point at least ``clearance_m`` from every trunk surface and the fence."""
    for _ in range(10_000):
        x, y = rng.uniform(clearance_m, size_m - clearance_m, 2)
        if len(trunks) == 0:
            return float(x), float(y)
        d = np.hypot(trunks[:, 0] - x, trunks[:, 1] - y) - trunks[:, 2] / np.cos(np.pi / _SIDES)
        if d.min() >= clearance_m:
            return float(x), float(y)
    raise ValueError(f"forest: no point {clearance_m} m clear of the trunks; lower density")


def generate_forest(params: ForestParams, name: str | None = None) -> World:
    """A procedural forest world (deterministic for ``params.seed``)."""
    rng = np.random.default_rng(params.seed)
    trunks = place_trunks(params, rng)
    s = params.size_m
    fence = np.array([[0, 0, s, 0], [s, 0, s, s], [s, s, 0, s], [0, s, 0, 0]], dtype=np.float64)
    segments = np.vstack([fence, trunk_segments(trunks)])
    x, y = sample_clear_point(trunks, s, params.min_gap_m / 2, rng)
    start = (x, y, float(rng.uniform(-np.pi, np.pi)))
    spec = (
        f"forest:seed={params.seed},size_m={params.size_m:g},density={params.density:g},"
        f"trunk_radius_min_m={params.trunk_radius_min_m:g},"
        f"trunk_radius_max_m={params.trunk_radius_max_m:g},min_gap_m={params.min_gap_m:g}"
    )
    return world_from_segments(
        name if name is not None else spec,
        segments,
        np.array([[x, y]]),
        start_pose=start,
        bounds_m=(0.0, 0.0, s, s),
        metadata={
            "source": "procedural",
            "family": "forest",
            "params": asdict(params),
            "spec": spec,
            "n_trunks": int(len(trunks)),
        },
    )
