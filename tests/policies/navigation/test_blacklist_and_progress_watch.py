"""Goal blacklist and progress watch: the bookkeeping the baselines and the expert share."""

from __future__ import annotations

import math

import pytest
from semexplore_gym.policies.navigation import GoalBlacklist, ProgressWatch


def test_blacklist_disc_and_box_include_their_boundary() -> None:
    disc = GoalBlacklist(0.5)
    box = GoalBlacklist(0.5, shape="box")
    for bl in (disc, box):
        assert (0.0, 0.0) not in bl
        bl.add((1.0, 1.0))
        assert (1.5, 1.0) in bl and (1.0, 0.5) in bl and (1.6, 1.0) not in bl
        assert len(bl) == 1 and list(bl) == [(1.0, 1.0)]
    # The box's corner is outside the disc.
    assert (1.45, 1.45) in box and (1.45, 1.45) not in disc
    box.clear()
    assert len(box) == 0 and (1.0, 1.0) not in box
    with pytest.raises(ValueError, match="shape"):
        GoalBlacklist(0.5, shape="ring")  # type: ignore[arg-type]


def test_motion_watch_inclusive_and_strict_radius() -> None:
    inclusive = ProgressWatch(10.0, radius_m=0.2, radius_inclusive=True)
    strict = ProgressWatch(10.0, radius_m=0.2)
    for w in (inclusive, strict):
        w.reset(0.0)
        assert not w.update(0.0, (0.0, 0.0))  # the first position becomes the anchor
        assert w.anchor_xy_m == (0.0, 0.0)
    # Moving exactly the radius is progress only for the inclusive (move_base) watch.
    assert not inclusive.update(9.0, (0.2, 0.0)) and inclusive.since_s == 9.0
    assert not strict.update(9.0, (0.2, 0.0)) and strict.since_s == 0.0
    assert strict.update(10.0, (0.2, 0.0))
    assert not inclusive.update(18.0, (0.3, 0.0)) and inclusive.update(19.0, (0.3, 0.0))


def test_map_growth_and_path_progress_reset_the_clock() -> None:
    w = ProgressWatch(5.0, min_new_cells=20, path_margin_m=0.1)
    w.reset(0.0, known_cells=100)
    w.track_path(3.0)
    assert not w.update(4.0, known_cells=119, remaining_m=2.95)  # neither criterion met
    assert not w.update(4.5, known_cells=119, remaining_m=2.85) and w.since_s == 4.5
    assert w.best_remaining_m == 2.85
    assert not w.update(9.0, known_cells=140, remaining_m=2.9) and w.known_cells == 140
    assert w.stalled(14.0) and not w.stalled(13.9)
    # A recovery holds the clock until it ends and forgets the best path.
    w.hold(20.0, known_cells=150)
    assert not w.stalled(24.0) and w.stalled(25.0) and math.isinf(w.best_remaining_m)
