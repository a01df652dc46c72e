"""The configuration of a training run (``semexplore train``): frozen sections, strict keys.

One YAML file (``configs/agents/*.yml``) plus ``key.path=value`` overrides, read by
:func:`load_train_config` with :func:`semexplore_gym.config.from_dict`; the ``egocentric``
section is :class:`EgocentricParams` itself, so the features the learner sees are defined once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from semexplore_gym.config import build_params
from semexplore_gym.core.features.egocentric import EgocentricParams
from semexplore_gym.evaluation.errors import PARAM, ParameterError

#: The base env id; any other ``env.env_id`` is a macro-action env with its own observation.
BASE_ENV_ID = "SemanticExplore-v0"


@dataclass(frozen=True)
class EnvSection:
    """The env to train in: id, world spec, env config (preset, path or None) and overrides.

    ``macro`` (``MacroParams`` fields) and ``expert`` (driver parameter overrides) are passed to
    the macro-action env ids only.
    """

    env_id: str = BASE_ENV_ID
    world: str = "maze:size_m=5"
    config: str | None = None
    overrides: tuple[str, ...] = ()
    macro: dict[str, Any] = field(default_factory=dict)
    expert: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class ExpertSection:
    """The labelling expert (a ``semexplore_gym.policies.registry`` spec) and how much to record.

    ``noise_std`` > 0 records the first ``noise_fraction`` of the episodes with DART noise on
    the executed actions (labels stay clean); ``save_interval_s`` throttles dataset rewrites;
    ``workers`` > 1 records episodes in that many processes (same data as one).

    ``privileged_teacher`` (False by default) is the one way to let a privileged policy (the
    ``oracle``, which reads the true world) label the data: the run's env then hands the true
    world to the teacher at reset (``info["privileged_world"]``), while the student still sees
    only its egocentric features of the observation. Without it such a spec is refused.
    """

    spec: str = "semantic"
    episodes: int = 8
    max_steps: int = 600
    holdout_fraction: float = 0.125
    noise_std: float = 0.0
    noise_fraction: float = 1.0
    save_interval_s: float = 0.0
    workers: int = 1
    privileged_teacher: bool = False


@dataclass(frozen=True)
class PolicySection:
    """SB3 policy network: ``net_arch`` of the MLP heads, CNN feature size, initial log std."""

    net_arch: tuple[int, ...] = (64, 64)
    cnn_output_dim: int = 128
    log_std_init: float = -0.5


@dataclass(frozen=True)
class BCSection:
    """:func:`~semexplore_gym.training.bc.train_bc` settings.

    ``epochs`` passes over the data in minibatches of ``batch_size``; Adam with rate ``lr`` and
    weight decay ``l2_weight``; ``ent_weight`` weighs the entropy bonus (keeps the action std
    from collapsing too early). ``mirror`` replaces each minibatch sample by its left-right
    mirror image with probability 1/2 (the data doubled for free; needs
    ``egocentric.scan_bins_centred`` and odd beams per bin). ``select_best`` restores the
    weights of the epoch with the lowest held-out action error at the end. The rate decays
    along a cosine from ``lr`` to ``lr * lr_final_fraction`` (1: constant).
    """

    epochs: int = 15
    batch_size: int = 64
    lr: float = 3e-4
    ent_weight: float = 1e-3
    l2_weight: float = 0.0
    mirror: bool = False
    select_best: bool = False
    lr_final_fraction: float = 1.0


@dataclass(frozen=True)
class DaggerSection:
    """DAgger rounds; ``beta`` is the per-round probability of executing the expert's action.

    Each round refits on the aggregate with the ``bc`` settings for ``epochs_per_round`` epochs,
    except that ``select_best`` replaces ``bc.select_best``: the held-out error is measured on
    expert states only, which the aggregate holds fewer of with every round. ``workers`` > 1
    runs the episodes of a round in that many processes (same data as one).
    """

    rounds: int = 3
    episodes_per_round: int = 2
    beta: tuple[float, ...] = (0.5, 0.25, 0.0)
    epochs_per_round: int = 5
    select_best: bool = False
    workers: int = 1


#: ``ppo.vec_env`` choices: how the ``n_envs`` learner envs are stepped.
VEC_ENV_KINDS: tuple[str, ...] = ("auto", "subproc", "dummy")


@dataclass(frozen=True)
class PPOSection:
    """SB3 PPO settings; ``init_from`` starts from a BC/DAgger model zip (egocentric env only).

    PPO collects from ``n_envs`` envs at once (``n_steps`` each per update). ``vec_env`` picks
    how: ``"subproc"`` (SB3's ``SubprocVecEnv``: one process per env, which pays off with a
    free core per env), ``"dummy"`` (``DummyVecEnv``: all envs in this process, no start-up
    cost or messaging; the policy's forward pass is batched over them) or ``"auto"`` (subproc
    when the machine has more cores than ``n_envs``, else dummy). On a 2-core machine 4 envs
    in this process collect the most (``scripts/bench_ppo_collection.py``).
    """

    total_timesteps: int = 20_000
    n_envs: int = 4
    vec_env: str = "auto"
    n_steps: int = 512
    batch_size: int = 64
    n_epochs: int = 5
    learning_rate: float = 3e-4
    gamma: float = 0.99
    ent_coef: float = 0.0
    max_episode_steps: int = 600
    init_from: str | None = None


@dataclass(frozen=True)
class TrainConfig:
    """Everything ``semexplore train`` needs; loaded from YAML with strict keys.

    ``torch_threads`` sets ``torch.set_num_threads`` for the run (BC and the DAgger refits;
    roll-outs drive the learner with one thread).
    """

    seed: int = 0
    torch_threads: int = 1
    env: EnvSection = field(default_factory=EnvSection)
    egocentric: EgocentricParams = field(default_factory=EgocentricParams)
    expert: ExpertSection = field(default_factory=ExpertSection)
    policy: PolicySection = field(default_factory=PolicySection)
    bc: BCSection = field(default_factory=BCSection)
    dagger: DaggerSection = field(default_factory=DaggerSection)
    ppo: PPOSection = field(default_factory=PPOSection)


def load_train_config(path: str | None, overrides: list[str]) -> TrainConfig:
    """Config from YAML ``path`` (or defaults) with ``key.path=value`` overrides applied."""
    return build_params(TrainConfig, path, overrides=overrides)


def is_macro(cfg: TrainConfig) -> bool:
    """True when the run trains on a macro-action env id (its own observation, no egocentric)."""
    return cfg.env.env_id != BASE_ENV_ID


def check_train_config(cfg: TrainConfig, algo: str) -> None:
    """Raise a ValueError when ``cfg`` cannot run ``algo`` (checked before any work starts);
    a :class:`ParameterError` naming ``algo`` when the two do not fit together."""
    for key, value in (
        ("torch_threads", cfg.torch_threads),
        ("expert.workers", cfg.expert.workers),
        ("dagger.workers", cfg.dagger.workers),
    ):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ValueError(f"{key} must be an integer >= 1, got {value!r}")
    if (
        isinstance(cfg.ppo.n_envs, bool)
        or not isinstance(cfg.ppo.n_envs, int)
        or cfg.ppo.n_envs < 1
    ):
        raise ValueError(f"ppo.n_envs must be an integer >= 1, got {cfg.ppo.n_envs!r}")
    if cfg.ppo.vec_env not in VEC_ENV_KINDS:
        raise ValueError(f"ppo.vec_env must be one of {VEC_ENV_KINDS}, got {cfg.ppo.vec_env!r}")
    if algo == "maskable_ppo" and not is_macro(cfg):
        raise maskable_needs_macro(cfg)
    if algo in ("bc", "dagger") and is_macro(cfg):
        raise ParameterError(
            "algo",
            f"{PARAM} {algo} trains on the egocentric env only, not env.env_id={cfg.env.env_id!r}",
        )


def maskable_needs_macro(cfg: TrainConfig) -> ParameterError:
    """The error of ``algo="maskable_ppo"`` on an env without action masks."""
    return ParameterError(
        "algo",
        f"{PARAM} maskable_ppo needs a macro-action env with action masks (env.env_id), "
        f"got {cfg.env.env_id!r}",
    )
