"""Train the option explorer: behaviour cloning, then MaskablePPO with a privileged critic.

``semexplore train --algo option_ppo --train-config configs/agents/option_ppo.yml --out DIR``:

1. **Worlds**: each episode draws a world from the ``train`` parts of ``splits`` (never another
   part; worlds up to ``max_size_m``) and a random start, in ``SemanticExploreOptions-v0`` with
   the privileged key on (:mod:`semexplore_gym.wrappers.option_choice`).
2. **Behaviour cloning**: ``bc_episodes`` episodes driven by the frontier student ``student``;
   its choice at each decision is the actor's label (cross-entropy over the valid rows) and the
   discounted return the critic's (``DIR/bc_data.npz``, read back when it exists).
3. **PPO**: sb3-contrib MaskablePPO with :class:`~semexplore_gym.policies.option_ppo` networks,
   ``n_envs`` envs (``vec_env``: all in this process, or one process each);
   ``DIR/checkpoints/last.zip`` after every update. Rerun the same command and it resumes from
   there. ``DIR/curve.csv`` gets one row per finished episode
   (and ``curve.png`` at the end); the final model is ``DIR/model.zip``.
"""

from __future__ import annotations

import csv
import math
import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.config import build_params

__all__ = ["OptionPPOConfig", "fit_bc", "load_option_ppo_config", "train_option_ppo"]

VEC_ENVS = ("dummy", "subproc")


@dataclass(frozen=True)
class OptionPPOConfig:
    """Settings of :func:`train_option_ppo` (``configs/agents/option_ppo.yml``).

    Attributes:
        seed: Seed of the world draws, the starts and the networks.
        splits: Learning splits whose ``train`` part is drawn from.
        max_size_m: Only training worlds with ``size_m`` at most this (DungeonMaps: 28 m).
        max_time_s: Simulated time limit of an episode.
        student: The frontier student that drives (and labels the BC data).
        option: ``OptionParams`` fields (rows, reward terms).
        hidden: Width of the actor's and the critic's layers.
        bc_episodes, bc_epochs, bc_lr: Behaviour cloning.
        total_timesteps: PPO decisions (all envs together), BC's not counted.
        n_envs, n_steps, batch_size, n_epochs, learning_rate, gamma, ent_coef: MaskablePPO.
        torch_threads: ``torch.set_num_threads``.
        vec_env: ``"dummy"``: the ``n_envs`` envs step in this process, one after another;
            ``"subproc"``: each in its own process (SB3's ``SubprocVecEnv``), on as many cores.
            The envs draw the same worlds and starts either way, so the run is the same.
        wall_budget_s: PPO stops (and saves) once the run has taken this much wall time,
            BC included (0: no limit; a resumed run counts from its restart).
    """

    seed: int = 0
    splits: tuple[str, ...] = ("mazes", "offices", "dungeon", "caves")
    max_size_m: float = 14.0
    max_time_s: float = 900.0
    student: str = "pretrained:oracle_student"
    option: dict[str, Any] = field(default_factory=dict)
    hidden: int = 64
    bc_episodes: int = 8
    bc_epochs: int = 30
    bc_lr: float = 1e-3
    total_timesteps: int = 512
    n_envs: int = 2
    n_steps: int = 64
    batch_size: int = 32
    n_epochs: int = 4
    learning_rate: float = 1e-4
    gamma: float = 0.98
    ent_coef: float = 0.003
    torch_threads: int = 1
    vec_env: str = "dummy"
    wall_budget_s: float = 0.0

    def __post_init__(self) -> None:
        ints = ("hidden", "bc_epochs", "total_timesteps", "n_envs", "n_steps", "batch_size")
        for name in (*ints, "n_epochs", "torch_threads"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise ValueError(f"{name} must be an integer >= 1, got {v!r}")
        if isinstance(self.bc_episodes, bool) or not isinstance(self.bc_episodes, int):
            raise ValueError(f"bc_episodes must be an integer >= 0, got {self.bc_episodes!r}")
        if self.bc_episodes < 0:
            raise ValueError(f"bc_episodes must be an integer >= 0, got {self.bc_episodes!r}")
        for name in ("max_size_m", "max_time_s", "bc_lr", "learning_rate"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
        w = self.wall_budget_s
        if not (isinstance(w, (int, float)) and math.isfinite(w) and w >= 0):
            raise ValueError(f"wall_budget_s must be a finite number >= 0, got {w!r}")
        if not 0 < self.gamma <= 1:
            raise ValueError(f"gamma must be in (0, 1], got {self.gamma!r}")
        if not self.splits:
            raise ValueError("splits is empty: name at least one learning split")
        if self.vec_env not in VEC_ENVS:
            raise ValueError(f"vec_env must be one of {', '.join(VEC_ENVS)}, got {self.vec_env!r}")


def load_option_ppo_config(path: str | None, overrides: list[str]) -> OptionPPOConfig:
    """Config from YAML ``path`` (or defaults) with ``key=value`` overrides applied; the
    option section is checked here too."""
    from semexplore_gym.wrappers.option_choice import OptionParams

    cfg = build_params(OptionPPOConfig, path, overrides=overrides)
    build_params(OptionParams, cfg.option)
    return cfg


_SIZE = re.compile(r"size_m=([0-9.]+)")


def training_worlds(splits: tuple[str, ...], max_size_m: float) -> list[str]:
    """The ``train`` parts of ``splits`` up to ``max_size_m`` (DungeonMaps count as 28 m)."""
    from semexplore_gym.evaluation.splits import load_split

    out = []
    for name in splits:
        for world in load_split(name).parts["train"]:
            m = _SIZE.search(world)
            if (float(m.group(1)) if m else 28.0) <= max_size_m:
                out.append(world)
    if not out:
        raise ValueError(f"no training world of splits {list(splits)} is <= {max_size_m} m")
    return out


class EpisodeLog:
    """Appends one row per finished episode to ``curve.csv``."""

    FIELDS = ("timesteps", "episode", "phase", "world", "return", "coverage", "sim_time_s",
              "collisions", "wall_s")  # fmt: skip

    def __init__(self, path: Path) -> None:
        self.path = path
        self.t0 = time.perf_counter()
        self.episodes = 0
        if path.is_file():
            with path.open() as f:
                self.episodes = sum(1 for _ in f) - 1
        else:
            path.write_text(",".join(self.FIELDS) + "\n")

    def add(self, timesteps: int, phase: str, world: str, ret: float, info: dict) -> None:
        self.episodes += 1
        row = [timesteps, self.episodes, phase, world, round(ret, 3),
               round(float(info.get("coverage", float("nan"))), 4),
               round(float(info.get("sim_time_s", float("nan"))), 1),
               int(info.get("collisions", 0)), round(time.perf_counter() - self.t0, 1)]  # fmt: skip
        with self.path.open("a", newline="") as f:
            csv.writer(f).writerow(row)


def make_world_env(cfg: OptionPPOConfig, worlds: list[str], index: int) -> Any:
    """A gym env that starts each episode on a new draw of ``worlds`` (random start)."""
    import gymnasium as gym

    from semexplore_gym.expert_driven_envs import make_option_choice_env

    class WorldDraws(gym.Env):  # type: ignore[type-arg]
        def __init__(self) -> None:
            self.rng = np.random.default_rng([cfg.seed, index])
            self.world = worlds[0]
            self.env = self._make(self.world)
            self.observation_space = self.env.observation_space
            self.action_space = self.env.action_space
            self.episode_return = 0.0

        def _make(self, world: str) -> Any:
            overrides = ["episode.random_start=true", f"episode.max_time_s={cfg.max_time_s!r}"]
            return make_option_choice_env(
                world, overrides=overrides, option=cfg.option, student=cfg.student,
                privileged=True,
            )  # fmt: skip

        def reset(self, *, seed: int | None = None, options: Any = None) -> Any:
            self.env.close()
            self.world = worlds[int(self.rng.integers(len(worlds)))]
            self.env = self._make(self.world)
            self.episode_return = 0.0
            obs, info = self.env.reset(seed=int(self.rng.integers(2**31 - 1)))
            return obs, dict(info, world=self.world)

        def step(self, action: Any) -> Any:
            obs, r, te, tr, info = self.env.step(action)
            self.episode_return += r
            return obs, r, te, tr, dict(info, world=self.world, episode_total=self.episode_return)

        def action_masks(self) -> np.ndarray:
            return self.env.action_masks()

        def teacher_row(self) -> int:
            return int(self.env.teacher_row)

        def close(self) -> None:
            self.env.close()

    return WorldDraws()


def collect_bc(cfg: OptionPPOConfig, worlds: list[str], log: EpisodeLog) -> dict[str, np.ndarray]:
    """``bc_episodes`` episodes driven by the student: observations, its rows, returns."""
    env = make_world_env(cfg, worlds, 1000)
    obs_rows: dict[str, list[np.ndarray]] = {}
    labels: list[int] = []
    returns: list[float] = []
    try:
        for _ in range(cfg.bc_episodes):
            obs, _ = env.reset()
            rewards: list[float] = []
            done = False
            while not done:
                row = max(env.teacher_row(), 0)
                for k, v in obs.items():
                    obs_rows.setdefault(k, []).append(v)
                labels.append(row)
                obs, r, te, tr, info = env.step(row)
                rewards.append(r)
                done = te or tr
            g, ret = 0.0, []
            for r in reversed(rewards):
                g = r + cfg.gamma * g
                ret.append(g)
            returns += ret[::-1]
            log.add(0, "bc", info["world"], sum(rewards), info)
    finally:
        env.close()
    data = {k: np.stack(v) for k, v in obs_rows.items()}
    data["label"] = np.asarray(labels, dtype=np.int64)
    data["return"] = np.asarray(returns, dtype=np.float32)
    return data


def fit_bc(policy: Any, data: dict[str, np.ndarray], epochs: int, lr: float, seed: int = 0) -> dict:
    """Fit the actor to ``data["label"]`` (cross-entropy over the valid rows) and the critic to
    ``data["return"]`` (squared error); returns the final losses and the actor's agreement."""
    import torch as th

    th.manual_seed(seed)
    keys = [k for k in ("options", "valid", "global", "privileged") if k in data]
    obs = {k: th.as_tensor(data[k]) for k in keys}
    y = th.as_tensor(data["label"])
    ret = th.as_tensor(data["return"])
    opt = th.optim.Adam(policy.parameters(), lr=lr)
    n = len(y)
    rng = np.random.default_rng(seed)
    ce = vl = 0.0
    for _ in range(epochs):
        for idx in np.array_split(rng.permutation(n), max(1, n // 64)):
            i = th.as_tensor(idx)
            feats = policy.extract_features({k: v[i] for k, v in obs.items()})
            logits = policy.mlp_extractor.forward_actor(feats)
            value = policy.value_net(policy.mlp_extractor.forward_critic(feats)).squeeze(1)
            loss_pi = th.nn.functional.cross_entropy(logits, y[i])
            loss_v = th.nn.functional.mse_loss(value, ret[i])
            opt.zero_grad()
            (loss_pi + 0.5 * loss_v).backward()
            opt.step()
            ce, vl = float(loss_pi.detach()), float(loss_v.detach())
    with th.no_grad():
        pick = policy.mlp_extractor.forward_actor(policy.extract_features(obs)).argmax(1)
    return {"bc_ce": ce, "bc_value_mse": vl, "bc_agree": float((pick == y).float().mean())}


def _new_model(cfg: OptionPPOConfig, vec_env: Any, out: Path) -> Any:
    from sb3_contrib import MaskablePPO

    from semexplore_gym.policies.option_ppo import option_network_classes

    return MaskablePPO(
        option_network_classes()["OptionActorCriticPolicy"], vec_env,
        learning_rate=cfg.learning_rate, n_steps=cfg.n_steps, batch_size=cfg.batch_size,
        n_epochs=cfg.n_epochs, gamma=cfg.gamma, ent_coef=cfg.ent_coef,
        policy_kwargs={"hidden": cfg.hidden}, seed=cfg.seed, device="cpu", verbose=0,
        tensorboard_log=str(out / "tb"),
    )  # fmt: skip


def _callback(out: Path, log: EpisodeLog, stop_at: float) -> Any:
    from stable_baselines3.common.callbacks import BaseCallback

    class Curve(BaseCallback):
        def _on_step(self) -> bool:
            for done, info in zip(self.locals["dones"], self.locals["infos"], strict=True):
                if done:
                    ret = float(info.get("episode_total", float("nan")))
                    log.add(self.num_timesteps, "ppo", info.get("world", "?"), ret, info)
            return time.perf_counter() < stop_at

        def _on_rollout_end(self) -> None:
            (out / "checkpoints").mkdir(exist_ok=True)
            self.model.save(str(out / "checkpoints" / "last.zip"))

    return Curve()


def plot_curve(csv_path: Path, png_path: Path) -> None:
    """``curve.png``: episode return and T at the end of each episode, BC then PPO."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with csv_path.open() as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return
    ep = [int(r["episode"]) for r in rows]
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.2))
    for phase, colour in (("bc", "tab:gray"), ("ppo", "tab:blue")):
        sel = [i for i, r in enumerate(rows) if r["phase"] == phase]
        x = np.array([ep[i] for i in sel])
        for a, key in zip(ax, ("return", "coverage"), strict=True):
            y = np.array([float(rows[i][key]) for i in sel])
            a.plot(x, y, "o", c=colour, ms=2, alpha=0.3, label=phase if key == "return" else None)
            k = len(y) // 20  # a running mean over a twentieth of the phase's episodes
            if k >= 5:
                a.plot(x[k - 1 :], np.convolve(y, np.ones(k) / k, mode="valid"), c="black", lw=1.5,
                       label=f"mean of {k} episodes" if key == "return" else None)  # fmt: skip
    ax[0].set(xlabel="episode", ylabel="return")
    ax[1].set(xlabel="episode", ylabel="coverage at the end")
    ax[0].legend()
    fig.tight_layout()
    fig.savefig(png_path, dpi=90)
    plt.close(fig)


def train_option_ppo(
    cfg: OptionPPOConfig, out: Path, log: Callable[[str], None] = print, progress: bool = True
) -> dict[str, Any]:
    """BC then PPO (see the module); resumes from ``out/checkpoints/last.zip``."""
    import torch as th
    from sb3_contrib import MaskablePPO
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    from semexplore_gym.policies.option_ppo import load_option_model

    th.set_num_threads(cfg.torch_threads)
    th.manual_seed(cfg.seed)
    worlds = training_worlds(cfg.splits, cfg.max_size_m)
    log(f"{len(worlds)} training worlds")
    curve = EpisodeLog(out / "curve.csv")
    metrics: dict[str, Any] = {}
    makers = [partial(make_world_env, cfg, worlds, i) for i in range(cfg.n_envs)]
    vec = SubprocVecEnv(makers) if cfg.vec_env == "subproc" else DummyVecEnv(makers)
    last = out / "checkpoints" / "last.zip"
    t0 = time.perf_counter()
    if last.is_file():
        model = load_option_model(last)
        model.set_env(vec)
        log(f"resuming from {last} at {model.num_timesteps} decisions")
    else:
        model = _new_model(cfg, vec, out)
        if cfg.bc_episodes:
            data_path = out / "bc_data.npz"
            if data_path.is_file():
                with np.load(data_path) as z:
                    data = {k: z[k] for k in z.files}
            else:
                data = collect_bc(cfg, worlds, curve)
                np.savez_compressed(data_path, **data)  # type: ignore[arg-type]
            metrics.update(fit_bc(model.policy, data, cfg.bc_epochs, cfg.bc_lr, cfg.seed))
            metrics["bc_decisions"] = len(data["label"])
            log(f"BC on {len(data['label'])} decisions: {metrics}")
        model.save(str(out / "bc_model.zip"))
    metrics["bc_s"] = time.perf_counter() - t0
    metrics["resumed_at"] = int(model.num_timesteps)
    remaining = cfg.total_timesteps - model.num_timesteps
    if remaining > 0:
        stop_at = t0 + cfg.wall_budget_s if cfg.wall_budget_s > 0 else math.inf
        model.learn(remaining, callback=_callback(out, curve, stop_at), progress_bar=progress,
                    reset_num_timesteps=False)  # fmt: skip
    model.save(str(out / "model.zip"))
    vec.close()
    plot_curve(out / "curve.csv", out / "curve.png")
    metrics.update(
        timesteps=int(model.num_timesteps),
        episodes=curve.episodes,
        wall_s=time.perf_counter() - t0,
    )
    assert isinstance(model, MaskablePPO)
    return metrics
