"""The oracle's parameters (:class:`OracleParams`), apart from the policy that reads them
(:mod:`semexplore_gym.policies.oracle`, which re-exports them)."""

from __future__ import annotations

from dataclasses import dataclass, field

from semexplore_gym.core.coverage_tour import TourParams
from semexplore_gym.core.planning.potential_field import PotentialFieldParams

__all__ = ["OracleParams"]


@dataclass(frozen=True)
class OracleParams:
    """Parameters of :class:`OraclePolicy`.

    Attributes:
        tour: The static tour's settings (its legs' path cost is set from ``path_*`` below).
        potential_field: The path follower (the expert's defaults).
        goal_reached_radius_m: A viewpoint within this distance is reached. Small: the tour
            counts on the scan from the viewpoint itself (in a dead end, turning back 0.3 m
            short of it left cells unseen that the tour had counted).
        check_period_s: How often the viewpoints left are checked against the live map.
        min_gain_cells: A viewpoint that would add fewer unseen cells is not needed.
        path_prefer_clearance_m: Paths keep this far from walls where they can ...
        path_wall_cost: ... at up to this extra cost per metre nearer.
        goal_time_factor: Time budget of a viewpoint: this times its path at top speed ...
        min_goal_time_s: ... and at least this.
        stuck_timeout_s: The expert's stuck watch (no motion, no map growth).
        stuck_radius_m: See ``stuck_timeout_s``.
        backoff_duration_s: The expert's back-off manoeuvre.
        backoff_speed_fraction: See ``backoff_duration_s``.
        max_fallback_goals: Goals beyond the tour (see :meth:`OraclePolicy._fallback_cell`)
            before the oracle gives up.
        tight_margin_m: Where the true wall clearance at the robot or along the next
            ``tight_lookahead_m`` of its path is below ``radius + tight_margin_m``, the potential
            field (whose walls balance and stall the robot in a gap a few centimetres wider
            than it) gives way to exact, slow path tracking
            (:func:`~semexplore_gym.core.planning.path_tracking.tight_tracking_command`) ...
        tight_lookahead_m: See ``tight_margin_m``.
        tight_speed_mps: ... at this speed ...
        tight_track_lookahead_m: ... aiming at the path point this far ahead ...
        tight_turn_in_place_rad: ... and turning on the spot above this heading error. The
            robot then strays from its path by at most about lookahead x sin(error), 9 mm
            with the defaults: less than the 1 cm margin by which the env's reachable mask
            exceeds the robot's radius.
        repair_min_cells: At a viewpoint reached, when its scan left at least this many cells
            unseen that the plan counted on and no viewpoint left sees, the oracle looks again
            from the candidate within ...
        repair_radius_m: ... this path distance that sees most of them (before driving on,
            while it is near: a view through a gap between walls can vanish 0.1 m aside).
        finish_max_share: Shortcuts to the goal are looked for once the cells still needed are
            fewer than this share of the reachable mask ...
        finish_slack: ... at a candidate whose scan would see this many times the cells needed
            (a single scan's view is fragile: see :class:`~semexplore_gym.core.coverage_tour.refine.LegVisibility`).
        drive_planned_legs: Drive to the next viewpoint along the leg the tour counted (from
            the viewpoint just reached, or from where the rest of the tour was re-chosen), not
            the least-cost path from the robot's cell: the robot stops up to
            ``goal_reached_radius_m`` short of a viewpoint, and where two ways round a block
            cost about the same, a search from there can take the other way, which does not
            see what the planned leg would (on a DungeonMap this left a room unseen until a
            15 m detour at the end). False: the least-cost path from the robot (before).
    """

    tour: TourParams = field(default_factory=TourParams)
    potential_field: PotentialFieldParams = field(default_factory=PotentialFieldParams)
    goal_reached_radius_m: float = 0.1
    check_period_s: float = 0.4
    min_gain_cells: int = 1
    path_prefer_clearance_m: float = 0.2
    path_wall_cost: float = 4.0
    goal_time_factor: float = 3.0
    min_goal_time_s: float = 20.0
    stuck_timeout_s: float = 8.0
    stuck_radius_m: float = 0.25
    backoff_duration_s: float = 1.5
    backoff_speed_fraction: float = 0.5
    max_fallback_goals: int = 30
    tight_margin_m: float = 0.04
    tight_lookahead_m: float = 0.5
    tight_speed_mps: float = 0.08
    tight_track_lookahead_m: float = 0.06
    tight_turn_in_place_rad: float = 0.15
    finish_max_share: float = 0.03
    repair_min_cells: int = 10
    repair_radius_m: float = 1.0
    finish_slack: float = 1.5
    drive_planned_legs: bool = True
