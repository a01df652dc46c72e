"""The navigation stack the policies share.

* :mod:`policies.navigation.navigator`: the move_base-like :class:`Navigator` (Navfn global
  plan, DWA local control, patience, rotate recoveries) that drives the frontier baselines.
* :mod:`policies.navigation.bookkeeping`: :class:`GoalBlacklist` and :class:`ProgressWatch`,
  the goal blacklist and no-progress watch of the baselines and the semantic expert alike.
"""

from policies.navigation.bookkeeping import GoalBlacklist, ProgressWatch
from policies.navigation.navigator import (
    MoveBaseParams,
    Navigator,
    NavStatus,
    check_int_at_least,
    check_positive,
    warm_up_navigation_kernels,
)

__all__ = [
    "GoalBlacklist",
    "MoveBaseParams",
    "NavStatus",
    "Navigator",
    "ProgressWatch",
    "check_int_at_least",
    "check_positive",
    "warm_up_navigation_kernels",
]
