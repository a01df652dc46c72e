"""The expert-driven env ids: base env + the scripted expert as driver + a macro-action wrapper.

``SemanticExploreFrontier-v0`` (choose one of the top-K frontiers) and
``SemanticExploreWeights-v0`` (choose the planner weights) need the scripted expert as their
driver. Wrappers may not import ``policies`` and policies may not import envs or wrappers
(STYLE.md layering), so this module, which sits outside the layers like ``cli`` and
``evaluation``, is the one place that joins them. It is imported only by ``gym.make`` through
the string entry points registered in :func:`semexplore_gym.register_envs`.

Example::

    import gymnasium as gym, semexplore_gym
    env = gym.make("SemanticExploreFrontier-v0", world="maze:size_m=5", macro={"n_candidates": 6})
    obs, info = env.reset(seed=0)
    mask = env.get_wrapper_attr("action_masks")()
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

from semexplore_gym.config import build_params
from semexplore_gym.envs.semantic_explore import SemanticExploreEnv
from semexplore_gym.policies.expert.driver import ExpertDriver
from semexplore_gym.policies.expert.expert import SemanticExpertParams
from semexplore_gym.wrappers.frontier_choice import FrontierChoice, MacroParams, PlannerWeights
from semexplore_gym.wrappers.option_choice import OptionChoice, OptionParams


def _parts(
    world: Any,
    config: Any,
    overrides: list[str] | None,
    render_mode: str | None,
    macro: MacroParams | Mapping[str, Any] | None,
    expert: Mapping[str, Any] | None,
) -> tuple[SemanticExploreEnv, ExpertDriver, MacroParams]:
    env = SemanticExploreEnv(
        world=world, config=config, overrides=overrides, render_mode=render_mode
    )
    driver = ExpertDriver(build_params(SemanticExpertParams, expert))
    return env, driver, build_params(MacroParams, macro)


def make_frontier_choice_env(
    world: str | os.PathLike | Any = "maze1",
    config: Any = None,
    overrides: list[str] | None = None,
    render_mode: str | None = None,
    macro: MacroParams | Mapping[str, Any] | None = None,
    expert: Mapping[str, Any] | None = None,
) -> FrontierChoice:
    """``SemanticExploreFrontier-v0``: :class:`FrontierChoice` over ``SemanticExplore-v0``.

    Args:
        world, config, overrides, render_mode: As for ``SemanticExplore-v0``.
        macro: :class:`MacroParams` or a mapping of its fields.
        expert: Overrides of the driver's ``SemanticExpertParams`` (dotted or nested keys).
    """
    env, driver, params = _parts(world, config, overrides, render_mode, macro, expert)
    return FrontierChoice(env, driver, params)


def make_planner_weights_env(
    world: str | os.PathLike | Any = "maze1",
    config: Any = None,
    overrides: list[str] | None = None,
    render_mode: str | None = None,
    macro: MacroParams | Mapping[str, Any] | None = None,
    expert: Mapping[str, Any] | None = None,
) -> PlannerWeights:
    """``SemanticExploreWeights-v0``: :class:`PlannerWeights` over ``SemanticExplore-v0``.

    Arguments as for :func:`make_frontier_choice_env`.
    """
    env, driver, params = _parts(world, config, overrides, render_mode, macro, expert)
    return PlannerWeights(env, driver, params)


def make_option_choice_env(
    world: str | os.PathLike | Any = "maze1",
    config: Any = None,
    overrides: list[str] | None = None,
    option: OptionParams | Mapping[str, Any] | None = None,
    student: str = "pretrained:oracle_student",
    privileged: bool = False,
) -> OptionChoice:
    """``SemanticExploreOptions-v0``: :class:`OptionChoice` over ``SemanticExplore-v0``, the
    frontier student ``student`` (a policy spec) driving; its own choices are the
    ``teacher_row`` of each decision.

    Args:
        world, config, overrides: As for ``SemanticExplore-v0``.
        option: :class:`OptionParams` or a mapping of its fields.
        student: A frontier-student spec (``frontier-student``, ``pretrained:oracle_student``).
        privileged: Training only: the env hands the true world to the wrapper (not the
            driver), which adds the ``privileged`` observation key.

    Raises:
        ValueError: ``student`` is not a frontier student.
    """
    from semexplore_gym.policies.frontier_student import FrontierStudentPolicy
    from semexplore_gym.policies.registry import make_policy

    driver = make_policy(student)
    if not isinstance(driver, FrontierStudentPolicy):
        raise ValueError(f"student must be a frontier-student spec, got {student!r}")
    env = SemanticExploreEnv(
        world=world,
        config=config,
        overrides=overrides,
        map_observation="shared",
        privileged=privileged,
    )
    return OptionChoice(env, driver, build_params(OptionParams, option), privileged=privileged)
