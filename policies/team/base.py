"""The interface of team policies: all robots' observations in, one action per robot out."""

from __future__ import annotations

import abc
from typing import Any

import numpy as np
from semexplore_gym.policies.base import require_reset_before_act


class TeamPolicy(abc.ABC):
    """A controller for a team of robots (``SemanticExploreMulti-v0``'s agents).

    It sees what the robots see: each agent's observation and ``info``. Lifecycle:
    ``reset(observations, infos, seed=...)``, then ``act(observations, infos)`` each step,
    which returns ``{agent: action}``. ``done`` turns True when the team considers the mission
    over (``stop_reason`` says why). Before the first ``reset``, ``act`` raises
    :class:`~semexplore_gym.policies.base.PolicyNotResetError`.
    """

    name: str = "team"

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        require_reset_before_act(cls)

    def __init__(self) -> None:
        self.done = False
        self.stop_reason = ""
        self.agents: list[str] = []
        self.counters: dict[str, int] = {}
        self._reset_done = False

    def reset(
        self,
        observations: dict[str, dict[str, np.ndarray]],
        infos: dict[str, dict[str, Any]],
        seed: int | None = None,
    ) -> None:
        """Start a new episode with the agents of ``observations`` (in their order)."""
        self.done = False
        self.stop_reason = ""
        self.agents = list(observations)
        self.counters = {}

    def reset_members(
        self,
        members: list[Any],
        observations: dict[str, dict[str, np.ndarray]],
        infos: dict[str, dict[str, Any]],
        seed: int | None,
    ) -> None:
        """Reset one member policy per agent (agent ``i`` seeded ``seed + i``) and note every
        agent's start pose in ``self._poses``."""
        for i, (m, a) in enumerate(zip(members, self.agents, strict=True)):
            m.reset(observations[a], infos[a], seed=None if seed is None else seed + i)
        self._poses = [np.asarray(observations[a]["pose"], dtype=np.float64) for a in self.agents]

    @abc.abstractmethod
    def act(
        self, observations: dict[str, dict[str, np.ndarray]], infos: dict[str, dict[str, Any]]
    ) -> dict[str, np.ndarray]:
        """The action of every agent in ``observations`` for this step."""

    def overlays(self) -> dict[str, dict[str, Any]]:
        """Per agent, drawing hints (goal, path) for the team renderer; empty by default."""
        return {}

    def mission_metrics(self) -> dict[str, Any]:
        """Extra per-mission figures (name -> number); empty by default."""
        return {}


require_reset_before_act(TeamPolicy)  # its own reset marks too (subclasses that do not override it)
