"""What ``coverage`` counts, in one place: the env, the team env, ``show-world`` and the
benchmark rows all take their reachable mask from :func:`coverage_mask`."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from semexplore_gym.core.grid import FREE, GridGeometry
from semexplore_gym.core.worlds.start import reachable_free_mask
from semexplore_gym.core.worlds.world import World
from semexplore_gym.envs.env_config import EnvConfig


def coverage_mask(
    world: World,
    geometry: GridGeometry,
    start_xy_m: npt.ArrayLike,
    config: EnvConfig,
    clearance_margin_m: float | None = None,
) -> np.ndarray:
    """The cells coverage counts in: what the robot's body sweeps from ``start_xy_m``.

    The robot's centre keeps ``config.robot.radius_m + clearance_margin_m`` from every wall
    (default margin: ``config.episode.coverage_clearance_margin_m``, 0.01 m, so gaps of
    ``2 * (radius + margin)`` = 0.23 m and wider count); see
    :func:`~semexplore_gym.core.worlds.start.reachable_free_mask` for the exact rule. A larger
    margin gives the cells reachable at a planner's own clearance.

    Args:
        world: The world.
        geometry: The map grid.
        start_xy_m: The episode's start position.
        config: The env config (robot radius, default margin).
        clearance_margin_m: Margin beyond the radius; None for the env's.

    Raises:
        ValueError: a negative or non-finite margin, or no cell with that clearance near the
            start.
    """
    margin = (
        config.episode.coverage_clearance_margin_m
        if clearance_margin_m is None
        else float(clearance_margin_m)
    )
    if not (np.isfinite(margin) and margin >= 0):
        raise ValueError(f"clearance_margin_m must be a non-negative distance, got {margin!r}")
    radius = config.robot.radius_m
    return reachable_free_mask(world, geometry, start_xy_m, radius, radius + margin)


def map_coverage(map_encoded: np.ndarray, mask: np.ndarray) -> float:
    """Share of ``mask``'s cells that are FREE in ``map_encoded`` (the env's ``coverage`` when
    ``mask`` is its :func:`coverage_mask`)."""
    if map_encoded.shape != mask.shape:
        raise ValueError(f"map shape {map_encoded.shape} != mask shape {mask.shape}")
    return int(np.count_nonzero((map_encoded == FREE) & mask)) / max(1, int(mask.sum()))
