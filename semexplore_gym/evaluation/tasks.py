"""The benchmark's missions: one :class:`Task` per (world, policy, seed), seed-major."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from semexplore_gym.core.validation import short_repr
from semexplore_gym.evaluation.errors import PARAM, ParameterError


def resolve_world(world: str, seed: int) -> str:
    """A world spelling with a ``seed=*`` placeholder replaced by ``seed``."""
    return world.replace("seed=*", f"seed={int(seed)}")


@dataclass(frozen=True)
class Task:
    """One mission to run."""

    world: str
    policy: str
    seed: int
    max_time_s: float | None = None
    env_config: Any = None
    policy_overrides: dict[str, Any] = field(default_factory=dict)

    @property
    def key(self) -> tuple[str, str, int]:
        return (self.world, self.policy, self.seed)

    @property
    def resolved_world(self) -> str:
        """The world spelling with a ``seed=*`` placeholder replaced by this task's seed."""
        return resolve_world(self.world, self.seed)


def expand_tasks(
    worlds: Sequence[str],
    policies: Sequence[str],
    seeds: Sequence[int],
    max_time_s: float | None = None,
    env_config: Any = None,
    policy_overrides: dict[str, Any] | None = None,
) -> list[Task]:
    """Every (world, policy, seed), ordered seed-major so early results are already paired.

    Raises:
        ParameterError: an empty list, a blank policy name, or an item listed twice (naming
            ``worlds``, ``policies`` or ``seeds``).
    """
    if not worlds:
        raise ParameterError("worlds", f"no worlds given ({PARAM} is empty)")
    if not policies:
        raise ParameterError("policies", f"no policies given ({PARAM} is empty)")
    if not seeds:
        raise ParameterError("seeds", f"no seeds given ({PARAM} is empty; runs must be >= 1)")
    for p in policies:
        if not isinstance(p, str) or not p.strip():
            raise ParameterError("policies", f"bad policy name {short_repr(p)} in {PARAM}")
    for what, items in (("worlds", worlds), ("policies", policies), ("seeds", seeds)):
        seen: set = set()
        for item in items:
            if item in seen:
                raise ParameterError(
                    what,
                    f"{PARAM} lists {short_repr(item)} twice; each must appear once "
                    "(a repeat would count the same missions twice)",
                )
            seen.add(item)
    return [
        Task(w, p, int(s), max_time_s, env_config, dict(policy_overrides or {}))
        for s in seeds
        for w in worlds
        for p in policies
    ]


def parse_seeds(runs: int, seed0: int = 0) -> list[int]:
    """The ``runs`` seeds from ``seed0`` on.

    Raises:
        ParameterError: ``runs`` below 1.
    """
    if runs < 1:
        raise ParameterError("runs", f"{PARAM} must be >= 1, got {runs}")
    return list(range(seed0, seed0 + runs))
