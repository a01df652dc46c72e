"""The envs and the expert of a training run, built from its :class:`TrainConfig`.

The factories are module-level functions of the config alone, so ``functools.partial`` of them
pickles and the roll-out workers build their own envs and experts.
"""

from __future__ import annotations

from typing import Any

from semexplore_gym.evaluation.rollout import make_mission_env
from semexplore_gym.training.train_config import TrainConfig, is_macro


def make_raw_env(cfg: TrainConfig, teacher: bool = True) -> Any:
    """The base ``SemanticExplore-v0`` env of the run (raw observations).

    With ``teacher`` (the env the labelling expert resets with) it is privileged, handing the
    true world to the teacher at reset, exactly when the run asks for a privileged teacher
    (``expert.privileged_teacher``); the learner's own env (``teacher=False``) never is.
    """
    privileged = teacher and bool(getattr(cfg.expert, "privileged_teacher", False))
    return make_mission_env(
        cfg.env.world, cfg.env.config, overrides=list(cfg.env.overrides), privileged=privileged
    )


def make_macro_env(cfg: TrainConfig) -> Any:
    """The macro-action env ``cfg.env.env_id`` with its ``macro`` and ``expert`` settings."""
    import gymnasium as gym

    import semexplore_gym  # noqa: F401  (registers the env ids)

    return gym.make(
        cfg.env.env_id,
        world=cfg.env.world,
        config=cfg.env.config,
        overrides=list(cfg.env.overrides),
        macro=dict(cfg.env.macro),
        expert=dict(cfg.env.expert),
    )


def make_learner_env(cfg: TrainConfig, max_episode_steps: int | None = None) -> Any:
    """The env the learner trains in: egocentric observations, or the macro env's own."""
    from gymnasium.wrappers import TimeLimit

    from semexplore_gym.wrappers.egocentric import EgocentricObservation

    if is_macro(cfg):
        env = make_macro_env(cfg)
    else:
        env = EgocentricObservation(make_raw_env(cfg, teacher=False), params=cfg.egocentric)
    if max_episode_steps:
        env = TimeLimit(env, max_episode_steps=max_episode_steps)
    return env


def make_expert(cfg: TrainConfig) -> Any:
    """The labelling expert ``cfg.expert.spec`` (a ``semexplore_gym.policies.registry`` spec).

    A privileged spec (the oracle) is refused unless the run asks for it by name with
    ``expert.privileged_teacher=true``; that flag with an honest spec is an error too, so a
    privileged env is never made for nothing.
    """
    from semexplore_gym.policies.oracle import refuse_privileged
    from semexplore_gym.policies.registry import make_policy

    expert = make_policy(cfg.expert.spec)
    if not getattr(cfg.expert, "privileged_teacher", False):
        refuse_privileged(
            expert,
            "training expert",
            hint="to let it label the data as a teacher, set expert.privileged_teacher=true",
        )
    elif not getattr(expert, "privileged", False):
        raise ValueError(
            f"expert.privileged_teacher=true needs a privileged expert spec (oracle), "
            f"got expert.spec={cfg.expert.spec!r}"
        )
    return expert
