"""How often each behaviour of the semantic expert fired in a mission (:class:`ExpertCounters`).

The expert and its parts count into one :class:`ExpertCounters`;
:attr:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy.counters` gives the same
numbers as a plain ``{name: int}`` dict (what the mission runners store).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, fields
from typing import Any

__all__ = ["ExpertCounters"]


@dataclass
class ExpertCounters:
    """Counts of one mission (cleared by the expert's ``reset``).

    Attributes:
        replans: Replans run (segmentation or search and a goal choice).
        segmentations: Replans that segmented the map anew.
        semantic_plans: Plans adopted from Algorithm 1's frontiers.
        fallback_plans: Every other plan adopted (grid fallback, retry, look, commanded).
        entry_detours: Grid detours onto a semantic path whose first leg crossed a wall.
        semantic_grid_routes: Semantic plans driven over the grid's route to Algorithm 1's goal
            instead of the map's path (the semantic source's ``grid_route``).
        grid_frontier_plans: Replans where the grid's nearest frontier cost less than
            Algorithm 1's choice and was taken instead (its ``grid_candidate``).
        escapes: Local-minimum escapes of the potential field.
        recoveries: Stuck recoveries (back-offs).
        blacklisted: Goals dropped.
        switches: Goal switches (a new goal farther than the commitment radius).
        retries: Failed approaches retried another way.
        revived: Dropped goals brought back by a map change.
        looks: Narrow frontiers looked at (or passed close by) and dropped.
        look_drives: Drives to a look point.
        pocket_escapes: Plans that first leave a pocket of the usable map.
        narrow_plans: Plans through passages narrower than the planners' clearance.
        tight_steps: Steps driven by exact tracking in such a passage.
        goal_timeouts: Goals not reached within their time budget.
        oscillations_blocked: Switches back to a recently abandoned goal refused.
        shuttles: Goals adopted again without the map growing (the shuttle guard commits).
        view_drives: Drives to a place that sees into a frontier reached without clearing.
        scored_replans: Replans with at least one scored frontier (instrumentation only).
        semantic_decisive: Of those, replans where the metric cost alone would have chosen
            another frontier (instrumentation only).
        replans_by_reason: Replans by reason (``"period"``, ``"goal_reached"``, ...), in the
            order the reasons first occurred.
    """

    replans: int = 0
    segmentations: int = 0
    semantic_plans: int = 0
    fallback_plans: int = 0
    entry_detours: int = 0
    semantic_grid_routes: int = 0
    grid_frontier_plans: int = 0
    escapes: int = 0
    recoveries: int = 0
    blacklisted: int = 0
    switches: int = 0
    retries: int = 0
    revived: int = 0
    looks: int = 0
    look_drives: int = 0
    pocket_escapes: int = 0
    narrow_plans: int = 0
    tight_steps: int = 0
    goal_timeouts: int = 0
    oscillations_blocked: int = 0
    shuttles: int = 0
    view_drives: int = 0
    scored_replans: int = 0
    semantic_decisive: int = 0
    replans_by_reason: dict[str, int] = field(default_factory=dict)

    def clear(self) -> None:
        """Every count back to 0 (in place: the expert's parts keep this object)."""
        for f in fields(self):
            if f.name != "replans_by_reason":
                setattr(self, f.name, 0)
        self.replans_by_reason.clear()

    def count_replan_reason(self, reason: str) -> None:
        """Count one replan due to ``reason``."""
        self.replans_by_reason[reason] = self.replans_by_reason.get(reason, 0) + 1

    def record_scored_replan(self, candidates: Sequence[Any]) -> None:
        """Count a replan whose cheapest frontier by ``C`` is not cheapest by the metric part.

        The metric part ``d / L_path + w_v v`` is ``C`` with ``w_p = w_I = 0``; both choices are
        made among the same candidates (the ones Algorithm 1 found with the full cost, cheapest
        ``C`` first, each with a ``metric_cost``). A tie on the metric cost counts as agreement.
        ``semantic_decisive / scored_replans`` is the share of replans in which the semantic
        gain changed the chosen frontier. No candidate: nothing is counted.
        """
        if not candidates:
            return
        self.scored_replans += 1
        best_metric = min(c.metric_cost for c in candidates)
        if candidates[0].metric_cost > best_metric + 1e-9:
            self.semantic_decisive += 1

    def semantic_share(self) -> float | None:
        """``semantic_decisive / scored_replans`` (None before any scored replan)."""
        if self.scored_replans <= 0:
            return None
        return self.semantic_decisive / self.scored_replans

    def as_dict(self) -> dict[str, int]:
        """``{name: count}``, then ``replan_<reason>`` for each reason that occurred."""
        out = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "replans_by_reason"}
        out.update({f"replan_{r}": n for r, n in self.replans_by_reason.items()})
        return out
