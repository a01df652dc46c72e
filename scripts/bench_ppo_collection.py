"""PPO collection speed: env steps/s of ``collect_rollouts`` for several ``ppo.n_envs``/``vec_env``.

    python scripts/bench_ppo_collection.py [--train-config configs/agents/ppo_maze.yml] \
        [--n-steps 256] [--variants 1:dummy 2:dummy 2:subproc] [--repeats 2]

Times SB3's rollout collection alone (env steps, egocentric encoding, the policy's forward
pass; no gradient updates) of the PPO learner ``semexplore train --algo ppo`` builds, after one
warm-up rollout. Prints aggregate env steps/s per variant (the median of ``--repeats``). Not a
test: the numbers depend on the machine and its load (``os.getloadavg`` is printed).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Sequence


def collection_steps_per_s(
    config: str, n_envs: int, vec_env: str, n_steps: int, repeats: int
) -> float:
    from semexplore_gym.training.config import load_train_config
    from semexplore_gym.training.ppo import make_vec_env, new_ppo

    cfg = load_train_config(
        config, [f"ppo.n_envs={n_envs}", f"ppo.vec_env={vec_env}", f"ppo.n_steps={n_steps}"]
    )
    venv = make_vec_env(cfg)
    try:
        model = new_ppo(cfg, venv, None)
        _total, callback = model._setup_learn(total_timesteps=10**9, callback=None)
        callback.on_training_start(locals(), globals())
        rates = []
        for i in range(repeats + 1):
            t0 = time.perf_counter()
            model.collect_rollouts(venv, callback, model.rollout_buffer, n_rollout_steps=n_steps)
            if i:  # the first rollout warms up (numba, torch)
                rates.append(n_steps * n_envs / (time.perf_counter() - t0))
        return statistics.median(rates)
    finally:
        venv.close()


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--train-config", default="configs/agents/ppo_maze.yml")
    ap.add_argument("--n-steps", type=int, default=256, help="steps per env per rollout")
    ap.add_argument(
        "--variants", nargs="+", default=["1:dummy", "2:dummy", "2:subproc"], help="N_ENVS:VEC_ENV"
    )
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args(argv)
    import torch

    torch.set_num_threads(1)
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")
    print("| n_envs | vec_env | env steps/s |\n|---:|---|---:|")
    for v in args.variants:
        n, _, kind = v.partition(":")
        rate = collection_steps_per_s(
            args.train_config, int(n), kind or "auto", args.n_steps, args.repeats
        )
        print(f"| {n} | {kind} | {rate:.0f} |", flush=True)
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
