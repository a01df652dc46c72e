"""Benchmark :func:`segment_map` on synthetic corridor grids (the GRID-FAST reference setup).

Grids of ``size x size`` cells, occupied except for ``corridor_cells``-wide corridors every
``spacing_cells`` cells in both directions; each corridor segment between two crossings is
blocked with probability ``block_prob`` (seeded). Corridors run to the map edge, where the
outside counts as unknown, so the grids also have frontiers.

Each size is segmented ``--repeats`` times by its own :class:`TopometricSegmenter`, as in an
exploration loop (it reuses its scratch memory; ``--one-shot`` calls :func:`segment_map`, which
starts from fresh memory every time). Prints a markdown table of the median and fastest time by
size with the area counts, next to the GRID-FAST C++ reference (g++ -O2, one thread, measured
on the same kind of machine; see ``gridfast-notes.md`` §4). Usage::

    python scripts/bench_segmentation.py [--sizes 200 400 800 1600] [--repeats 7] [--seed 0]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from semexplore_gym.core.grid import FREE, OCCUPIED
from semexplore_gym.core.topometric import SegmentationParams, TopometricSegmenter, segment_map

#: GRID-FAST C++ total time (ms) on the same synthetic grids (gridfast-notes.md §4).
GRIDFAST_REFERENCE_MS = {200: 3.2, 400: 16.5, 800: 122.0, 1600: 2362.0}


def corridor_grid(
    size: int,
    rng: np.random.Generator,
    corridor_cells: int = 10,
    spacing_cells: int = 50,
    block_prob: float = 0.2,
) -> np.ndarray:
    """A ``size x size`` encoded grid of crossing corridors with random blockages."""
    g = np.full((size, size), OCCUPIED, dtype=np.uint8)
    offset = (spacing_cells - corridor_cells) // 2
    starts = np.arange(offset, size - corridor_cells + 1, spacing_cells)
    for s in starts:
        g[s : s + corridor_cells, :] = FREE
        g[:, s : s + corridor_cells] = FREE
    # block some segments between crossings with a short wall across the corridor
    for horizontal in (True, False):
        for s in starts:
            for k in range(len(starts) + 1):
                if rng.random() >= block_prob:
                    continue
                lo = starts[k - 1] + corridor_cells if k > 0 else 0
                hi = starts[k] if k < len(starts) else size
                if hi - lo < 6:
                    continue
                m = (lo + hi) // 2
                if horizontal:
                    g[s : s + corridor_cells, m - 2 : m + 2] = OCCUPIED
                else:
                    g[m - 2 : m + 2, s : s + corridor_cells] = OCCUPIED
    return g


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--sizes", type=int, nargs="+", default=[200, 400, 800, 1600], help="grid sizes in cells"
    )
    ap.add_argument(
        "--repeats",
        type=int,
        default=15,
        help="rounds of one timed call per size (the median and fastest are reported)",
    )
    ap.add_argument("--seed", type=int, default=0, help="seed of the random blockages")
    ap.add_argument("--resolution", type=float, default=0.05, help="cell size in metres")
    ap.add_argument(
        "--clearance", type=float, default=0.155, help="robot radius + margin in metres"
    )
    ap.add_argument(
        "--block-prob",
        type=float,
        default=0.2,
        help="probability that a corridor segment is blocked",
    )
    ap.add_argument(
        "--stages", action="store_true", help="also print the median time of each stage"
    )
    ap.add_argument(
        "--one-shot",
        action="store_true",
        help="time segment_map (fresh scratch memory per call) instead of a reused segmenter",
    )
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error("--repeats must be >= 1")

    params = SegmentationParams()
    rng = np.random.default_rng(args.seed)
    # warm-up: numba kernels are compiled (or loaded from the cache) on the first call
    segment_map(
        corridor_grid(120, np.random.default_rng(0)), args.resolution, args.clearance, params
    )
    print(
        "| map (cells) | intersections | pathways | dead ends | frontier pathways | openings "
        "| median ms | fastest ms | GRID-FAST C++ ms |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    # Round-robin over the sizes: this VM's speed drifts over seconds (other tenants), so each
    # round times one call per size and every size samples the same mix of fast and slow spells.
    grids = [corridor_grid(size, rng, block_prob=args.block_prob) for size in args.sizes]
    segmenters = [segment_map if args.one_shot else TopometricSegmenter(params) for _ in grids]
    for segment, grid in zip(segmenters, grids, strict=True):
        segment(grid, args.resolution, args.clearance, params)  # sizes a segmenter's scratch
    times: list[list[float]] = [[] for _ in grids]
    stages: list[dict[str, list[float]]] = [{} for _ in grids]
    tmaps = [None] * len(grids)
    for _ in range(args.repeats):
        for k, (segment, grid) in enumerate(zip(segmenters, grids, strict=True)):
            t0 = time.perf_counter()
            tmap = segment(grid, args.resolution, args.clearance, params)
            times[k].append((time.perf_counter() - t0) * 1000.0)
            for name, v in tmap.extras.get("stage_ms", {}).items():
                stages[k].setdefault(name, []).append(v)
            tmaps[k] = tmap
    stage_rows = []
    for size, tmap, t_ms, st in zip(args.sizes, tmaps, times, stages, strict=True):
        assert tmap is not None
        c = tmap.counts()
        ref = GRIDFAST_REFERENCE_MS.get(size)
        ref_s = f"{ref:g}" if ref is not None else "-"
        print(
            f"| {size}x{size} | {c['intersections']} | {c['pathways']} | {c['dead_ends']} "
            f"| {c['frontier_pathways']} | {len(tmap.openings)} | {np.median(t_ms):.1f} "
            f"| {np.min(t_ms):.1f} | {ref_s} |"
        )
        stage_rows.append((size, {k: float(np.median(v)) for k, v in st.items()}))
    sys.stdout.flush()
    if args.stages:
        print()
        names = list(stage_rows[0][1]) if stage_rows else []
        print("| map | " + " | ".join(names) + " |")
        print("|---|" + "---|" * len(names))
        for size, st in stage_rows:
            print(f"| {size}x{size} | " + " | ".join(f"{st.get(n, 0.0):.1f}" for n in names) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
