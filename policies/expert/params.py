"""Parameters of the semantic expert (:class:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy`).

What the paper leaves open, and how the expert handles it (parameters in
:class:`SemanticExpertParams`, all times in simulated seconds):

* **Event-driven and periodic replanning** (``replan_period_s``, ``goal_reached_radius_m``,
  ``goal_check_radius_m``, ``resegment_min_new_m2``): the map changes every step, but
  segmentation and search run only every ``replan_period_s``, and at once when the goal is
  reached, when it vanishes (no frontier cell, UNKNOWN next to FREE, is left within
  ``goal_check_radius_m`` of it: its frontier has been mapped; without the goal rule
  ``vanish_on_frontier``, as in ``semantic-v2``: no UNKNOWN cell at all, which unknown space
  behind a mapped wall keeps from happening), when
  the path is used up, or when a recovery ends. A scheduled
  replan skips the segmentation (map-change gating) when less than ``resegment_min_new_m2``
  became known since the last one, e.g. while the robot crosses explored space.
* **Goal commitment** (``commitment_radius_m``, ``switch_margin``): at a replan the frontier
  pursued so far (same frontier pathway, or a frontier within ``commitment_radius_m`` of the
  old goal: frontiers recede as the robot approaches) is kept unless the best frontier is
  cheaper by more than ``switch_margin`` (cost units of ``C``). This stops the robot from
  oscillating between near-equal frontiers.
* **Narrow frontiers** (``min_frontier_width_m``, ``clearance_margin_m``): frontier openings
  narrower than ``min_frontier_width_m`` are ignored; the segmentation's clearance
  ``radius + clearance_margin_m`` already closes passages the robot cannot follow.
* **Path entry check**: when the straight first leg from the robot to the map's path crosses
  an occupied cell (the robot stands outside every area), a grid path with the robot's
  clearance leads to the path instead.
* **Grid-frontier fallback** (sources ``committed_fallback``, ``nearest_fallback``;
  ``fallback_min_frontier_m``,
  ``fallback_min_unknown_depth_m``, ``fallback_reach_m``): while the topometric map offers no
  frontier (no frontier pathway yet; frontiers the segmentation leaves out, such as unknown
  space seen only along a narrow laser fan or behind a gap), the robot drives to the nearest
  frontier a grid search with its clearance can reach
  (:mod:`semexplore_gym.core.frontiers.reachable`), and keeps that goal while it lasts. Tiny
  frontier groups (leaks through rasterised walls) and unknown slivers no scan can fill (the
  inside of walls, pockets along them) are ignored.
* **Wall slivers of a SLAM map** (recipe part ``map_reading``, ``sliver_max_width_m``,
  ``sliver_maps``; in ``semantic-v4``, on SLAM maps unless ``sliver_maps="all"``): UNKNOWN strips narrower than ``sliver_max_width_m``
  along walls (the inside of walls and their junctions, which a SLAM map rendered from
  keyframes shows through gaps in wall faces) read as OCCUPIED: no scan clears them, and where
  one meets the outside of the building it looks like a frontier with deep unknown space behind.
* **Stop confirmation** (``stop_confirmations``): the mission ends after this many consecutive
  replans found no frontier from either source.
* **Potential-field local minima** (in :class:`PotentialFieldParams`): the lookahead point
  ``G`` needs a sight line with the robot's clearance (``lookahead_clearance_m``), so the field
  does not pull the robot onto wall ends at corners and doorways; a collision guard
  (``safety_margin_m``, ``contact_margin_m``, ``braking_time_s``, ``map_guard_radius_m``) caps
  the speed before any obstacle; guard steering (``guard_steer_max_rad``) turns the robot
  towards the nearest open heading when the guard blocks the field's direction.
* **Local-minimum escape** (``local_min_timeout_s``, ``escape_duration_s``,
  ``escape_repulsion_scale``): when the field has held the robot almost still (forward command
  below 10 % of the maximum) for ``local_min_timeout_s`` (a dead end or doorway where repulsion
  cancels attraction), the repulsion is scaled down for ``escape_duration_s``; the collision
  guard still keeps the robot off the walls.
* **Stuck recovery** (``stuck_timeout_s``, ``stuck_radius_m``, ``progress_timeout_s``,
  ``progress_min_new_cells``, ``backoff_duration_s``, ``backoff_speed_fraction``): the robot is
  stuck when it stayed within ``stuck_radius_m`` for ``stuck_timeout_s`` while the map grew by
  fewer than ``progress_min_new_cells`` known cells, or when for ``progress_timeout_s`` neither
  the remaining path to its goal shrank (by 0.1 m) nor the map grew. It then backs off for
  ``backoff_duration_s`` at ``backoff_speed_fraction`` of the top speed (turning towards open
  space when the way back is blocked), blacklists the goal and replans.
* **Unreachable / unclearable goals** (``blacklist_radius_m``, ``max_goal_reaches``,
  ``max_goal_attempts``): a goal whose approach failed (a stuck recovery) is tried again by
  other approaches before it is dropped: first along a grid route on the current map, then
  from another side of the frontier (a standable point round it, away from where the robot got
  stuck). A goal is dropped after ``max_goal_attempts`` failed approaches, when the grid
  planner finds no path for the robot's disc to it, or when it was reached
  ``max_goal_reaches`` times without its frontier disappearing. Frontiers within
  ``blacklist_radius_m`` of a dropped goal are ignored.
* **Dropped frontiers come back** (``revive_window_m``, ``revive_min_changed_cells``,
  ``max_revivals``): when at least ``revive_min_changed_cells`` cells within
  ``revive_window_m`` of a dropped goal changed since it was dropped (the map around it grew or
  was corrected), it is considered again, at most ``max_revivals`` times. A goal dropped
  within ``blacklist_radius_m`` of an earlier drop is the same place for that count; with
  the goal rule ``drop_each_point`` (not in ``semantic-v2``) it keeps a point of its own too,
  so the frontier round it is ignored as well (without, the grid fallback could find the same
  goal again at once, for ever).
* **The stop rule**: the mission stops only when the grid fallback (a clearance-aware grid
  search, the final check) finds no frontier the robot's disc can reach, besides dropped goals;
  the stop reason names the rule and counts what was dropped and why.
* **Pocket escape** (source ``pocket_escape``, ``pocket_max_share``, ``pocket_clearance_margin_m``):
  the potential field may park the robot closer to a wall than the planner's clearance, in a
  spot cut off from the rest of the usable map by a gap narrower than that clearance. The grid
  check then searches only that pocket and finds nothing. When the robot's region holds less
  than ``pocket_max_share`` of the usable cells, the robot leaves it over cells with the
  clearance of its radius plus ``pocket_clearance_margin_m`` (half the usual margin), and the
  check runs again, with the full clearance, from the nearest region that is not a pocket.
* **A closer look at narrow frontiers** (source ``look``, ``look_reach_m``,
  ``look_min_unknown_depth_m``): frontiers too narrow for the robot at first sight are not
  discarded: before stopping, the robot drives to a standable point within ``look_reach_m`` of
  one with unknown space behind it to look closer, once per place; if the gap widens it is
  explored, otherwise it is dropped as looked-at.
* **Oscillation guard** (goal rule ``oscillation_guard``, ``oscillation_window_s``): the robot
  does not switch back to a goal it abandoned less than ``oscillation_window_s`` ago while its
  current goal is still a candidate (two far frontiers whose costs trade places as the robot moves
  would otherwise keep it shuttling between them, as on open ground).

* **Shuttle guard** (goal rule ``shuttle_guard``, ``shuttle_switches``, ``shuttle_radius_m``,
  ``shuttle_min_new_m2``): the oscillation guard counts seconds, and a shuttle can be slower
  than its window (the robot circling round clutter on its way to one goal while Algorithm 1's
  costs trade places, a switch every couple of minutes, the map not growing). The shuttle
  guard counts goal switches instead: when the robot adopts again a goal (within
  ``shuttle_radius_m``) that it adopted within its last ``shuttle_switches`` goals, and the map
  gained less than ``shuttle_min_new_m2`` since, it commits to that goal: no switching away
  until it is reached, its frontier is mapped or its approach fails (then the usual retries
  and drops, with the goal's time budget, take over).
* **A reached frontier that stays unknown gets another view** (source ``view``,
  ``view_rim_radius_m``, ``view_range_fraction``, ``view_min_range_margin_m``,
  ``view_clearance_margin_m``, ``view_min_unknown_m2``): a frontier reached ``max_goal_reaches`` times without clearing
  (or a narrow frontier looked at from close by without opening) is not dropped at once. The
  robot first drives to the nearest cell it can reach from which straight lines over known
  free cells reach the unknown cells next to the frontier (its rim: the unknown cells within
  ``view_rim_radius_m`` of it with a free neighbour), at a distance the LiDAR resolves
  (beyond its minimum range plus ``view_min_range_margin_m``, within ``view_range_fraction``
  of its maximum range), away from every place it has been (its trail: a rim cell in sight
  from there on the grid, yet unknown, is hidden in fact; :mod:`semexplore_gym.core.frontiers.
  viewpoint`); the planner's clearance first, then the robot radius plus
  ``view_clearance_margin_m``. The frontier is dropped only when no such
  place exists, or once the robot looked from there and it stayed unknown (once per place).
  A frontier whose unknown side is a sliver (less than ``view_min_unknown_m2`` of unknown
  connected to its rim) is dropped as before: a view drive across the map for a few cells costs
  more time than it gains.
* **Narrow passages** (``narrow_passages``, off by default while it is measured;
  ``narrow_clearance_margin_m``, ``tight_speed_mps``, ``tight_track_lookahead_m``,
  ``tight_turn_in_place_rad``, ``tight_centring_range_m``): a graded clearance. When nothing
  is reachable at the planners' clearance (robot radius plus ``clearance_margin_m``), the
  grid fallback searches once more at the radius plus ``narrow_clearance_margin_m`` (gaps
  from about 0.25 m for the 0.105 m robot on a 5 cm map), before the stop rule's look. Where such
  a plan's path has less than the planners' clearance on the map, the potential field (whose
  two walls balance and stall the robot in a gap barely wider than it) gives way to slow,
  exact tracking (:func:`~semexplore_gym.core.planning.path_tracking.tight_tracking_command`:
  ``tight_speed_mps``, aiming ``tight_track_lookahead_m`` ahead, turning on the spot above
  ``tight_turn_in_place_rad``), kept in the middle between the walls the scan measures on
  both sides within ``tight_centring_range_m`` (the map places a wall only to within a cell).
  Optionally the narrow tier gives up (``narrow_give_up_goals`` > 0, ``narrow_give_up_m2``)
  rather than take a new goal once its last ``narrow_give_up_goals`` goals together mapped less than
  ``narrow_give_up_m2`` of room to move (where the robot's centre may be at that clearance):
  cave walls are full of cracks, narrower than the robot or whose far side is rock,
  and driving into each costs minutes for nothing; it tries again once the map has grown by
  that much since (from elsewhere). ``narrow_give_up_s`` > 0 gives up by time instead: no new
  narrow goal once the map has gained less than ``narrow_give_up_m2`` of room to move in the
  last ``narrow_give_up_s`` seconds (both measured in docs/results.md; off by default).
* **Room beyond a gap** (source ``room_beyond_gap``, ``narrow_min_room_m2``; in
  ``semantic-v3``): when
  nothing is reachable at the planners' clearance, but the map shows room beyond a gap
  narrower than it (at least ``narrow_min_room_m2`` of space with the planners' clearance and a
  frontier next to it, seen through the gap:
  :mod:`semexplore_gym.core.frontiers.beyond_gap`), the robot goes through the gap at the
  narrow tier's clearance (tracked slowly and exactly as above) and on to that frontier. It
  needs no ``narrow_passages``: it drives into a gap only where the LiDAR already saw room on
  the far side, never into a crack whose far side is rock, so it costs nothing where nothing
  lies beyond (``narrow_passages`` comes after it and probes the cracks too).

Which of these an expert holds is its recipe's (:mod:`semexplore_gym.policies.expert.recipes`:
``semantic-v3``, ``semantic-v2``, ``semantic-paper``, the paper's method alone); the
parameters here tune them. The on/off switches left are the user's choices.

``counters`` and ``events`` record how often each behaviour fired.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import ClassVar, Literal, TypeVar

from semexplore_gym.core.planning.graph_search import FrontierCostWeights
from semexplore_gym.core.planning.potential_field import PotentialFieldParams
from semexplore_gym.core.topometric.params import SegmentationParams
from semexplore_gym.core.validation import require_finite

__all__ = [
    "REMOVED_SWITCHES",
    "GoalMemoryParams",
    "PathFollowingParams",
    "SemanticExpertParams",
]

_Group = TypeVar("_Group")

_V2 = "semantic-v3 has it; for the 0.2.0 expert without it use semantic-v2"
_PAPER = "every version has it; for the paper's method without it use semantic-paper"

#: The on/off switches that left the params: each behaviour is now a part an expert's recipe
#: lists or not (:mod:`semexplore_gym.policies.expert.recipes`); setting one is an error that
#: says which named version or preset gives the behaviour without it.
REMOVED_SWITCHES: dict[str, str] = {
    "vanish_on_frontier": f"'goal mapped when no frontier cell is near' is a goal rule; {_V2}",
    "drop_each_point": f"'each dropped goal keeps its point' is a goal rule; {_V2}",
    "shuttle_guard": f"the shuttle guard is a goal rule of the recipe; {_V2}",
    "shuttle_guard_holds_grid": f"the shuttle guard holds against the grid candidate; {_V2}",
    "view_unseen_frontiers": f"the 'view' plan source is part of the recipe; {_V2}",
    "room_beyond_gaps": f"the 'room_beyond_gap' plan source is part of the recipe; {_V2}",
    "grid_candidate": f"the semantic source's grid candidate is part of the recipe; {_V2}",
    "semantic_grid_route": f"the semantic source's grid route is part of the recipe; {_V2}",
    "grid_fallback": f"the grid fallback plan sources are part of the recipe; {_PAPER}",
    "pocket_escape": f"the 'pocket_escape' plan source is part of the recipe; {_PAPER}",
    "look_at_narrow_frontiers": f"the 'look' plan source is part of the recipe; {_PAPER}",
    "oscillation_guard": f"the oscillation guard is a goal rule of the recipe; {_PAPER}",
    "reach_blacklist": f"dropping goals reached but not cleared is a goal rule; {_PAPER}",
    "entry_detour": f"the semantic source's entry detour is part of the recipe; {_PAPER}",
}


@dataclass(frozen=True)
class PathFollowingParams:
    """The path follower's group of :class:`SemanticExpertParams` (same names and meaning).

    :class:`~semexplore_gym.policies.expert.path_following.PathFollower` reads these: the
    potential field, the local-minimum escape, the progress watch and the stuck recovery.
    """

    potential_field: PotentialFieldParams
    local_min_escape: bool
    local_min_timeout_s: float
    escape_duration_s: float
    escape_repulsion_scale: float
    stuck_recovery: bool
    stuck_timeout_s: float
    stuck_radius_m: float
    progress_timeout_s: float
    progress_min_new_cells: int
    backoff_duration_s: float
    backoff_speed_fraction: float
    goal_time_factor: float
    min_goal_time_s: float
    narrow_passages: bool
    clearance_margin_m: float
    tight_speed_mps: float
    tight_track_lookahead_m: float
    tight_turn_in_place_rad: float
    tight_centring_range_m: float


@dataclass(frozen=True)
class GoalMemoryParams:
    """The goal memory's group of :class:`SemanticExpertParams` (same names and meaning).

    :class:`~semexplore_gym.policies.expert.goal_memory.GoalMemory` reads these: dropping,
    retrying and reviving goals, the oscillation guard and the stop reason.
    """

    blacklist_radius_m: float
    max_goal_reaches: int
    max_goal_attempts: int
    revive_window_m: float
    revive_min_changed_cells: int
    max_revivals: int
    oscillation_window_s: float
    shuttle_switches: int
    shuttle_radius_m: float
    shuttle_min_new_m2: float


def _group(cls: type[_Group], params: SemanticExpertParams) -> _Group:
    """The fields of ``cls`` taken from ``params`` (YAML keys stay flat: one level)."""
    return cls(**{f.name: getattr(params, f.name) for f in fields(cls)})  # type: ignore[arg-type]


@dataclass(frozen=True)
class SemanticExpertParams:
    """All parameters of the semantic expert (defaults: the paper's weights, then ours).

    Four on/off switches are the user's choice here (``narrow_passages``,
    ``goal_commitment``, ``local_min_escape``, ``stuck_recovery``), two more sit in the nested
    groups (``potential_field.braking_guard``, ``segmentation.keep_debug``); which plan sources
    and goal rules an expert holds is its recipe's (:mod:`semexplore_gym.policies.expert.
    recipes`), and a removed switch (:data:`REMOVED_SWITCHES`) is an error naming the version
    that gives the behaviour.

    Attributes:
        cost: Frontier cost weights ``w_v``, ``w_p``, ``w_I`` (defaults: the paper's, defined
            once in :class:`FrontierCostWeights`).
        potential_field: Potential field ``f_g``, ``f_o``, ``f_l`` (defaults: the paper's, in
            :class:`PotentialFieldParams`) and the command mapping.
        segmentation: Parameters of ``segment_map`` (the robot clearance is not one of them).
        prune_by: ``A_cost`` slots of Algorithm 1: ``"opening"`` (exact) or ``"area"``.
        clearance_margin_m: Segmentation clearance is the robot radius plus this.
        replan_period_s: Period of the scheduled replans (segmentation + Algorithm 1).
        resegment_min_new_m2: A scheduled replan re-segments the map only if at least this much
            area became known since the last segmentation; otherwise it reruns Algorithm 1 on
            the previous topometric map from the new pose.
        goal_reached_radius_m: The goal counts as reached within this distance.
        goal_check_radius_m: The goal has vanished (replan at once) when no UNKNOWN cell is
            left within this distance of it (with ``vanish_on_frontier``: no frontier cell).
        commitment_radius_m: A frontier this close to the current goal is the same goal.
        switch_margin: Another frontier replaces the current one only if cheaper by this much.
        min_frontier_width_m: Narrower frontier openings are ignored.
        fallback_min_frontier_m: Smallest frontier group the fallback considers (its cell count
            times the resolution, metres). Smaller groups are mostly leaks through gaps in
            rasterised walls, which no robot can clear.
        fallback_min_unknown_depth_m: The fallback ignores frontiers without unknown space at
            least this far from every known cell next to them (the inside of thick walls seen
            through gaps in their mapped faces, thin pockets along walls: no scan fills them).
        fallback_reach_m: The fallback's goal lies within this distance of the frontier.
        stop_confirmations: Consecutive replans without any frontier before stopping.
        local_min_timeout_s: Time almost still (forward command < 10 % of max) before escaping.
        escape_duration_s: Duration of a local-minimum escape.
        escape_repulsion_scale: Factor on ``f_o`` during an escape.
        stuck_timeout_s: Time within ``stuck_radius_m`` (and no map growth) that means stuck.
        stuck_radius_m: See ``stuck_timeout_s``.
        progress_timeout_s: Time without path progress nor map growth that means stuck.
        progress_min_new_cells: Known cells the map must gain to count as growth.
        backoff_duration_s: Length of the back-off manoeuvre of a stuck recovery.
        backoff_speed_fraction: Back-off speed as a fraction of the top speed.
        blacklist_radius_m: Frontiers this close to a blacklisted goal are ignored.
        max_goal_reaches: A goal reached this many times without clearing is blacklisted.
        max_goal_attempts: Failed approaches (stuck recoveries) before a goal is dropped; 1
            drops it at the first failure.
        revive_window_m: Radius round a dropped goal watched for map changes.
        revive_min_changed_cells: Changed cells in that window that bring a dropped goal back.
        max_revivals: How often one place may come back.
        pocket_max_share: The robot's region is a pocket when it holds less than this share
            of the usable cells.
        pocket_clearance_margin_m: The way out of a pocket keeps the robot radius plus this
            from walls.
        look_reach_m: The look point lies within this distance of the frontier.
        look_min_unknown_depth_m: Unknown depth behind a narrow frontier worth a look.
        look_min_frontier_m: Smallest narrow frontier worth a look (cells x resolution); one-
            or two-cell groups are leaks through rasterised walls.
        look_seen_radius_m: A narrow frontier the robot already passed this close to had its
            look (the LiDAR resolved it then).
        look_clearance_fraction: A frontier a robot with this fraction of the clearance could
            reach is narrow at first sight and worth a look; narrower gaps are leaks.
        max_look_drives: Drives to look points per mission. A gap seen narrow that opens up is
            rare; most candidates are the mixed cells along a wall's unseen far side, so the
            drives are capped (frontiers the trail already passed close to are dropped free).
        oscillation_window_s: How long an abandoned goal stays "recent".
        shuttle_switches: How many of the last adopted goals a new goal is compared with.
        shuttle_radius_m: A goal this close to an earlier one is the same goal.
        shuttle_min_new_m2: Known area the map must gain between two adoptions of the same goal
            for the second not to count as a shuttle.
        view_rim_radius_m: The unknown cells to see lie within this distance of the frontier.
        view_range_fraction: A view place lies within this share of the LiDAR's maximum range
            of them (farther, beams are more than a cell apart).
        view_min_range_margin_m: ... and farther than the LiDAR's minimum range plus this.
        view_clearance_margin_m: Without a view place at the planner's clearance, one at the
            robot radius plus this (a smaller physical margin) is sought.
        view_min_unknown_m2: Unknown area connected to the frontier's rim below which it is
            dropped without a view (a sliver; 0: view every one).
        narrow_passages: The graded clearance for passages narrower than the planners'
            clearance (see the module docstring).
        narrow_clearance_margin_m: Its last search's clearance on the map: the robot radius
            plus this (may be slightly negative: the map places each wall only to within a
            cell, so a passage 0.25 m wide can show as 4 free cells, 0.1 m from the walls'
            cells at its middle; the scan then says whether the robot fits).
        narrow_give_up_goals: The narrow tier takes no new goal when its last this many (0, the
            default: it never gives up; 4 measured in docs/results.md) ...
        narrow_give_up_m2: ... mapped less than this much room to move in all (area where the
            robot's centre may be at the narrow clearance, since the first of them was
            adopted; 0 goals: never gives up).
        narrow_give_up_s: The narrow tier takes no new goal once this long (seconds) has passed
            since the map last gained ``narrow_give_up_m2`` of room to move, counted from its
            first goal (0, the default: never; 100 measured in docs/results.md).
        narrow_min_room_m2: Room beyond a gap is at least this much area the robot's centre
            may take at the planners' clearance.
        tight_speed_mps: Forward speed where a narrow plan's path is tight.
        tight_track_lookahead_m: There it aims at the path point this far ahead ...
        tight_turn_in_place_rad: ... and turns on the spot above this heading error ...
        tight_centring_range_m: ... centred between walls the scan sees within this on both
            sides.
        goal_commitment: Keep the current frontier unless another is clearly cheaper.
        local_min_escape: Lower the repulsion when the field holds the robot still.
        stuck_recovery: Watch progress; back off, retry or drop the goal when stuck.
        goal_time_factor: A goal not reached within this many times its path's length at full
            speed (at least ``min_goal_time_s``) counts as a failed approach (part of
            ``stuck_recovery``): the robot may be moving but not getting there.
        min_goal_time_s: See ``goal_time_factor``.
        sliver_max_width_m: With a recipe that reads a SLAM map's wall slivers as wall
            (``semantic-v4``: :mod:`~semexplore_gym.policies.expert.map_reading`), UNKNOWN
            strips narrower than this along walls are read as OCCUPIED (the inside of walls,
            and the corners where they meet, that a SLAM map shows through gaps in their faces).
        sliver_maps: On which maps: ``"slam"``, a map the env's SLAM back end builds (the
            perfect map is read as observed); ``"all"``, every map.
    """

    removed_config_keys: ClassVar[dict[str, str]] = REMOVED_SWITCHES

    cost: FrontierCostWeights = field(default_factory=FrontierCostWeights)
    potential_field: PotentialFieldParams = field(default_factory=PotentialFieldParams)
    segmentation: SegmentationParams = field(default_factory=SegmentationParams)
    prune_by: Literal["opening", "area"] = "opening"
    clearance_margin_m: float = 0.05
    replan_period_s: float = 2.0
    resegment_min_new_m2: float = 0.1
    goal_reached_radius_m: float = 0.35
    goal_check_radius_m: float = 0.5
    commitment_radius_m: float = 1.0
    switch_margin: float = 0.5
    min_frontier_width_m: float = 0.25
    fallback_min_frontier_m: float = 0.35
    fallback_min_unknown_depth_m: float = 0.2
    fallback_reach_m: float = 0.1
    stop_confirmations: int = 2
    local_min_timeout_s: float = 3.0
    escape_duration_s: float = 4.0
    escape_repulsion_scale: float = 0.3
    stuck_timeout_s: float = 8.0
    stuck_radius_m: float = 0.25
    progress_timeout_s: float = 30.0
    progress_min_new_cells: int = 20
    backoff_duration_s: float = 1.5
    backoff_speed_fraction: float = 0.5
    blacklist_radius_m: float = 0.5
    max_goal_reaches: int = 2
    max_goal_attempts: int = 3
    revive_window_m: float = 0.75
    revive_min_changed_cells: int = 40
    max_revivals: int = 2
    pocket_max_share: float = 0.1
    pocket_clearance_margin_m: float = 0.025
    look_reach_m: float = 1.0
    look_min_unknown_depth_m: float = 0.3
    look_min_frontier_m: float = 0.15
    look_seen_radius_m: float = 1.5
    look_clearance_fraction: float = 0.5
    max_look_drives: int = 2
    oscillation_window_s: float = 120.0
    shuttle_switches: int = 6
    shuttle_radius_m: float = 1.0
    shuttle_min_new_m2: float = 1.0
    view_rim_radius_m: float = 0.5
    view_range_fraction: float = 0.7
    view_min_range_margin_m: float = 0.15
    view_clearance_margin_m: float = 0.025
    view_min_unknown_m2: float = 0.5
    narrow_passages: bool = False
    narrow_clearance_margin_m: float = -0.005
    narrow_give_up_goals: int = 0
    narrow_give_up_m2: float = 0.5
    narrow_give_up_s: float = 0.0
    narrow_min_room_m2: float = 0.5
    tight_speed_mps: float = 0.08
    tight_track_lookahead_m: float = 0.06
    tight_turn_in_place_rad: float = 0.15
    tight_centring_range_m: float = 0.3
    goal_commitment: bool = True
    local_min_escape: bool = True
    stuck_recovery: bool = True
    goal_time_factor: float = 4.0
    min_goal_time_s: float = 90.0
    sliver_max_width_m: float = 0.25
    sliver_maps: str = "slam"

    def __post_init__(self) -> None:
        if self.sliver_maps not in ("slam", "all"):
            raise ValueError(f"sliver_maps must be 'slam' or 'all', got {self.sliver_maps!r}")
        if self.prune_by not in ("opening", "area"):
            raise ValueError(f"prune_by must be 'opening' or 'area', got {self.prune_by!r}")
        positive = (
            "replan_period_s",
            "goal_reached_radius_m",
            "goal_check_radius_m",
            "stuck_timeout_s",
            "stuck_radius_m",
            "progress_timeout_s",
            "local_min_timeout_s",
            "sliver_max_width_m",
        )
        require_finite(self, positive, positive=True)
        nonneg = (
            "clearance_margin_m",
            "commitment_radius_m",
            "switch_margin",
            "min_frontier_width_m",
            "fallback_min_frontier_m",
            "fallback_min_unknown_depth_m",
            "resegment_min_new_m2",
            "fallback_reach_m",
            "escape_duration_s",
            "escape_repulsion_scale",
            "backoff_duration_s",
            "blacklist_radius_m",
            "revive_window_m",
            "look_min_unknown_depth_m",
            "goal_time_factor",
            "min_goal_time_s",
            "look_min_frontier_m",
            "look_seen_radius_m",
            "look_clearance_fraction",
            "look_reach_m",
            "oscillation_window_s",
            "pocket_clearance_margin_m",
            "pocket_max_share",
            "shuttle_radius_m",
            "shuttle_min_new_m2",
            "view_rim_radius_m",
            "view_min_range_margin_m",
            "view_clearance_margin_m",
            "view_min_unknown_m2",
        )
        require_finite(self, nonneg, positive=False)
        self._check_narrow()
        if not 0.0 < self.view_range_fraction <= 1.0:
            raise ValueError(
                f"view_range_fraction must be in (0, 1], got {self.view_range_fraction!r}"
            )
        if self.pocket_max_share > 1.0:
            raise ValueError(f"pocket_max_share must be in [0, 1], got {self.pocket_max_share!r}")
        if not 0.0 <= self.backoff_speed_fraction <= 1.0:
            raise ValueError(
                f"backoff_speed_fraction must be in [0, 1], got {self.backoff_speed_fraction!r}"
            )
        for name in (
            "stop_confirmations",
            "max_goal_reaches",
            "progress_min_new_cells",
            "max_goal_attempts",
            "revive_min_changed_cells",
            "shuttle_switches",
        ):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)!r}")
        if int(self.max_look_drives) < 0:
            raise ValueError(f"max_look_drives must be >= 0, got {self.max_look_drives!r}")
        if int(self.max_revivals) < 0:
            raise ValueError(f"max_revivals must be >= 0, got {self.max_revivals!r}")

    def _check_narrow(self) -> None:
        m = self.narrow_clearance_margin_m
        if isinstance(m, bool) or not isinstance(m, (int, float)) or not -0.05 <= m <= 0.5:
            raise ValueError(f"narrow_clearance_margin_m must be in [-0.05, 0.5] m, got {m!r}")
        k = self.narrow_give_up_goals
        if isinstance(k, bool) or not isinstance(k, int) or k < 0:
            raise ValueError(f"narrow_give_up_goals must be an integer >= 0, got {k!r}")
        require_finite(
            self, ("narrow_give_up_m2", "narrow_give_up_s", "narrow_min_room_m2"), positive=False
        )
        tight = ("tight_speed_mps", "tight_track_lookahead_m", "tight_turn_in_place_rad")
        require_finite(self, (*tight, "tight_centring_range_m"), positive=True)

    @property
    def path_following(self) -> PathFollowingParams:
        """The path follower's parameters (a view of this object's fields)."""
        return _group(PathFollowingParams, self)

    @property
    def goal_memory(self) -> GoalMemoryParams:
        """The goal memory's parameters (a view of this object's fields)."""
        return _group(GoalMemoryParams, self)
