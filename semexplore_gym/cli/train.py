"""``semexplore train --algo bc|dagger|ppo --config FILE --out DIR``: train a learning agent.

``bc`` records expert episodes and behaviour-clones an SB3 policy; ``dagger`` does the same and
then runs DAgger rounds; ``ppo`` trains SB3 PPO on the egocentric env, optionally starting from
a BC/DAgger model (``ppo.init_from``). With ``env.env_id`` set to a macro-action env
(``SemanticExploreFrontier-v0``, ``SemanticExploreWeights-v0``) ``ppo`` and ``maskable_ppo``
(sb3-contrib ``MaskablePPO``, using the env's ``action_masks``) train an MLP on that env's own
observation instead (``env.macro`` holds its ``MacroParams`` fields, ``env.expert`` overrides of
the driving expert's parameters). Every run directory gets ``model.zip``, the resolved
``config.yaml``, ``args.json`` (arguments and command line), TensorBoard logs (CSV when
tensorboard is missing) and, for bc/dagger, the dataset ``dataset.npz`` and ``metrics.json``.
"""

from __future__ import annotations

import argparse
import csv
import functools
import json
import shlex
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from semexplore_gym.core.params import ConfigError, from_dict, load_yaml, merge_overrides, to_dict

ALGOS = ("bc", "dagger", "ppo", "maskable_ppo")
#: The base env id; any other ``env.env_id`` is a macro-action env with its own observation.
BASE_ENV_ID = "SemanticExplore-v0"


# ------------------------------------------------------------------------ config
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
class EgocentricSection:
    """``EgocentricParams`` fields (defaults: the original one-channel encoding)."""

    crop_cells: int = 64
    crop_resolution_m: float | None = 0.1
    n_scan_bins: int = 60
    channels: tuple[str, ...] = ("occupancy",)
    frontier_clearance_m: float = 0.1
    distance_scale_per_m: float = 20.0
    trail_radius_m: float = 0.1
    scan_bins_centred: bool = False


@dataclass(frozen=True)
class ExpertSection:
    """The labelling expert (a ``policies.registry`` spec) and how much to record.

    ``noise_std`` > 0 records the first ``noise_fraction`` of the episodes with DART noise on
    the executed actions (labels stay clean); ``save_interval_s`` throttles dataset rewrites;
    ``workers`` > 1 records episodes in that many processes (same data as one).
    """

    spec: str = "semantic"
    episodes: int = 8
    max_steps: int = 600
    holdout_fraction: float = 0.125
    noise_std: float = 0.0
    noise_fraction: float = 1.0
    save_interval_s: float = 0.0
    workers: int = 1


@dataclass(frozen=True)
class PolicySection:
    """SB3 policy network: ``net_arch`` of the MLP heads, CNN feature size, initial log std."""

    net_arch: tuple[int, ...] = (64, 64)
    cnn_output_dim: int = 128
    log_std_init: float = -0.5


@dataclass(frozen=True)
class BCSection:
    """``train_bc`` settings; ``mirror`` needs ``egocentric.scan_bins_centred`` and odd beams per bin."""

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


@dataclass(frozen=True)
class PPOSection:
    total_timesteps: int = 20_000
    n_envs: int = 1
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
    egocentric: EgocentricSection = field(default_factory=EgocentricSection)
    expert: ExpertSection = field(default_factory=ExpertSection)
    policy: PolicySection = field(default_factory=PolicySection)
    bc: BCSection = field(default_factory=BCSection)
    dagger: DaggerSection = field(default_factory=DaggerSection)
    ppo: PPOSection = field(default_factory=PPOSection)


def load_train_config(path: str | None, overrides: list[str]) -> TrainConfig:
    """Config from YAML ``path`` (or defaults) with ``key.path=value`` overrides applied."""
    data = load_yaml(path) if path else {}
    data = merge_overrides(data, overrides)
    return from_dict(TrainConfig, data)


# ----------------------------------------------------------------------- logging
class ScalarLogger:
    """Scalars to TensorBoard when installed, else to ``scalars.csv``; always to ``metrics``."""

    def __init__(self, log_dir: Path) -> None:
        log_dir.mkdir(parents=True, exist_ok=True)
        self._writer: Any = None
        self._csv: Any = None
        try:
            from torch.utils.tensorboard import SummaryWriter

            self._writer = SummaryWriter(str(log_dir))
        except ImportError:
            f = open(log_dir / "scalars.csv", "w", newline="")  # noqa: SIM115 (closed in close())
            self._csv = (f, csv.writer(f))
            self._csv[1].writerow(["tag", "step", "value"])

    def __call__(self, tag: str, value: float, step: int) -> None:
        if self._writer is not None:
            self._writer.add_scalar(tag, value, step)
        else:
            self._csv[1].writerow([tag, step, value])

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
        if self._csv is not None:
            self._csv[0].close()


# ----------------------------------------------------------------------- helpers
def _make_raw_env(cfg: TrainConfig) -> Any:
    import gymnasium as gym

    import semexplore_gym  # noqa: F401  (registers the env)

    return gym.make(
        "SemanticExplore-v0",
        world=cfg.env.world,
        config=cfg.env.config,
        overrides=list(cfg.env.overrides),
    )


def _egocentric_params(cfg: TrainConfig) -> Any:
    from semexplore_gym.wrappers.egocentric import EgocentricParams

    return EgocentricParams(**to_dict(cfg.egocentric))


def _is_macro(cfg: TrainConfig) -> bool:
    return cfg.env.env_id != BASE_ENV_ID


def _make_macro_env(cfg: TrainConfig) -> Any:
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


def _make_wrapped_env(cfg: TrainConfig, max_episode_steps: int | None = None) -> Any:
    from gymnasium.wrappers import TimeLimit

    from semexplore_gym.wrappers.egocentric import EgocentricObservation

    if _is_macro(cfg):
        env = _make_macro_env(cfg)
    else:
        env = EgocentricObservation(_make_raw_env(cfg), params=_egocentric_params(cfg))
    if max_episode_steps:
        env = TimeLimit(env, max_episode_steps=max_episode_steps)
    return env


def _policy_kwargs(cfg: TrainConfig) -> dict[str, Any]:
    p = cfg.policy
    return {
        "net_arch": {"pi": list(p.net_arch), "vf": list(p.net_arch)},
        "log_std_init": p.log_std_init,
        "features_extractor_kwargs": {"cnn_output_dim": p.cnn_output_dim},
    }


def _new_ppo(cfg: TrainConfig, vec_env: Any, tensorboard_log: str | None, algo: str = "ppo") -> Any:
    pc = cfg.ppo
    if algo == "maskable_ppo":
        if not _is_macro(cfg):
            raise ValueError(
                f"--algo maskable_ppo needs a macro-action env with action masks (env.env_id), got {cfg.env.env_id!r}"
            )
        from sb3_contrib import MaskablePPO as algo_cls
    else:
        from stable_baselines3 import PPO as algo_cls
    if _is_macro(cfg):
        policy_name = "MlpPolicy"
        kwargs: dict[str, Any] = {
            "net_arch": {"pi": list(cfg.policy.net_arch), "vf": list(cfg.policy.net_arch)}
        }
        if algo != "maskable_ppo":
            kwargs["log_std_init"] = cfg.policy.log_std_init
    else:
        policy_name, kwargs = "MultiInputPolicy", _policy_kwargs(cfg)
    return algo_cls(
        policy_name,
        vec_env,
        learning_rate=pc.learning_rate,
        n_steps=pc.n_steps,
        batch_size=pc.batch_size,
        n_epochs=pc.n_epochs,
        gamma=pc.gamma,
        ent_coef=pc.ent_coef,
        policy_kwargs=kwargs,
        tensorboard_log=tensorboard_log,
        seed=cfg.seed,
        device="cpu",
        verbose=0,
    )


def _vec_env(cfg: TrainConfig) -> Any:
    from stable_baselines3.common.env_util import make_vec_env

    return make_vec_env(
        lambda: _make_wrapped_env(cfg, cfg.ppo.max_episode_steps),
        n_envs=cfg.ppo.n_envs,
        seed=cfg.seed,
    )


def _make_expert(cfg: TrainConfig) -> Any:
    from policies.registry import make_policy

    return make_policy(cfg.expert.spec)


def _save_model(model: Any, path: Path, params: Any, algo: str) -> None:
    from policies.imitation import tag_model_zip

    model.save(str(path))
    tag_model_zip(path, params, algo="ppo")


# -------------------------------------------------------------------- algorithms
def _train_imitation(
    cfg: TrainConfig, args: argparse.Namespace, out: Path, log: ScalarLogger
) -> dict[str, Any]:
    from policies.imitation import action_error, record_expert_dataset, run_dagger, train_bc

    params = _egocentric_params(cfg)
    raw_env = _make_raw_env(cfg)
    if cfg.bc.mirror:
        n_beams = raw_env.unwrapped.config.lidar.n_beams
        per_bin = n_beams // params.n_scan_bins
        if not params.scan_bins_centred or per_bin % 2 == 0:
            raise ValueError(
                "bc.mirror needs egocentric.scan_bins_centred=true and an odd number of beams per "
                f"scan bin; got scan_bins_centred={params.scan_bins_centred}, "
                f"{n_beams} beams / {params.n_scan_bins} bins = {per_bin}"
            )
    expert = _make_expert(cfg)
    progress = not args.no_progress
    t0 = time.perf_counter()
    data = record_expert_dataset(
        raw_env,
        expert,
        out / "dataset.npz",
        cfg.expert.episodes,
        params,
        seed=cfg.seed,
        max_steps=cfg.expert.max_steps,
        meta={"world": cfg.env.world, "expert_spec": cfg.expert.spec},
        progress=progress,
        log_fn=log,
        noise_std=cfg.expert.noise_std,
        noise_fraction=cfg.expert.noise_fraction,
        save_interval_s=cfg.expert.save_interval_s,
        workers=cfg.expert.workers,
        make_env=functools.partial(_make_raw_env, cfg),
        make_expert=functools.partial(_make_expert, cfg),
    )
    record_s = time.perf_counter() - t0
    train, held = data.split_by_episode(
        cfg.expert.holdout_fraction, np.random.default_rng(cfg.seed)
    )
    # PPO's policy object is the learner, so a BC model can be fine-tuned by `train --algo ppo`.
    model = _new_ppo(cfg, _vec_env(cfg), None)
    policy = model.policy
    metrics: dict[str, Any] = {
        "dataset_samples": len(data),
        "dataset_episodes": data.n_episodes,
        "record_s": record_s,
    }
    if len(held):
        metrics["heldout_action_error_before"] = action_error(policy, held)
        # Reference: always answering the training set's mean action.
        mean_action = train.actions.mean(axis=0)
        metrics["heldout_action_error_mean_action"] = float(
            np.abs(held.actions - mean_action).mean()
        )
    bc = cfg.bc
    bc_kwargs = {
        "batch_size": bc.batch_size,
        "lr": bc.lr,
        "ent_weight": bc.ent_weight,
        "l2_weight": bc.l2_weight,
        "progress": progress,
        "mirror_params": params if bc.mirror else None,
        "select_best": bc.select_best,
        "lr_final_fraction": bc.lr_final_fraction,
    }
    t0 = time.perf_counter()
    eval_data = held if len(held) else None
    hist = train_bc(
        train, policy, epochs=bc.epochs, seed=cfg.seed, log_fn=log, eval_data=eval_data, **bc_kwargs
    )
    metrics["bc_s"] = time.perf_counter() - t0
    metrics["bc_final_loss"] = hist["loss"][-1]
    if "best_epoch" in hist:
        metrics["bc_best_epoch"] = int(hist["best_epoch"][0])
    if len(held):
        metrics["heldout_action_error_after_bc"] = action_error(policy, held)
        log("bc/heldout_action_error", metrics["heldout_action_error_after_bc"], bc.epochs)
    if args.algo == "dagger":
        d = cfg.dagger
        t0 = time.perf_counter()
        result = run_dagger(
            raw_env,
            expert,
            policy,
            params,
            rounds=d.rounds,
            beta=list(d.beta),
            episodes_per_round=d.episodes_per_round,
            dataset=train,
            dataset_path=out / "dagger_dataset.npz",
            bc_kwargs={
                **bc_kwargs,
                "epochs": d.epochs_per_round,
                "progress": False,
                "eval_data": eval_data,
                "select_best": d.select_best,
            },
            seed=cfg.seed,
            max_steps=cfg.expert.max_steps,
            progress=progress,
            log_fn=log,
            save_interval_s=cfg.expert.save_interval_s,
            workers=d.workers,
            make_env=functools.partial(_make_raw_env, cfg),
            make_expert=functools.partial(_make_expert, cfg),
        )
        metrics["dagger_s"] = time.perf_counter() - t0
        metrics["dagger_rounds"] = result.rounds
        if len(held):
            metrics["heldout_action_error_after_dagger"] = action_error(policy, held)
    _save_model(model, out / "model.zip", params, "ppo")
    raw_env.close()
    return metrics


def _train_ppo(cfg: TrainConfig, args: argparse.Namespace, out: Path) -> dict[str, Any]:
    from policies.imitation import load_model

    params = _egocentric_params(cfg)
    vec_env = _vec_env(cfg)
    model = _new_ppo(cfg, vec_env, str(out / "tb"), algo=args.algo)
    if cfg.ppo.init_from and _is_macro(cfg):
        raise ValueError(
            f"ppo.init_from (a BC/DAgger model) only fits the egocentric env, not env.env_id={cfg.env.env_id!r}"
        )
    if cfg.ppo.init_from:
        init_policy, init_params = load_model(cfg.ppo.init_from)
        if init_params != params:
            raise ValueError(
                f"ppo.init_from model uses egocentric {init_params.to_dict()} but this config uses {params.to_dict()}"
            )
        missing = model.policy.load_state_dict(init_policy.state_dict(), strict=False)
        if missing.missing_keys or missing.unexpected_keys:
            raise ValueError(f"ppo.init_from model does not match the policy network: {missing}")
    t0 = time.perf_counter()
    model.learn(
        total_timesteps=cfg.ppo.total_timesteps,
        progress_bar=not args.no_progress,
        tb_log_name=args.algo,
    )
    metrics = {"ppo_s": time.perf_counter() - t0, "timesteps": int(model.num_timesteps)}
    if _is_macro(cfg):
        # Not an egocentric-observation model: no tag, it is loaded with the algorithm's own load().
        model.save(str(out / "model.zip"))
    else:
        _save_model(model, out / "model.zip", params, "ppo")
    vec_env.close()
    return metrics


# ---------------------------------------------------------------------- CLI glue
def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    from semexplore_gym.cli import describe

    p = sub.add_parser(
        "train",
        help="train a learning agent (behaviour cloning, DAgger or PPO)",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--algo",
        required=True,
        choices=ALGOS,
        help="bc, dagger, ppo or maskable_ppo (macro-action envs)",
    )
    p.add_argument("--config", default=None, help="agent config YAML (configs/agents/*.yml)")
    p.add_argument("--out", required=True, help="run directory (created)")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a config key, e.g. bc.epochs=5 (repeatable)",
    )
    p.add_argument("--no-progress", action="store_true", help="no tqdm progress bars")
    return p


def _command_line(args: argparse.Namespace) -> str:
    """The ``semexplore train`` command that reproduces this run (also when called via ``main``)."""
    parts = ["semexplore", "train", "--algo", args.algo, "--out", str(args.out)]
    if args.config:
        parts += ["--config", str(args.config)]
    for text in args.overrides:
        parts += ["--set", text]
    if args.no_progress:
        parts.append("--no-progress")
    return shlex.join(parts)


def run(args: argparse.Namespace) -> int:
    try:
        import stable_baselines3  # noqa: F401
        import torch  # noqa: F401
    except ImportError as e:
        print(
            f"semexplore train needs the rl extra: pip install 'semexplore-gym[rl]' ({e})",
            file=sys.stderr,
        )
        return 2
    try:
        cfg = load_train_config(args.config, args.overrides)
    except ConfigError as e:
        raise ValueError(str(e)) from e
    for key, value in (
        ("torch_threads", cfg.torch_threads),
        ("expert.workers", cfg.expert.workers),
        ("dagger.workers", cfg.dagger.workers),
    ):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ValueError(f"{key} must be an integer >= 1, got {value!r}")
    if args.algo == "maskable_ppo" and not _is_macro(cfg):
        raise ValueError(
            f"--algo maskable_ppo needs a macro-action env with action masks (env.env_id), got {cfg.env.env_id!r}"
        )
    if args.algo in ("bc", "dagger") and _is_macro(cfg):
        raise ValueError(
            f"--algo {args.algo} trains on the egocentric env only, not env.env_id={cfg.env.env_id!r}"
        )
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "config.yaml").write_text(yaml.safe_dump(to_dict(cfg), sort_keys=False))
    (out / "args.json").write_text(
        json.dumps(
            {
                "args": {k: v for k, v in vars(args).items() if not k.startswith("_")},
                "process_argv": sys.argv,
                "command_line": _command_line(args),
            },
            indent=2,
        )
    )
    import torch

    torch.set_num_threads(cfg.torch_threads)
    torch.manual_seed(cfg.seed)
    t0 = time.perf_counter()
    if args.algo in ("ppo", "maskable_ppo"):
        metrics = _train_ppo(cfg, args, out)  # SB3's own logger writes out/tb/ppo_N
    else:
        log = ScalarLogger(out / "tb" / args.algo)
        try:
            metrics = _train_imitation(cfg, args, out, log)
        finally:
            log.close()
    metrics["total_s"] = time.perf_counter() - t0
    metrics["model"] = str(out / "model.zip")
    (out / "metrics.json").write_text(json.dumps(metrics, indent=2, default=float))
    print(json.dumps({k: v for k, v in metrics.items() if k != "dagger_rounds"}, default=float))
    return 0
