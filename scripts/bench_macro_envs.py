"""Fixed-policy baselines of the macro-action env ids, and their decision cost.

Runs whole episodes of ``SemanticExploreFrontier-v0`` with ``first`` (always candidate 0: the
cheapest frontier by ``C``, i.e. the expert's own choice) and ``random`` (a uniformly random valid
candidate), and of ``SemanticExploreWeights-v0`` with ``paper`` (action 0: the paper's weights)
and ``random`` (uniform actions). ``--frontier-model`` / ``--weights-model`` add a ``model``
row for a trained agent (``semexplore train --algo maskable_ppo`` / ``--algo ppo``), acting
deterministically. Prints a markdown table of mean return, final coverage,
simulated mission time, decisions per episode and wall-clock ms per decision: the numbers a
learned agent has to beat.

Usage::

    python scripts/bench_macro_envs.py [--world 'maze:seed=*,size_m=6'] [--episodes 4] [--max-time-s 240]
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import semexplore_gym  # noqa: F401  (registers the env ids)

BASELINES = {
    "SemanticExploreFrontier-v0": ("first", "random"),
    "SemanticExploreWeights-v0": ("paper", "random"),
}


def _action(
    env: gym.Env,
    env_id: str,
    baseline: str,
    rng: np.random.Generator,
    obs: np.ndarray,
    model: object,
) -> object:
    if env_id.startswith("SemanticExploreFrontier"):
        mask = env.get_wrapper_attr("action_masks")()
        if baseline == "model":
            return int(model.predict(obs, action_masks=mask, deterministic=True)[0])  # type: ignore[attr-defined]
        return 0 if baseline == "first" else int(rng.choice(np.flatnonzero(mask)))
    if baseline == "model":
        return model.predict(obs, deterministic=True)[0]  # type: ignore[attr-defined]
    if baseline == "paper":
        return np.zeros(3, np.float32)
    return rng.uniform(-1.0, 1.0, 3).astype(np.float32)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--world", default="maze:seed=*,size_m=6", help="world ('seed=*' takes the episode seed)"
    )
    ap.add_argument("--episodes", type=int, default=4, help="episodes (seeds 0..N-1) per baseline")
    ap.add_argument(
        "--max-time-s", type=float, default=240.0, help="episode time limit (simulated s)"
    )
    ap.add_argument("--seed0", type=int, default=0, help="first seed")
    ap.add_argument(
        "--frontier-model", default=None, help="MaskablePPO model.zip for the frontier env"
    )
    ap.add_argument("--weights-model", default=None, help="PPO model.zip for the weights env")
    ap.add_argument("--only-models", action="store_true", help="skip the fixed baselines")
    args = ap.parse_args(argv)
    models: dict[str, object] = {}
    if args.frontier_model:
        from sb3_contrib import MaskablePPO

        models["SemanticExploreFrontier-v0"] = MaskablePPO.load(args.frontier_model, device="cpu")
    if args.weights_model:
        from stable_baselines3 import PPO

        models["SemanticExploreWeights-v0"] = PPO.load(args.weights_model, device="cpu")
    if args.episodes < 1:
        raise SystemExit(f"--episodes must be >= 1, got {args.episodes}")
    print("| env | baseline | return | coverage | mission time s | decisions | ms/decision |")
    print("|---|---|---|---|---|---|---|")
    for env_id, baselines in BASELINES.items():
        runs = () if args.only_models else baselines
        for baseline in (*runs, "model") if env_id in models else runs:
            rets, covs, times, decs, ms = [], [], [], [], []
            for seed in range(args.seed0, args.seed0 + args.episodes):
                world = args.world.replace("seed=*", f"seed={seed}")
                env = gym.make(
                    env_id, world=world, overrides=[f"episode.max_time_s={args.max_time_s:g}"]
                )
                rng = np.random.default_rng(seed)
                obs, info = env.reset(seed=seed)
                ret, n = 0.0, 0
                t0 = time.perf_counter()
                while True:
                    action = _action(env, env_id, baseline, rng, obs, models.get(env_id))
                    obs, r, term, trunc, info = env.step(action)
                    ret += r
                    n += 1
                    if term or trunc:
                        break
                ms.append((time.perf_counter() - t0) * 1e3 / n)
                rets.append(ret)
                covs.append(info["coverage"])
                times.append(info["sim_time_s"])
                decs.append(n)
                env.close()
            print(
                f"| {env_id} | {baseline} | {np.mean(rets):.2f} | {np.mean(covs):.3f} | "
                f"{np.mean(times):.1f} | {np.mean(decs):.1f} | {np.median(ms):.0f} |",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
