"""Relative pose error of an estimated trajectory against the true one.

RPE here is the translation part of the relative pose error over a fixed distance of travel
(``delta_m``, 1 m by default), as ``evo_rpe --delta 1 --delta_unit m`` defines it: for each
pose ``i``, the first later pose ``j`` at least ``delta_m`` of true path further on; the error
is the distance between the estimated motion ``est_i^-1 (+) est_j`` and the true motion
``true_i^-1 (+) true_j`` (both in the frame of pose ``i``). The RPE is the RMSE of these
errors over all ``i`` that have such a ``j``. Unlike the absolute error it does not grow with
drift accumulated earlier: it measures the local consistency of the trajectory.
"""

from __future__ import annotations

import math

import numpy as np

from semexplore_gym.core.slam.backend import relative


def relative_pose_error_m(
    estimate: np.ndarray, truth: np.ndarray, delta_m: float = 1.0
) -> float | None:
    """RMSE of the translation error of the motion over ``delta_m`` of true travel (see the
    module docstring).

    Args:
        estimate: ``(n, 3)`` estimated poses ``x, y, yaw``.
        truth: ``(n, 3)`` the true poses at the same instants.
        delta_m: The travel (true path length) the motion is taken over.

    Returns:
        The RPE in metres, or None when the true path is shorter than ``delta_m``.
    """
    est = np.asarray(estimate, dtype=np.float64)
    true = np.asarray(truth, dtype=np.float64)
    if est.shape != true.shape or est.ndim != 2 or est.shape[1] != 3:
        raise ValueError(
            f"estimate and truth must both be (n, 3), got {est.shape} and {true.shape}"
        )
    travelled = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(true[:, :2], axis=0).T))])
    ends = np.searchsorted(travelled, travelled + delta_m - 1e-9, side="left")
    errors = []
    for i, j in enumerate(ends):
        if j >= len(true):
            break
        e = relative(tuple(est[i]), tuple(est[j]))  # type: ignore[arg-type]
        t = relative(tuple(true[i]), tuple(true[j]))  # type: ignore[arg-type]
        errors.append(math.hypot(e[0] - t[0], e[1] - t[1]))
    if not errors:
        return None
    return float(np.sqrt(np.mean(np.square(errors))))
