"""Full-knowledge coverage tours: the oracle explorer's planner (privileged: true map).

* :mod:`.problem`: :class:`PrivilegedWorld` (the ground truth a privileged env hands out) and
  :class:`SensorModel`;
* :mod:`.viewpoints`: standing mask, candidate viewpoints, visible sets (the env's LiDAR model);
* :mod:`.tour`: greedy set cover, geodesic distances, open tour by LKH, :func:`plan_coverage_tour`;
* :mod:`.refine`: the scans along the legs, and the local search over cover and order;
* :mod:`.lower_bound`: :func:`lower_bound`, a certified lower bound on the drive (and time) any
  explorer needs to reach the coverage goal.
"""

from semexplore_gym.core.coverage_tour.lower_bound import (
    LowerBound,
    LowerBoundParams,
    lower_bound,
)
from semexplore_gym.core.coverage_tour.problem import (
    PRIVILEGED_INFO_KEY,
    PrivilegedWorld,
    SensorModel,
)
from semexplore_gym.core.coverage_tour.tour import (
    SOLVER_HINT,
    CoverageTour,
    TourParams,
    geodesic_matrix,
    greedy_cover,
    open_tour_order,
    plan_coverage_tour,
)

__all__ = [
    "PRIVILEGED_INFO_KEY",
    "SOLVER_HINT",
    "CoverageTour",
    "LowerBound",
    "LowerBoundParams",
    "PrivilegedWorld",
    "SensorModel",
    "TourParams",
    "geodesic_matrix",
    "greedy_cover",
    "lower_bound",
    "open_tour_order",
    "plan_coverage_tour",
]
