"""The gtsam adapter: odometry chains, a loop edge, and a Huber-robust outlier."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.slam.backend import compose, relative
from semexplore_gym.core.slam.pose_graph import Edge, optimise

pytest.importorskip("gtsam")

ODOM_COV = np.diag([0.05**2, 0.05**2, 0.05**2])
LOOP_COV = np.diag([0.01**2, 0.01**2, 0.01**2])


def _square() -> list[tuple[float, float, float]]:
    """Truth: four 2 m sides, a left turn at each corner, back at the start (5 poses)."""
    poses = [(0.0, 0.0, 0.0)]
    for _ in range(4):
        poses.append(compose(poses[-1], (2.0, 0.0, math.pi / 2)))
    return poses


def test_a_loop_edge_pulls_a_drifted_chain_back() -> None:
    truth = _square()
    # Odometry edges with a yaw bias of 0.1 rad per side; the estimate drifts away.
    edges = [Edge(k, k + 1, (2.0, 0.0, math.pi / 2 + 0.1), ODOM_COV) for k in range(4)]
    drifted = [truth[0]]
    for e in edges:
        drifted.append(compose(drifted[-1], e.delta))
    err_before = math.hypot(drifted[4][0] - truth[4][0], drifted[4][1] - truth[4][1])
    loop = Edge(0, 4, relative(truth[0], truth[4]), LOOP_COV, robust=True)
    solved = optimise(np.asarray(drifted), [*edges, loop])
    err_after = math.hypot(solved[4, 0] - truth[4][0], solved[4, 1] - truth[4][1])
    assert err_before > 0.5
    assert err_after < 0.1 * err_before
    assert solved[0] == pytest.approx(np.asarray(truth[0]), abs=1e-6)  # the prior holds


def test_a_huber_loop_edge_gives_way_to_a_gross_outlier() -> None:
    truth = _square()
    edges = [Edge(k, k + 1, relative(truth[k], truth[k + 1]), ODOM_COV) for k in range(4)]
    wrong = (3.0, -2.0, 1.0)  # a false loop closure, far from the truth
    # As sure as one odometry edge: Huber's linear tail makes the outlier cheaper to reject.
    robust = optimise(np.asarray(truth), [*edges, Edge(0, 4, wrong, ODOM_COV, robust=True)])
    plain = optimise(np.asarray(truth), [*edges, Edge(0, 4, wrong, ODOM_COV)])

    def err(p: np.ndarray) -> float:
        return math.hypot(p[4, 0] - truth[4][0], p[4, 1] - truth[4][1])

    assert err(robust) < 0.5 * err(plain)
