"""Choose among every reachable frontier option; the frontier student's navigation drives.

:class:`OptionChoice` (``SemanticExploreOptions-v0``) turns ``SemanticExplore-v0`` into a
decision process over the frontier student's choices: whenever the student
(``semexplore_gym.policies.frontier_student.FrontierStudentPolicy``) would choose a new goal
among two or more reachable frontiers, the agent chooses instead. Between choices the student,
the expert's navigation, drives. A choice with one option only is made without the agent.

Observation (:mod:`semexplore_gym.core.features.option_observation`): ``options``
``(max_options, K)`` scaled option features, ``valid`` the real rows, ``global`` a few global
features; with ``privileged=True`` (training only) also ``privileged``, read from the true world
through the env's one privileged door (``info["privileged_world"]`` of ``reset``, which the
driver never sees). Action: ``Discrete(max_options)``, a row; :meth:`OptionChoice.action_masks`
marks the valid rows (sb3-contrib ``MaskablePPO``); an invalid row means row 0.

Reward of a decision: ``area_reward_per_m2 * new mapped area - time_penalty_per_s * simulated
seconds``, plus ``goal_bonus`` when the base env terminates at its coverage goal. The episode
ends when the base env ends or the driver stops by itself.

Wrappers may not import ``policies``: the driver is injected (:class:`OptionDriver`); the
student's chooser hook is called deep inside its ``act``, so the mission runs in a helper thread
that hands each choice to :meth:`OptionChoice.step` and waits for the answer (one thread runs
at a time).
"""

from __future__ import annotations

import math
import queue
import threading
from dataclasses import dataclass
from typing import Any, Protocol

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY
from semexplore_gym.core.features.frontier_option_features import OPTION_FEATURE_NAMES
from semexplore_gym.core.features.option_observation import (
    CLIP,
    GLOBAL_FEATURE_NAMES,
    PRIVILEGED_FEATURE_NAMES,
    option_observation,
    privileged_option_features,
)

__all__ = ["OptionChoice", "OptionDriver", "OptionParams"]


@dataclass(frozen=True)
class OptionParams:
    """Parameters of :class:`OptionChoice`.

    Attributes:
        max_options: Rows of the observation (the options with the shortest paths).
        time_scale_s: The ``time`` global feature is mission time over this.
        area_reward_per_m2: Reward per m^2 of newly mapped free area.
        time_penalty_per_s: Reward lost per simulated second.
        goal_bonus: Reward when the base env reaches its coverage goal.
    """

    max_options: int = 32
    time_scale_s: float = 1500.0
    area_reward_per_m2: float = 0.05
    time_penalty_per_s: float = 0.02
    goal_bonus: float = 5.0

    def __post_init__(self) -> None:
        if isinstance(self.max_options, bool) or not isinstance(self.max_options, int):
            raise ValueError(f"max_options must be an integer >= 2, got {self.max_options!r}")
        if self.max_options < 2:
            raise ValueError(f"max_options must be an integer >= 2, got {self.max_options!r}")
        for name in ("time_scale_s", "area_reward_per_m2", "time_penalty_per_s", "goal_bonus"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {v!r}")
        if self.time_scale_s <= 0:
            raise ValueError(f"time_scale_s must be > 0, got {self.time_scale_s!r}")


class OptionDriver(Protocol):
    """What :class:`OptionChoice` needs from its driver (the frontier student has it):
    ``chooser`` is called with each decision (``options``, ``features``, ``grid``, ``time_s``,
    ``choice``) and returns the option to drive to (None: the driver's own)."""

    done: bool
    chooser: Any

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None: ...

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray: ...


class _Abort(BaseException):
    """Ends a mission thread that waits for a choice (reset or close mid-episode)."""


_ABORT = object()


class OptionChoice(gym.Wrapper):
    """The agent chooses each new goal among every reachable frontier (see the module).

    Args:
        env: A ``SemanticExplore-v0`` env (``privileged=True`` when ``privileged``).
        driver: An :class:`OptionDriver` (the frontier student).
        params: :class:`OptionParams`.
        privileged: Add the ``privileged`` observation key (training only).

    Attributes:
        decision: The last decision handed to the agent (None at the episode's end).
        teacher_row: The row the driver itself would choose at the last decision (for
            behaviour cloning), -1 when it chose an option outside the rows.
    """

    def __init__(
        self,
        env: gym.Env,
        driver: OptionDriver,
        params: OptionParams | None = None,
        privileged: bool = False,
    ) -> None:
        super().__init__(env)
        self.driver = driver
        self.params = params or OptionParams()
        self.privileged = bool(privileged)
        n, k = self.params.max_options, len(OPTION_FEATURE_NAMES)
        space: dict[str, spaces.Space[Any]] = {
            "options": spaces.Box(-CLIP, CLIP, (n, k), np.float32),
            "valid": spaces.Box(0.0, 1.0, (n,), np.float32),
            "global": spaces.Box(0.0, 1.0, (len(GLOBAL_FEATURE_NAMES),), np.float32),
        }
        if self.privileged:
            shape = (n + 1, len(PRIVILEGED_FEATURE_NAMES))
            space["privileged"] = spaces.Box(0.0, np.inf, shape, np.float32)
        self.observation_space = spaces.Dict(space)
        self.action_space = spaces.Discrete(n)
        self.decision: Any = None
        self.teacher_row = -1
        self._slots = np.zeros(0, dtype=np.int64)
        self._valid = np.zeros(n, dtype=np.float32)
        self._truth: Any = None
        self._to_agent: queue.Queue[tuple[str, Any]] = queue.Queue()
        self._to_driver: queue.Queue[Any] = queue.Queue()
        self._thread: threading.Thread | None = None
        self._info: dict[str, Any] = {}
        self._end: tuple[bool, bool] | None = None
        self.driver_stopped = False

    # ------------------------------------------------------------------ mission thread
    def _choose(self, decision: Any) -> int | None:
        if len(decision.options) < 2:
            return None
        self._to_agent.put(("decide", decision))
        answer = self._to_driver.get()
        if answer is _ABORT:
            raise _Abort
        return int(answer)

    def _mission(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> None:
        try:
            while True:
                action = self.driver.act(obs, info)
                if self.driver.done:
                    self._to_agent.put(("end", (False, False, True)))
                    return
                obs, _, terminated, truncated, info = self.env.step(action)
                self._info = info
                if terminated or truncated:
                    self._to_agent.put(("end", (bool(terminated), bool(truncated), False)))
                    return
        except _Abort:
            return
        except BaseException as e:  # noqa: BLE001 - handed to the agent's thread
            self._to_agent.put(("error", e))

    def _stop_thread(self) -> None:
        if self._thread is not None and self._thread.is_alive():
            self._to_driver.put(_ABORT)
            self._thread.join()
        self._thread = None
        self._to_agent = queue.Queue()
        self._to_driver = queue.Queue()

    # ------------------------------------------------------------------ gym API
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        self._stop_thread()
        obs, info = self.env.reset(seed=seed, options=options)
        self._truth = info.get(PRIVILEGED_INFO_KEY) if self.privileged else None
        info = {k: v for k, v in info.items() if k != PRIVILEGED_INFO_KEY}  # never the driver's
        self._info, self._end = info, None
        self.driver.chooser = self._choose
        self.driver.reset(obs, info, seed=seed)
        self._thread = threading.Thread(
            target=self._mission, args=(obs, info), daemon=True, name="option-mission"
        )
        self._thread.start()
        observation, _ = self._next()
        return observation, dict(info, decision_time_s=0.0)

    def _next(self) -> tuple[dict[str, np.ndarray], bool]:
        """Wait for the next decision (True) or the mission's end (False)."""
        kind, payload = self._to_agent.get()
        if kind == "error":
            self._thread = None
            raise payload
        if kind == "end":
            self._end = payload[:2]
            self.driver_stopped = payload[2]
            self.decision, self.teacher_row = None, -1
            self._slots = np.zeros(0, dtype=np.int64)
            return self._observation(None), False
        self.decision = payload
        return self._observation(payload), True

    def _observation(self, decision: Any) -> dict[str, np.ndarray]:
        p = self.params
        n, k = p.max_options, len(OPTION_FEATURE_NAMES)
        if decision is None:
            feats, grid = np.zeros((0, k)), np.zeros((1, 1), dtype=np.int8)
            time_s = float(self._info.get("sim_time_s", 0.0))
        else:  # the driver's own clock, as a policy that drives without this wrapper reads it
            feats, grid, time_s = decision.features, decision.grid, float(decision.time_s)
        ob = option_observation(feats, grid, time_s, n, p.time_scale_s)
        self._slots, self._valid = ob.slots, ob.valid
        hits = (
            np.flatnonzero(ob.slots == decision.choice)
            if decision is not None
            else np.zeros(0, dtype=np.int64)
        )
        self.teacher_row = int(hits[0]) if len(hits) else -1
        out = {"options": ob.options, "valid": ob.valid, "global": ob.global_features}
        if self.privileged:
            out["privileged"] = self._privileged(decision)
        return out

    def _privileged(self, decision: Any) -> np.ndarray:
        n = self.params.max_options
        truth = self._truth
        if truth is None or decision is None:
            return np.zeros((n + 1, len(PRIVILEGED_FEATURE_NAMES)), dtype=np.float32)
        goals = decision.options.goal_xy_m[self._slots]
        return privileged_option_features(
            decision.grid, truth.geometry, truth.reachable_mask, goals, n
        )

    def action_masks(self) -> np.ndarray:
        """``(max_options,)`` bool: the valid rows (at least row 0)."""
        mask = self._valid > 0
        if not mask.any():
            mask = mask.copy()
            mask[0] = True
        return mask

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        n = self.params.max_options
        row = int(np.asarray(action).reshape(-1)[0])
        if not 0 <= row < n:
            raise ValueError(f"action must be in [0, {n}), got {action!r}")
        info0 = self._info
        if self._end is None:
            row = row if row < len(self._slots) else 0
            self._to_driver.put(int(self._slots[row]))
            observation, _ = self._next()
        else:  # the mission ended before any choice
            observation = self._observation(None)
        terminated, truncated = self._end if self._end is not None else (False, False)
        info = self._info
        p = self.params
        area = float(info.get("explored_area_m2", 0.0)) - float(info0.get("explored_area_m2", 0.0))
        dt = float(info.get("sim_time_s", 0.0)) - float(info0.get("sim_time_s", 0.0))
        reward = p.area_reward_per_m2 * area - p.time_penalty_per_s * dt
        if terminated and not self.driver_stopped:
            reward += p.goal_bonus
        terminated = terminated or (self._end is not None and not truncated)
        out = dict(info, decision_time_s=dt, area_gain_m2=area, chosen_row=row)
        return observation, float(reward), bool(terminated), bool(truncated), out

    def close(self) -> None:
        self._stop_thread()
        super().close()
