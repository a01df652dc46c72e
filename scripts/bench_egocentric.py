"""Benchmark the egocentric observation against the env step, per setting and per stage.

    python scripts/bench_egocentric.py [--world maze1] [--steps 300] [--repeats 5]

Each repeat drives the same seeded random walk for ``--steps`` steps (timing ``env.step``),
then times :meth:`EgocentricEncoder.encode` over the recorded raw observations for every
setting, and the stages of the training setting: the frontier-distance field over the same
observations (as the encoder runs it) and the rest of the encode. Settings and stages are
interleaved within each repeat, so a drift of the machine's speed hits them alike; medians of
``--repeats`` are printed as a markdown table. Not a test: numbers depend on the machine.
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any

import numpy as np

#: (label, EgocentricParams keyword arguments).
_TRAIN: dict[str, Any] = dict(
    crop_cells=64,
    crop_resolution_m=0.1,
    n_scan_bins=72,
    scan_bins_centred=True,
    channels=("occupancy", "frontier_distance", "trail"),
)
SETTINGS: tuple[tuple[str, dict[str, Any]], ...] = (
    ("train: 64 @ 0.1 m, 3 channels, pool_map", dict(_TRAIN, pool_map=True)),
    ("the same, sampled at full resolution (before pool_map)", _TRAIN),
    ("64 @ map resolution, occupancy", dict(crop_cells=64, crop_resolution_m=None)),
    ("64 @ 0.1 m, occupancy", dict(crop_cells=64, crop_resolution_m=0.1)),
    ("36 @ 0.15 m, occupancy", dict(crop_cells=36, crop_resolution_m=0.15)),
    ("96 @ 0.1 m, occupancy", dict(crop_cells=96, crop_resolution_m=0.1)),
)


def _walk(env: Any, n_steps: int, keep: bool) -> tuple[float, list[dict[str, np.ndarray]], dict]:
    """Seeded random walk; returns (µs per env.step, raw observations if ``keep``, last info)."""
    obs, info = env.reset(seed=0)
    rng = np.random.default_rng(0)
    raws = []
    t_step = 0.0
    for _ in range(n_steps):
        if keep:
            raws.append({k: np.array(v, copy=True) for k, v in obs.items()})
        action = np.array([rng.uniform(0.2, 1.0), rng.uniform(-1, 1)], np.float32)
        t0 = time.perf_counter()
        obs, _r, te, tr, info = env.step(action)
        t_step += time.perf_counter() - t0
        if te or tr:
            obs, info = env.reset()
    return t_step / n_steps * 1e6, raws, info


def _field_timer(encoder: Any) -> Any:
    """A function timing the frontier field over observations the way ``encoder`` builds it
    (with ``pool_map``: pooling the map, then the field on the pooled grid)."""
    from semexplore_gym.core.frontiers import distance

    params, geometry = encoder.params, encoder.geometry
    res, clear = geometry.resolution_m, params.frontier_clearance_m
    if hasattr(distance, "FrontierDistanceField"):  # kept between calls, skipped if unchanged
        # The grid the encoder searches (checkouts before pool_map: the map itself).
        sample = getattr(encoder, "sampled_grid", lambda grid: (grid, geometry))

        def run(raws: list[dict[str, np.ndarray]]) -> tuple[float, int]:
            g = sample(raws[0]["map"])[1]
            field = distance.FrontierDistanceField(g.shape, g.resolution_m, clear)
            t0 = time.perf_counter()
            n = sum(bool(field.update(sample(raw["map"])[0])) for raw in raws)
            return time.perf_counter() - t0, n

    else:  # the first encoder: recomputed, then mapped to grey levels, at every call

        def run(raws: list[dict[str, np.ndarray]]) -> tuple[float, int]:
            t0 = time.perf_counter()
            for raw in raws:
                d = distance.frontier_distance_m(raw["map"], res, clear)
                distance.relative_distance_image(d, 10, 10, params.distance_scale_per_m)
            return time.perf_counter() - t0, len(raws)

    return run


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
    _, raws, info = _walk(env, args.steps, keep=True)
    encoders = [EgocentricEncoder.from_info(EgocentricParams(**kw), info) for _, kw in SETTINGS]
    for enc in encoders:
        enc.encode(raws[0])  # numba compile / cache load outside the timing
    field_run = _field_timer(encoders[0])
    field_run(raws[:2])
    n = len(raws)
    t_enc = np.zeros((len(encoders), args.repeats))
    t_env = np.zeros(args.repeats)
    t_field = np.zeros(args.repeats)
    n_field = 0
    for rep in range(args.repeats):
        t_env[rep] = _walk(env, args.steps, keep=False)[0]
        for i, enc in enumerate(encoders):
            enc.reset()
            t0 = time.perf_counter()
            for raw in raws:
                enc.encode(raw)
            t_enc[i, rep] = (time.perf_counter() - t0) / n * 1e6
        secs, n_field = field_run(raws)
        t_field[rep] = secs / n * 1e6
    env.close()

    g = encoders[0].geometry
    step_us = float(np.median(t_env))
    print(
        f"world {args.world}: map {g.height}x{g.width} at {g.resolution_m} m, {n} observations, "
        f"median of {args.repeats}; env.step {step_us:.0f} us\n"
    )
    print("| setting | samples per cell | us per observation | x env.step |")
    print("|---|---:|---:|---:|")
    for (label, _), enc, t in zip(SETTINGS, encoders, t_enc, strict=True):
        us = float(np.median(t))
        print(f"| {label} | {enc.supersample**2} | {us:.0f} | {us / step_us:.2f} |")
    field_us, train_us = float(np.median(t_field)), float(np.median(t_enc[0]))
    print(f"\nstages of the training setting (frontier field computed on {n_field} of {n} maps):\n")
    print("| stage | us per observation |")
    print("|---|---:|")
    print(f"| env.step | {step_us:.0f} |")
    field_label = (
        "map pooling + frontier field" if encoders[0].params.pool_map else "frontier field"
    )
    print(f"| {field_label} | {field_us:.0f} |")
    print(f"| rest of encode (crops, trail, scan, features) | {max(train_us - field_us, 0):.0f} |")
    print(f"| encode | {train_us:.0f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
