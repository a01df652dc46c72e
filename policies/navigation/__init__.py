"""The navigation stack the policies share.

* :mod:`semexplore_gym.policies.navigation.navigator`: the move_base-like :class:`Navigator` (Navfn global
  plan, DWA local control, patience, rotate recoveries) that drives the frontier baselines.
* :mod:`semexplore_gym.policies.navigation.blacklist`: :class:`GoalBlacklist`, the goals given up on.
* :mod:`semexplore_gym.policies.navigation.progress_watch`: :class:`ProgressWatch`, the no-progress
  watch.
* :mod:`semexplore_gym.policies.navigation.frontier_memory`: :class:`FrontierMemory`, failed
  approaches, dropped goals that come back, recently abandoned goals (the semantic expert's).
* :mod:`semexplore_gym.policies.navigation.side_approach`: :func:`side_approach`, another way to a
  goal whose first approach failed (the semantic expert's retries).
* :mod:`semexplore_gym.policies.navigation.recovery`: the recovery manoeuvres, :class:`RotateRecovery`
  (move_base's, the baselines') and :class:`BackoffRecovery` (the expert's).

The baselines and the expert share the blacklist and the progress watch, each parametrised to
its own rules:

==================  ===================================  =====================================
                    frontier baselines (``Navigator``)   semantic expert
==================  ===================================  =====================================
blacklist near      FE: a box of half-size               a disc of ``blacklist_radius_m``
                    ``blacklist_box_m`` (cleared when a
                    goal succeeds); nearest: a disc
progress is         moving ``oscillation_distance_m``    moving more than ``stuck_radius_m``
                    or more (move_base's oscillation     or the map growing; and, separately,
                    check)                               the rest of the path shrinking or
                                                         the map growing
on no progress      rotate in place, abort after         back off, then blacklist the goal
                    ``max_recoveries``
==================  ===================================  =====================================

The recovery manoeuvres differ (move_base's in-place rotation against the expert's back-off) and
stay with their owners; the bookkeeping that decides *when* to recover and *which* goals to skip
is shared.
"""

from semexplore_gym.policies.navigation.blacklist import GoalBlacklist
from semexplore_gym.policies.navigation.navigator import (
    MoveBaseParams,
    Navigator,
    NavStatus,
    check_int_at_least,
    check_positive,
    warm_up_navigation_kernels,
)
from semexplore_gym.policies.navigation.progress_watch import ProgressWatch
from semexplore_gym.policies.navigation.recovery import BackoffRecovery, RotateRecovery

__all__ = [
    "BackoffRecovery",
    "GoalBlacklist",
    "MoveBaseParams",
    "NavStatus",
    "Navigator",
    "ProgressWatch",
    "RotateRecovery",
    "check_int_at_least",
    "check_positive",
    "warm_up_navigation_kernels",
]
