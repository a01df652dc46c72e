"""Why a policy stopped short on a SLAM map: the frontiers SLAM lost or made up.

A policy that ends its mission (self-stop) while the coverage counted on the truth is below the
goal stopped *falsely* when its map explains it. Two artefacts do, found by comparing the
frontiers of the SLAM map with those of the map the same scans build at the true poses (the
*truth map*; both in the same frame, as SLAM starts at the true start pose):

- a **lost frontier**: the truth map still borders reachable space it has not seen, and the
  SLAM map shows no frontier near there: a smeared or doubled wall closed a corridor, or a
  drifted scan painted free space over the gap;
- a **ghost frontier**: the SLAM map shows a frontier where the truth map has none (a gap
  between a wall and its drifted double): a goal the policy may have given up on, or one it
  could never reach.

Cells are compared with a tolerance of a few cells (``tolerance_cells``), so a frontier that
is only shifted by the map's residual error counts as kept; fewer than ``min_cells`` cells of
either kind are noise.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from semexplore_gym.core.frontiers.detection import frontier_cell_mask
from semexplore_gym.core.grid import UNKNOWN

#: The artefact names, in the order they are judged (the first that applies is reported).
LOST_FRONTIER = "lost_frontier"
GHOST_FRONTIER = "ghost_frontier"


def frontier_differences(
    slam_map: np.ndarray,
    truth_map: np.ndarray,
    reachable: np.ndarray,
    tolerance_cells: int = 3,
) -> tuple[int, int]:
    """Frontier cells the SLAM map lost and made up (see the module docstring).

    Args:
        slam_map: ``(H, W)`` encoded SLAM map (the policies' map).
        truth_map: ``(H, W)`` encoded map of the same scans at the true poses.
        reachable: ``(H, W)`` bool, the cells coverage counts (the truth's reachable space).
        tolerance_cells: A frontier cell within this many cells (Chebyshev) of a frontier cell
            of the other map counts as present in both.

    Returns:
        ``(lost, ghost)``: the truth map's frontier cells (unknown, reachable, next to free)
        with no SLAM frontier cell near, and the SLAM map's frontier cells with no truth
        frontier cell near that the truth map has observed.
    """
    slam = np.asarray(slam_map)
    truth = np.asarray(truth_map)
    if slam.shape != truth.shape or np.shape(reachable) != truth.shape:
        raise ValueError(
            f"slam_map, truth_map and reachable must have one shape, got {slam.shape}, "
            f"{truth.shape} and {np.shape(reachable)}"
        )
    if tolerance_cells < 0:
        raise ValueError(f"tolerance_cells must be >= 0, got {tolerance_cells}")
    near = np.ones((2 * tolerance_cells + 1,) * 2, dtype=bool)
    truth_front = frontier_cell_mask(truth)
    slam_front = frontier_cell_mask(slam)
    lost = truth_front & np.asarray(reachable, dtype=bool)
    lost &= ~ndimage.binary_dilation(slam_front, structure=near)
    ghost = slam_front & (truth != UNKNOWN)
    ghost &= ~ndimage.binary_dilation(truth_front, structure=near)
    return int(np.count_nonzero(lost)), int(np.count_nonzero(ghost))


def stop_artefact(
    slam_map: np.ndarray,
    truth_map: np.ndarray,
    reachable: np.ndarray,
    tolerance_cells: int = 3,
    min_cells: int = 3,
) -> str | None:
    """The SLAM artefact that explains a stop short of the goal: :data:`LOST_FRONTIER`,
    :data:`GHOST_FRONTIER` (at least ``min_cells`` cells of it; :func:`frontier_differences`),
    or None when the maps agree on the frontiers (the policy's own stop)."""
    lost, ghost = frontier_differences(slam_map, truth_map, reachable, tolerance_cells)
    if lost >= min_cells:
        return LOST_FRONTIER
    if ghost >= min_cells:
        return GHOST_FRONTIER
    return None
