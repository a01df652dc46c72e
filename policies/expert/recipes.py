"""Recipes: what a semantic expert is made of.

An expert is a composition, not a set of switches: the plan sources it asks, in order (and the
variant of each), the rules its goal memory follows, the parameter values it starts from, and
how it reads the observed map. :class:`ExpertRecipe` holds the four; every named version of the expert
(:mod:`~semexplore_gym.policies.expert.versions`) and the paper's method alone are recipes:

==================  =========================================================================
recipe              what it holds
==================  =========================================================================
``semantic-v4``     today's expert (``semantic``): ``semantic-v3`` reading the wall slivers of
                    a SLAM map as wall (:class:`~semexplore_gym.policies.expert.map_reading.
                    WallSliverFill`); on the perfect map it is ``semantic-v3``
``semantic-v3``     the 0.3.0 expert: every plan source (:data:`DEFAULT_PLAN_SOURCES`),
                    Algorithm 1's goal over the grid's route with the grid's nearest frontier
                    as a candidate, every goal rule (:class:`GoalRules`), the map as observed
``semantic-v2``     the 0.2.0 expert: no ``view`` nor ``room_beyond_gap`` source, Algorithm 1's
                    goal along the map's path (with the entry detour) and no grid candidate;
                    no shuttle guard, a dropped goal beside another keeps no point of its own,
                    a goal is mapped once no UNKNOWN cell is near it
``semantic-paper``  the paper's method alone: the ``commanded``, ``retry`` and ``semantic``
                    sources (the map's path, nothing else), no goal rule, and the parameters
                    of :data:`PAPER_PARAMS` (area-level ``A_cost``, no robustness guard)
==================  =========================================================================

A recipe's parameter values are a layer below the user's (``semantic-paper[cost.w_v=2]``);
the user's own switches (``narrow_passages``, ...) stay in
:class:`~semexplore_gym.policies.expert.params.SemanticExpertParams`. The experts whose goals
an outside choice makes (the learning agents' driver, the frontier student, the learned
frontier value, the teams) run :data:`OUTSIDE_CHOICE`: ``semantic-v3``'s recipe with the
semantic source along the map's paths and without the grid candidate (:func:`for_outside_choice`
refuses a recipe they cannot honour); they read the map as observed, as they were trained and
measured.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

from semexplore_gym.policies.expert.goal_memory import GoalRules
from semexplore_gym.policies.expert.map_reading import WallSliverFill
from semexplore_gym.policies.expert.narrow_sources import NarrowFallback
from semexplore_gym.policies.expert.plan_context import PlanSource
from semexplore_gym.policies.expert.plan_sources import (
    DEFAULT_PLAN_SOURCES,
    CommandedGoal,
    CommittedFallback,
    LookAtNarrowFrontier,
    NearestFallback,
    PocketEscape,
    RetryFailedGoal,
    SemanticFrontier,
    insert_plan_source,
)

__all__ = [
    "OUTSIDE_CHOICE",
    "PAPER_METHOD",
    "PAPER_PARAMS",
    "SEMANTIC_V2",
    "SEMANTIC_V3",
    "SEMANTIC_V4",
    "ExpertRecipe",
    "GoalRules",
    "for_outside_choice",
]


@dataclass(frozen=True)
class ExpertRecipe:
    """The parts of one semantic expert.

    Attributes:
        name: What it is called (a policy spec for the named ones: ``semantic-v2``).
        plan_sources: The plan sources asked at each replan, in order.
        goal_rules: The rules the goal memory follows.
        params: Parameter values (flat or nested keys of ``SemanticExpertParams``) the recipe
            starts from, below the user's overrides (a plain dict, so that an expert pickles;
            treat it as read-only).
        map_reading: How it reads the observed map
            (:mod:`~semexplore_gym.policies.expert.map_reading`): None, as observed; a
            :class:`~semexplore_gym.policies.expert.map_reading.WallSliverFill`, with the wall
            slivers of a SLAM map read as wall.
    """

    name: str
    plan_sources: tuple[PlanSource, ...]
    goal_rules: GoalRules = field(default_factory=GoalRules)
    params: Mapping[str, object] = field(default_factory=dict)
    map_reading: WallSliverFill | None = None

    def __post_init__(self) -> None:
        names = self.source_names
        if self.goal_rules.view_unseen_frontiers and "view" not in names:
            raise ValueError(f"recipe {self.name!r}: the view rule needs the 'view' plan source")
        if self.goal_rules.grid_check and "nearest_fallback" not in names:
            raise ValueError(
                f"recipe {self.name!r}: the grid check needs the 'nearest_fallback' plan source"
            )

    @property
    def source_names(self) -> tuple[str, ...]:
        """The names of its plan sources, in order."""
        return tuple(s.name for s in self.plan_sources)

    @property
    def semantic_source(self) -> SemanticFrontier | None:
        """Its ``semantic`` plan source (None: it lists none)."""
        return next((s for s in self.plan_sources if isinstance(s, SemanticFrontier)), None)

    def with_source(
        self, source: PlanSource, *, before: str | None = None, after: str | None = None
    ) -> ExpertRecipe:
        """This recipe with ``source`` inserted before or after the source named so (else
        last): :func:`~semexplore_gym.policies.expert.plan_sources.insert_plan_source`."""
        sources = insert_plan_source(self.plan_sources, source, before=before, after=after)
        return replace(self, plan_sources=sources)

    def without(self, *names: str, name: str | None = None) -> ExpertRecipe:
        """This recipe without the plan sources so named (a variant; ``name``: its name).

        Raises:
            ValueError: it lists no source of one of the names.
        """
        missing = [n for n in names if n not in self.source_names]
        if missing:
            raise ValueError(f"recipe {self.name!r} lists no plan source {missing[0]!r}")
        kept = tuple(s for s in self.plan_sources if s.name not in names)
        return replace(self, name=name or self.name, plan_sources=kept)

    def with_map_reading(
        self, part: WallSliverFill | None, name: str | None = None
    ) -> ExpertRecipe:
        """This recipe reading the map through ``part`` (None: as observed; a variant)."""
        return replace(self, name=name or self.name, map_reading=part)

    def with_rules(self, name: str | None = None, **rules: bool) -> ExpertRecipe:
        """This recipe with goal rules changed (``shuttle_guard=False``; a variant)."""
        return replace(self, name=name or self.name, goal_rules=replace(self.goal_rules, **rules))

    def with_semantic(self, name: str | None = None, **variant: bool) -> ExpertRecipe:
        """This recipe with another variant of its ``semantic`` source (``grid_route=False``).

        Raises:
            ValueError: it lists no semantic source.
        """
        old = self.semantic_source
        if old is None:
            raise ValueError(f"recipe {self.name!r} lists no semantic plan source")
        parts = {k: getattr(old, k) for k in ("grid_candidate", "grid_route", "entry_detour")}
        new = SemanticFrontier(**{**parts, **variant})
        sources = tuple(new if s is old else s for s in self.plan_sources)
        return replace(self, name=name or self.name, plan_sources=sources)


#: The expert of the 0.3.0 release: every plan source, every goal rule, the map as observed.
SEMANTIC_V3 = ExpertRecipe("semantic-v3", DEFAULT_PLAN_SOURCES)

#: Today's expert (``semantic``): ``semantic-v3`` reading the wall slivers of a SLAM map as
#: wall (on the perfect map it is ``semantic-v3``, mission for mission).
SEMANTIC_V4 = SEMANTIC_V3.with_map_reading(WallSliverFill(), name="semantic-v4")

#: The expert of the 0.2.0 release, mission for mission.
SEMANTIC_V2 = ExpertRecipe(
    "semantic-v2",
    (
        CommandedGoal(),
        RetryFailedGoal(),
        SemanticFrontier(grid_candidate=False, grid_route=False),
        CommittedFallback(),
        NearestFallback(),
        PocketEscape(),
        NarrowFallback(),
        LookAtNarrowFrontier(),
    ),
    GoalRules(
        vanish_on_frontier=False,
        drop_each_point=False,
        shuttle_guard=False,
        view_unseen_frontiers=False,
    ),
)

#: The paper's parameter values where ours differ (the weights are the paper's by default).
PAPER_PARAMS: Mapping[str, object] = {
    "prune_by": "area",
    "min_frontier_width_m": 0.0,
    "resegment_min_new_m2": 0.0,
    "stop_confirmations": 1,
    "goal_commitment": False,
    "local_min_escape": False,
    "stuck_recovery": False,
    "potential_field": {
        "lookahead_clearance_m": 0.0,
        "map_guard_radius_m": 0.0,
        "guard_steer_max_rad": 0.0,
        "braking_guard": False,
    },
}

#: The paper's method alone (``semantic-paper``): Algorithm 1 along the map's path and nothing
#: of ours; ``configs/expert/paper_method.yaml`` names it (tests/policies/test_policy_config.py).
PAPER_METHOD = ExpertRecipe(
    "semantic-paper",
    (
        CommandedGoal(),
        RetryFailedGoal(),
        SemanticFrontier(grid_candidate=False, grid_route=False, entry_detour=False),
    ),
    GoalRules(
        vanish_on_frontier=False,
        drop_each_point=False,
        reach_blacklist=False,
        oscillation_guard=False,
        shuttle_guard=False,
        view_unseen_frontiers=False,
        grid_check=False,
    ),
    PAPER_PARAMS,
)

#: The recipe of an expert whose goals an outside choice makes (``semantic-v3``'s, the map as
#: observed): the grid's nearest frontier
#: would overrule that choice, and the learned agents were trained and measured driving the
#: map's paths.
OUTSIDE_CHOICE = SEMANTIC_V3.with_semantic("outside-choice", grid_candidate=False, grid_route=False)


def for_outside_choice(recipe: ExpertRecipe, policy: str) -> ExpertRecipe:
    """``recipe`` for ``policy``, whose goals an outside choice makes; a ValueError naming the
    part when its semantic source has one such a policy cannot honour (the grid candidate
    would overrule the choice; the grid route is not what the agents were measured with)."""
    src = recipe.semantic_source
    for part, on in (
        ("grid_candidate", src is not None and src.grid_candidate),
        ("grid_route", src is not None and src.grid_route),
    ):
        if on:
            raise ValueError(
                f"{policy} cannot honour recipe {recipe.name!r}: its semantic source's "
                f"{part} is on (an outside choice makes the goals); use the outside-choice recipe"
            )
    return recipe
