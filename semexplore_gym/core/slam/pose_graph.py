"""The pose graph behind one small adapter: gtsam (the optional extra ``slam``), imported lazily.

Nothing else in the package imports gtsam; :func:`require_gtsam` is the one check that it is
there, with one line naming the extra when it is not.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

#: What to install when gtsam is missing.
GTSAM_HINT = "the slam mapping mode needs gtsam: pip install 'semexplore-gym[slam]'"

#: Huber threshold of the loop-closure factors (in standard deviations).
_HUBER_K = 1.345


@dataclass(frozen=True)
class Edge:
    """A relative-pose constraint ``pose_j = pose_i (+) delta`` with covariance ``cov`` (3x3, x, y, yaw)."""

    i: int
    j: int
    delta: tuple[float, float, float]
    cov: np.ndarray
    robust: bool = False


def require_gtsam() -> Any:
    """The gtsam module; ImportError with one line naming the extra when it is missing."""
    try:
        import gtsam
    except ImportError:
        raise ImportError(GTSAM_HINT) from None
    return gtsam


def optimise(poses: np.ndarray, edges: list[Edge], prior_sigma: float = 1e-3) -> np.ndarray:
    """The poses ``(n, 3)`` that best satisfy ``edges`` (Levenberg-Marquardt from ``poses``),
    the first pose held by a tight prior. Robust edges get a Huber noise model."""
    gtsam = require_gtsam()
    graph = gtsam.NonlinearFactorGraph()
    initial = gtsam.Values()
    for k, (x, y, yaw) in enumerate(np.asarray(poses, dtype=np.float64)):
        initial.insert(k, gtsam.Pose2(float(x), float(y), float(yaw)))
    prior = gtsam.noiseModel.Isotropic.Sigma(3, prior_sigma)
    graph.add(gtsam.PriorFactorPose2(0, gtsam.Pose2(*map(float, poses[0])), prior))
    for e in edges:
        noise: Any = gtsam.noiseModel.Gaussian.Covariance(np.asarray(e.cov, dtype=np.float64))
        if e.robust:
            huber = gtsam.noiseModel.mEstimator.Huber.Create(_HUBER_K)
            noise = gtsam.noiseModel.Robust.Create(huber, noise)
        graph.add(gtsam.BetweenFactorPose2(e.i, e.j, gtsam.Pose2(*e.delta), noise))
    params = gtsam.LevenbergMarquardtParams()
    params.setMaxIterations(100)
    result = gtsam.LevenbergMarquardtOptimizer(graph, initial, params).optimize()
    out = np.empty((len(poses), 3), dtype=np.float64)
    for k in range(len(poses)):
        p = result.atPose2(k)
        out[k] = (p.x(), p.y(), p.theta())
    return out
