"""The navigation stack the policies share.

* :mod:`semexplore_gym.policies.navigation.navigator`: the move_base-like :class:`Navigator` (Navfn global
  plan, DWA local control, patience, rotate recoveries) that drives the frontier baselines.
* :mod:`semexplore_gym.policies.navigation.bookkeeping`: :class:`GoalBlacklist` and :class:`ProgressWatch`,
  the goal blacklist and no-progress watch of the baselines and the semantic expert alike.
* :mod:`semexplore_gym.policies.navigation.recovery`: the recovery manoeuvres, :class:`RotateRecovery`
  (move_base's, the baselines') and :class:`BackoffRecovery` (the expert's).
"""

from semexplore_gym.policies.navigation.bookkeeping import GoalBlacklist, ProgressWatch
from semexplore_gym.policies.navigation.navigator import (
    MoveBaseParams,
    Navigator,
    NavStatus,
    check_int_at_least,
    check_positive,
    warm_up_navigation_kernels,
)
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
