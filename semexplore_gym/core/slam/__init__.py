"""SLAM in the loop: a correlative scan matcher, keyframes, loop closure and a pose graph.

Pure algorithms (numpy, scipy, numba); the pose graph is solved by gtsam (the optional extra
``slam``) behind :mod:`.pose_graph`, imported only when a graph is optimised.
"""

from semexplore_gym.core.slam.backend import ScanSlam, compose, relative
from semexplore_gym.core.slam.matcher import (
    LikelihoodField,
    MatchResult,
    build_likelihood_field,
    match_scan,
)
from semexplore_gym.core.slam.params import SlamParams
from semexplore_gym.core.slam.pose_graph import GTSAM_HINT, Edge, optimise, require_gtsam

__all__ = [
    "GTSAM_HINT",
    "Edge",
    "LikelihoodField",
    "MatchResult",
    "ScanSlam",
    "SlamParams",
    "build_likelihood_field",
    "compose",
    "match_scan",
    "optimise",
    "relative",
    "require_gtsam",
]
