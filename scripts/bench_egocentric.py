"""Benchmark the egocentric observation: microseconds per encoded observation, by crop setting.

    python scripts/bench_egocentric.py [--world maze1] [--steps 300] [--repeats 5]

Drives a random-walk for ``--steps`` steps to collect raw observations, then times
:meth:`EgocentricEncoder.encode` over them (median of ``--repeats``, interleaved settings).
Prints a markdown table. Not a test: numbers depend on the machine.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

SETTINGS = (
    (64, None),
    (64, 0.1),
    (36, 0.15),
    (96, 0.1),
)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--world", default="maze1", help="world spec (default: maze1)")
    parser.add_argument("--steps", type=int, default=300, help="observations to encode per repeat")
    parser.add_argument("--repeats", type=int, default=5, help="timing repeats (median reported)")
    args = parser.parse_args(argv)
    if args.steps < 1 or args.repeats < 1:
        parser.error("--steps and --repeats must be positive")

    import gymnasium as gym

    import semexplore_gym  # noqa: F401
    from semexplore_gym.wrappers.egocentric import EgocentricEncoder, EgocentricParams

    env = gym.make("SemanticExplore-v0", world=args.world)
    obs, info = env.reset(seed=0)
    rng = np.random.default_rng(0)
    raws = []
    for _ in range(args.steps):
        raws.append({k: v.copy() for k, v in obs.items()})
        obs, _r, te, tr, info = env.step(
            np.array([rng.uniform(0.2, 1.0), rng.uniform(-1, 1)], np.float32)
        )
        if te or tr:
            obs, info = env.reset()
    encoders = [
        EgocentricEncoder.from_info(EgocentricParams(crop_cells=c, crop_resolution_m=r), info)
        for c, r in SETTINGS
    ]
    for enc in encoders:
        enc.encode(raws[0])  # numba compile / cache load outside the timing
    times = np.zeros((len(encoders), args.repeats))
    for rep in range(args.repeats):
        for i, enc in enumerate(encoders):
            t0 = time.perf_counter()
            for raw in raws:
                enc.encode(raw)
            times[i, rep] = (time.perf_counter() - t0) / len(raws) * 1e6
    g = encoders[0].geometry
    print(
        f"world {args.world}: map {g.height}x{g.width} at {g.resolution_m} m, {len(raws)} observations, median of {args.repeats}\n"
    )
    print("| crop cells | crop resolution m | samples per cell | us per observation |")
    print("|---:|---:|---:|---:|")
    for (c, r), enc, t in zip(SETTINGS, encoders, times, strict=True):
        print(
            f"| {c} | {r if r is not None else g.resolution_m} | {enc.supersample**2} | {np.median(t):.0f} |"
        )
    env.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
