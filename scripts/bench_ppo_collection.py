"""PPO collection speed: env steps/s of ``collect_rollouts`` for several ``ppo.n_envs``/``vec_env``.

    python scripts/bench_ppo_collection.py [--train-config configs/agents/ppo_maze.yml] \
        [--n-steps 256] [--variants 1:dummy 2:dummy 4:dummy 4:subproc] [--repeats 3]

Times SB3's rollout collection alone (env steps, egocentric encoding, the policy's forward
pass; no gradient updates) of the PPO learner ``semexplore train --algo ppo`` builds, after one
warm-up rollout. Every variant is built first, then each repeat times one rollout of each in
turn (round-robin, so drift of the machine's speed hits all alike). Prints aggregate env steps/s
per variant (the median of ``--repeats``, and the range). Not a test: the numbers depend on the
machine and its load (``os.getloadavg`` is printed).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Sequence


class Collector:
    """The PPO learner ``semexplore train --algo ppo`` builds, with ``n_envs`` envs stepped by
    ``vec_env``, ready to time one rollout collection at a time."""

    def __init__(self, config: str, n_envs: int, vec_env: str, n_steps: int) -> None:
        from semexplore_gym.training.ppo import make_vec_env, new_ppo
        from semexplore_gym.training.train_config import load_train_config

        cfg = load_train_config(
            config, [f"ppo.n_envs={n_envs}", f"ppo.vec_env={vec_env}", f"ppo.n_steps={n_steps}"]
        )
        self.n_envs, self.n_steps = n_envs, n_steps
        self.venv = make_vec_env(cfg)
        self.model = new_ppo(cfg, self.venv, None)
        _total, self.callback = self.model._setup_learn(total_timesteps=10**9, callback=None)
        self.callback.on_training_start(locals(), globals())
        self.rate()  # the first rollout warms up (numba, torch)

    def rate(self) -> float:
        """Env steps/s of one rollout collection."""
        t0 = time.perf_counter()
        self.model.collect_rollouts(
            self.venv, self.callback, self.model.rollout_buffer, n_rollout_steps=self.n_steps
        )
        return self.n_steps * self.n_envs / (time.perf_counter() - t0)

    def close(self) -> None:
        self.venv.close()


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--train-config", default="configs/agents/ppo_maze.yml")
    ap.add_argument("--n-steps", type=int, default=256, help="steps per env per rollout")
    ap.add_argument(
        "--variants",
        nargs="+",
        default=["1:dummy", "2:dummy", "4:dummy", "4:subproc"],
        help="N_ENVS:VEC_ENV",
    )
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    import torch

    torch.set_num_threads(1)
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")
    print("| n_envs | vec_env | env steps/s (median) | min-max |\n|---:|---|---:|---|")
    collectors = []
    try:
        for v in args.variants:
            n, _, kind = v.partition(":")
            collectors.append(Collector(args.train_config, int(n), kind or "auto", args.n_steps))
        rates: list[list[float]] = [[] for _ in collectors]
        for _ in range(args.repeats):  # round-robin: machine drift hits every variant alike
            for c, r in zip(collectors, rates, strict=True):
                r.append(c.rate())
        for v, r in zip(args.variants, rates, strict=True):
            n, _, kind = v.partition(":")
            print(
                f"| {n} | {kind or 'auto'} | {statistics.median(r):.0f} | "
                f"{min(r):.0f}-{max(r):.0f} |"
            )
    finally:
        for c in collectors:
            c.close()
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
