"""The observation of an agent choosing among every reachable frontier option (pure numpy).

The frontier student's options (:mod:`~semexplore_gym.core.frontiers.options`) and their
features (:func:`~semexplore_gym.core.features.frontier_option_features.frontier_option_features`)
become a fixed-size observation: the ``max_options`` options with the shortest paths, each row
its features divided by :data:`OPTION_FEATURE_SCALES` and clipped to ``[-CLIP, CLIP]``, padded
with zero rows; ``valid`` marks the real rows (the action mask); ``global`` holds
:data:`GLOBAL_FEATURE_NAMES`.

:func:`privileged_option_features` is the training-only part, read from the true world: the
unseen reachable area round each option's goal and the unseen reachable share left. Nothing
an actor reads comes from it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from semexplore_gym.core.features.frontier_option_features import OPTION_FEATURE_NAMES
from semexplore_gym.core.grid import UNKNOWN, GridGeometry

__all__ = [
    "CLIP",
    "GLOBAL_FEATURE_NAMES",
    "OPTION_FEATURE_SCALES",
    "PRIVILEGED_FEATURE_NAMES",
    "OptionObservation",
    "option_observation",
    "privileged_option_features",
]

#: Each option feature is divided by this (same order as ``OPTION_FEATURE_NAMES``).
OPTION_FEATURE_SCALES: tuple[float, ...] = (
    20.0,  # path_m
    20.0,  # extra_path_m
    4.0,  # log_path
    20.0,  # straight_m
    10.0,  # detour
    np.pi,  # turn_rad
    5.0,  # frontier_m
    1.0,  # unknown_near
    1.0,  # unknown_far
    10.0,  # isolation_m
    10.0,  # crowd
    20.0,  # away_m
    1.0,  # current
    1.0,  # nearest
    50.0,  # tour_m
    50.0,  # tour_extra_m
)
assert len(OPTION_FEATURE_SCALES) == len(OPTION_FEATURE_NAMES)

#: Scaled features are clipped to ``[-CLIP, CLIP]``.
CLIP = 5.0

#: The global features: the known share of the map, mission time over ``time_scale_s``
#: (at most 1), the options' count over ``max_options`` (at most 1).
GLOBAL_FEATURE_NAMES: tuple[str, ...] = ("known_share", "time", "n_options")

#: Per option (training only): unseen reachable area within 2 m and within 4 m of its goal
#: (m^2, over 10 and 40); the last row: the unseen reachable share of the world, twice.
PRIVILEGED_FEATURE_NAMES: tuple[str, ...] = ("unseen_near", "unseen_far")


@dataclass(frozen=True)
class OptionObservation:
    """One decision's observation.

    Attributes:
        options: ``(max_options, K)`` float32 scaled features (zero rows: padding).
        valid: ``(max_options,)`` float32, 1 for the real rows.
        global_features: ``(len(GLOBAL_FEATURE_NAMES),)`` float32.
        slots: ``(n,)`` the option index of each real row (row ``i`` is option ``slots[i]``).
    """

    options: np.ndarray
    valid: np.ndarray
    global_features: np.ndarray
    slots: np.ndarray


def option_observation(
    features: np.ndarray,
    grid: np.ndarray,
    time_s: float,
    max_options: int,
    time_scale_s: float = 1500.0,
) -> OptionObservation:
    """The observation of ``features`` (``(F, K)``, one row per option) on map ``grid``.

    Raises:
        ValueError: ``features`` is not ``(F, len(OPTION_FEATURE_NAMES))``, or
            ``max_options`` < 1.
    """
    k = len(OPTION_FEATURE_NAMES)
    if features.ndim != 2 or features.shape[1] != k:
        raise ValueError(f"features must be (F, {k}), got shape {features.shape}")
    if max_options < 1:
        raise ValueError(f"max_options must be >= 1, got {max_options!r}")
    path = features[:, OPTION_FEATURE_NAMES.index("path_m")]
    slots = np.argsort(path, kind="stable")[:max_options]
    rows = np.zeros((max_options, k), dtype=np.float32)
    scaled = features[slots] / np.asarray(OPTION_FEATURE_SCALES)
    rows[: len(slots)] = np.clip(np.nan_to_num(scaled), -CLIP, CLIP)
    valid = np.zeros(max_options, dtype=np.float32)
    valid[: len(slots)] = 1.0
    known = 1.0 - float(np.count_nonzero(grid == UNKNOWN)) / max(grid.size, 1)
    glob = np.array(
        [known, min(time_s / time_scale_s, 1.0), min(len(features) / max_options, 1.0)],
        dtype=np.float32,
    )
    return OptionObservation(rows, valid, glob, slots.astype(np.int64))


def privileged_option_features(
    grid: np.ndarray,
    geometry: GridGeometry,
    reachable_mask: np.ndarray,
    goals_xy_m: np.ndarray,
    max_options: int,
) -> np.ndarray:
    """``(max_options + 1, 2)`` float32: per row the true unseen reachable area near that
    option's goal (``goals_xy_m`` in the rows' order, padding rows zero); the last row the
    unseen share of the reachable world (both columns)."""
    out = np.zeros((max_options + 1, len(PRIVILEGED_FEATURE_NAMES)), dtype=np.float32)
    unseen = reachable_mask & (grid == UNKNOWN)
    total = max(int(np.count_nonzero(reachable_mask)), 1)
    out[-1, :] = float(np.count_nonzero(unseen)) / total
    res = geometry.resolution_m
    cell_m2 = res * res
    rows, cols = grid.shape
    for i, (x, y) in enumerate(goals_xy_m[:max_options]):
        r0, c0 = (y - geometry.origin_y_m) / res, (x - geometry.origin_x_m) / res
        for j, (radius_m, norm) in enumerate(((2.0, 10.0), (4.0, 40.0))):
            n = int(np.ceil(radius_m / res))
            ra, rb = max(int(r0) - n, 0), min(int(r0) + n + 1, rows)
            ca, cb = max(int(c0) - n, 0), min(int(c0) + n + 1, cols)
            if ra >= rb or ca >= cb:
                continue
            rr, cc = np.ogrid[ra:rb, ca:cb]
            disk = (rr - r0) ** 2 + (cc - c0) ** 2 <= (radius_m / res) ** 2
            out[i, j] = float(np.count_nonzero(unseen[ra:rb, ca:cb] & disk)) * cell_m2 / norm
    return out
