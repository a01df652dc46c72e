"""Merging the occupancy grids of robots that meet (per-robot maps in a team)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid


def merge_grids(grids: Sequence[OccupancyGrid]) -> None:
    """Give every grid of ``grids`` the same merged map, in place.

    Each cell takes the log-odds of the grid most certain about it (largest magnitude; the
    first such grid on ties): a robot's confident observation is never averaged away by a
    teammate that has not seen the cell, and merging the same maps twice changes nothing
    (unlike summing log-odds, which would count shared observations twice). The encoded cells
    and the free-cell counters follow from the merged log-odds.

    Args:
        grids: Grids of one geometry, parameters and count mask (a team's per-robot maps).

    Raises:
        ValueError: grids of different shapes.
    """
    if len(grids) < 2:
        return
    merged = merged_log_odds(grids)
    for g in grids:
        g.load_log_odds(merged)


def merged_log_odds(grids: Sequence[OccupancyGrid]) -> np.ndarray:
    """The merged log-odds of :func:`merge_grids` (a new array; the grids stay as they are).

    Raises:
        ValueError: no grids, or grids of different shapes.
    """
    if not grids:
        raise ValueError("merged_log_odds needs at least one grid")
    shape = grids[0].geometry.shape
    if any(g.geometry.shape != shape for g in grids):
        raise ValueError("merge_grids needs grids of one shape")
    stack = np.stack([g.log_odds for g in grids])
    pick = np.argmax(np.abs(stack), axis=0)
    return np.take_along_axis(stack, pick[None], axis=0)[0]
