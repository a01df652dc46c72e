"""Benchmark a whole semantic-expert mission: simulated time / wall time and the stage split.

A warm-up mission (numba compilation, caches) runs first and is not timed. Then each timed
mission runs the full loop (env stepping, segmentation, Algorithm 1, potential field) and the
script prints the speed-up over simulated time, by wall clock and by the process's CPU time
(the same on an idle machine; CPU time is not inflated by other load), and where the wall time
went. The acceptance target is a maze1 mission at >= 100x simulated time. ``--seg-stages``
adds the map generation's own split: the mean time per segmentation of each stage of
:class:`~semexplore_gym.core.topometric.TopometricSegmenter` (its ``stage_ms``).

Usage::

    python scripts/bench_expert.py [--world maze1] [--seeds 0 1 2] [--policy-set KEY=VALUE] [--json]
        [--seg-stages] [--map-observation shared]
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--world", default="maze1", help="world spec (default: maze1)")
    ap.add_argument(
        "--seeds", type=int, nargs="+", default=[0], help="seeds of the timed missions (default: 0)"
    )
    ap.add_argument(
        "--policy-config", default=None, help="policy config YAML (sections env / policy / params)"
    )
    ap.add_argument(
        "--policy-set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="policy parameter override",
    )
    ap.add_argument(
        "--max-time-s", type=float, default=1200.0, help="simulated time limit (default: 1200)"
    )
    ap.add_argument(
        "--map-observation",
        default="auto",
        choices=["auto", "copy", "shared"],
        help="env option map_observation: a fresh map copy per step or a read-only live view; "
        "auto (default) gives the expert the live view, as semexplore explore/benchmark do "
        "(its missions are the same either way)",
    )
    ap.add_argument("--no-warmup", action="store_true", help="skip the untimed warm-up mission")
    ap.add_argument(
        "--json", action="store_true", help="print one JSON object per mission instead of the table"
    )
    ap.add_argument(
        "--seg-stages",
        action="store_true",
        help="also print the mean time per segmentation of each segmentation stage",
    )
    args = ap.parse_args(argv)

    import gymnasium as gym
    from semexplore_gym.policies.registry import make_policy
    from semexplore_gym.policies.specs import load_policy_config

    import semexplore_gym  # noqa: F401
    from semexplore_gym.core.topometric import TopometricSegmenter
    from semexplore_gym.evaluation.rollout import STAGES, map_observation_for, run_mission

    class StageRecorder(TopometricSegmenter):
        """The expert's segmenter, adding up each call's ``stage_ms``."""

        def __init__(self) -> None:
            super().__init__()
            self.calls = 0
            self.stage_ms: dict[str, float] = {}

        def __call__(self, *a, **k):  # type: ignore[no-untyped-def]
            tmap = super().__call__(*a, **k)
            self.calls += 1
            for name, ms in tmap.extras.get("stage_ms", {}).items():
                self.stage_ms[name] = self.stage_ms.get(name, 0.0) + ms
            return tmap

    cfg = load_policy_config(args.policy_config)
    kwargs = cfg.policy_kwargs(args.overrides)
    if args.map_observation == "auto":
        env_kwargs = map_observation_for(make_policy("semantic", **dict(kwargs)))
    elif args.map_observation == "shared":
        env_kwargs = {"map_observation": "shared", "disable_env_checker": True}
    else:
        env_kwargs = {"map_observation": "copy"}
    env = gym.make(
        "SemanticExplore-v0",
        world=args.world,
        config=cfg.env,
        overrides=[f"episode.max_time_s={args.max_time_s!r}"],
        **env_kwargs,
    )
    if not args.no_warmup:
        run_mission(
            env,
            make_policy("semantic", **dict(kwargs)),
            seed=args.seeds[0],
            max_time_s=args.max_time_s,
            progress=False,
            ignore_terminated=True,
        )
    rows = []
    for seed in args.seeds:
        recorder = StageRecorder() if args.seg_stages else None
        policy = make_policy("semantic", **dict(kwargs))
        if recorder is not None:
            policy = type(policy)(params=policy.params, segmenter=recorder)
        res = run_mission(
            env,
            policy,
            seed=seed,
            max_time_s=args.max_time_s,
            progress=False,
            ignore_terminated=True,
        )
        rows.append(res)
        s = res.summary()
        if args.json:
            cpu_x = round(res.mission_time_s / res.cpu_time_s, 1) if res.cpu_time_s > 0 else None
            print(
                json.dumps({**s, "speedup": round(res.speedup, 1), "cpu_speedup": cpu_x}),
                flush=True,
            )
            continue
        print(
            f"{res.world} seed {seed}: {s['mission_time_s']:.1f} s simulated in {s['wall_time_s']:.2f} s wall -> {res.speedup:.0f}x "
            f"({s['cpu_time_s']:.2f} s CPU -> {res.mission_time_s / max(res.cpu_time_s, 1e-9):.0f}x; "
            f"coverage {s['coverage']:.3f}, {s['steps']} steps, {s['n_replans']} replans, stop: {s['stop_reason']})"
        )
        print(
            f"  map generation {s['mean_map_generation_ms']:.2f} ms / call, global planning {s['mean_global_planning_ms']:.2f} ms / replan"
        )
        total = sum(res.stage_time_s.values())
        print(f"  {'stage':16s} {'total s':>8s} {'ms/step':>8s} {'share':>6s}")
        for k in STAGES:
            v = res.stage_time_s[k]
            print(
                f"  {k:16s} {v:8.3f} {1e3 * v / max(1, res.steps):8.3f} {100 * v / total if total else 0:5.1f}%"
            )
        if recorder is not None and recorder.calls:
            seg_total = sum(recorder.stage_ms.values())
            print(f"  segmentation stages over {recorder.calls} calls (ms per call):")
            for name, ms in recorder.stage_ms.items():
                print(
                    f"    {name:14s} {ms / recorder.calls:7.3f} {100 * ms / seg_total if seg_total else 0:5.1f}%"
                )
    env.close()
    if not args.json and len(rows) > 1:
        sp = np.array([r.speedup for r in rows])
        cp = np.array([r.mission_time_s / max(r.cpu_time_s, 1e-9) for r in rows])
        print(
            f"speed-up over {len(rows)} missions: wall median {np.median(sp):.0f}x (min {sp.min():.0f}x), "
            f"CPU median {np.median(cp):.0f}x (min {cp.min():.0f}x)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
