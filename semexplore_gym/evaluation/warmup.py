"""Load (or, on a fresh clone, compile) the numba kernels before a mission's clocks start.

Every hot loop is ``@njit(cache=True)``: the first run of a checkout compiles them (a minute or
two on 2 cores) and writes them to ``__pycache__``; later processes load them from there (a
second or two). Either cost lands in whatever calls a kernel first. :func:`warm_up` pays it up
front, so that a mission's reported wall time and per-call timings are the planners' own: it
runs a short mission of a fresh policy, then reaches the kernels a short mission may miss
(every world family's generator and loader, the segmentation of a map with intersections),
then loads every other kernel the disk cache holds for the modules now imported, and says on
stderr what is going on when numba really compiles (numba's ``numba:compile`` event fires only
on a cache miss). The warm-up env gives the policy the same map observation as the real
mission (:func:`~semexplore_gym.evaluation.rollout.map_observation_for`): numba compiles a
kernel per argument type, and a read-only array is another type than a writable one.

Why not ahead-of-time compilation: numba's AOT (``numba.pycc``) is deprecated, needs explicit
signatures for every kernel and a compiler at install time, and its extension modules would
replace the ``@njit`` functions the tests and callers use; the disk cache gives the same
steady state after one run. ``tests/evaluation/test_warmup_first_row.py`` checks, on an empty
cache, that no kernel compiles inside a benchmark's missions and that the first row's per-call
times are those of the rows after it.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Hashable
from typing import Any, TextIO

#: The world of the warm-up mission: a 3 m maze the semantic expert finishes in 53 s, passing
#: through its semantic plans, grid-frontier fallback, a stuck recovery and its stop.
WARMUP_WORLD = "maze:seed=0,size_m=3"
#: Simulated seconds of the warm-up mission at most (it stops when the policy is done).
WARMUP_TIME_S = 60.0
#: One small world per procedural family: their generators' kernels (rasterising, dropping
#: small free components) compile here rather than in a mission's reset.
FAMILY_WORLDS = (
    "maze:seed=0,size_m=3",
    "office:seed=0,size_m=8",
    "cave:seed=0,size_m=6",
    "forest:seed=0,size_m=6",
)
#: A world whose map has intersections: segmenting it joins legs at their centres, which the
#: 3 m maze never does.
SEGMENTED_WORLD = "maze1"
#: A world whose skeleton has spurs to prune (their removal re-thins it): the warm-up mission
#: reaches that only by chance, depending on the path the policy drives.
PRUNED_WORLD = "office:seed=0,size_m=8"
#: How long compiling every kernel takes: 296 kernels in 64 s of CPU time, one core (measured
#: for the semantic expert on an empty cache), so about a minute when that core is free; 3-6 min
#: of wall time on a 2-core machine shared by ~8 jobs. The warm-up prints the real figure.
COMPILE_ESTIMATE = "about 1 min on an idle machine, more under load"
#: The notice on stderr when numba starts compiling (``{n}``: kernels of the imported modules
#: that have nothing in the disk cache yet; a later run may compile a few more, for new code or
#: argument types).
COMPILE_MESSAGE = f"compiling {{n}} numba kernels not yet cached ({COMPILE_ESTIMATE})..."
#: Keys of the warm-ups this process has done (a process loads a kernel once; the set only
#: saves repeating the warm-up mission, it changes no result).
_WARMED_UP: set[Hashable] = set()


def warm_up(
    make_policy: Callable[[], Any],
    config: Any = None,
    overrides: list[str] | None = None,
    *,
    key: Hashable | None = None,
    stream: TextIO | None = None,
    env_kwargs: dict[str, Any] | None = None,
) -> dict[str, float]:
    """Run a short throw-away mission so the kernels of the env and the policy are loaded.

    Args:
        make_policy: Returns a fresh policy of the kind the real mission runs (the warm-up
            mission must not change the real policy's state).
        config: The env config of the real mission (so the kernels see the same types).
        overrides: Its env overrides (``episode.max_time_s`` is replaced).
        key: Skip the warm-up when this process already did one with the same key (e.g. the
            policy spec and env config of every mission of a benchmark).
        stream: Where the compile message goes (default: ``sys.stderr``).
        env_kwargs: The real mission env's map observation arguments (``map_observation``,
            ...); default: :func:`~semexplore_gym.evaluation.rollout.map_observation_for` the
            policy, as the CLI and the benchmark harness make their envs.

    Returns:
        ``{"wall_s": ..., "compiled": n, "loaded": n}``: the warm-up's wall time, the number
        of kernels numba compiled (0 when the on-disk cache had them all) and the number of
        further cached kernels loaded.
    """
    from numba.core import event

    import semexplore_gym  # noqa: F401  (registers the env)
    from semexplore_gym.evaluation.rollout import map_observation_for

    if key is not None and key in _WARMED_UP:
        return {"wall_s": 0.0, "compiled": 0.0, "loaded": 0.0}
    out = stream if stream is not None else sys.stderr
    compiled = 0

    class _OnCompile(event.Listener):
        def on_start(self, ev: Any) -> None:
            nonlocal compiled
            if compiled == 0:
                n = count_uncached_kernels()
                text = COMPILE_MESSAGE.format(n=n) if n else COMPILE_MESSAGE.replace("{n} ", "")
                notice(text, out)
            compiled += 1

        def on_end(self, ev: Any) -> None:
            pass

    t0 = time.perf_counter()
    env_overrides = [
        *(o for o in (overrides or []) if not o.startswith("episode.")),
        f"episode.max_time_s={WARMUP_TIME_S!r}",
    ]
    with event.install_listener("numba:compile", _OnCompile()):
        policy = make_policy()
        # The map observation the real mission gives this policy (a read-only shared map for
        # the scripted ones): kernels are compiled per argument type, read-only arrays included.
        run_warmup_mission(
            policy,
            config,
            env_overrides,
            map_observation_for(policy) if env_kwargs is None else env_kwargs,
        )
        reach_rare_kernels()
    loaded = load_cached_kernels()
    if key is not None:
        _WARMED_UP.add(key)
    wall_s = time.perf_counter() - t0
    if compiled:
        print(
            f"compiled {compiled} numba kernels in {wall_s:.0f} s (cached for later runs)",
            file=out,
            flush=True,
        )
    return {"wall_s": wall_s, "compiled": float(compiled), "loaded": float(loaded)}


def run_warmup_mission(
    policy: Any, config: Any, overrides: list[str], env_kwargs: dict[str, Any]
) -> None:
    """Drive ``policy`` in :data:`WARMUP_WORLD` until it stops or the episode ends."""
    import gymnasium as gym

    env = gym.make(
        "SemanticExplore-v0", world=WARMUP_WORLD, config=config, overrides=overrides, **env_kwargs
    )
    try:
        obs, info = env.reset(seed=0)
        policy.reset(obs, info, seed=0)
        while True:
            action = policy.act(obs, info)
            if policy.done:
                break
            obs, _, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                break
    finally:
        env.close()


def reach_rare_kernels() -> None:
    """Run the kernels a short mission may not reach: each procedural family's generator, a
    ROS map and a HouseExpo plan loaded from files, and the segmentation (of a read-only map, as
    the expert sees it) of :data:`SEGMENTED_WORLD`'s and :data:`PRUNED_WORLD`'s ground truths,
    and the path decomposition's shortest path at a clearance."""
    import json
    import tempfile
    from pathlib import Path

    import numpy as np
    from PIL import Image

    from semexplore_gym.core.grid import FREE, OCCUPIED, GridGeometry
    from semexplore_gym.core.planning.clearance_path import clear_cells, shortest_clear_path_m
    from semexplore_gym.core.topometric import segment_map
    from semexplore_gym.maps import make_world

    for spec in FAMILY_WORLDS:
        make_world(spec)
    with tempfile.TemporaryDirectory(prefix="semexplore-warmup-") as tmp:
        d = Path(tmp)
        pixels = np.full((24, 24), 254, np.uint8)
        pixels[[0, -1], :] = 0
        pixels[:, [0, -1]] = 0
        pixels[8:16, 10:12] = 0
        Image.fromarray(pixels).save(d / "map.pgm")
        (d / "map.yaml").write_text(
            "image: map.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
        )
        make_world(d / "map.yaml")
        house = [[0, 0], [0, 3], [4, 3], [4, 0], [2.05, 0], [2.05, 2], [1.95, 2], [1.95, 0]]
        plan = {"id": "0" * 32, "room_num": 1, "bbox": {"min": [0, 0], "max": [4, 3]}}
        (d / "plan.json").write_text(json.dumps({**plan, "verts": house}))
        make_world(d / "plan.json")
    for spec in (SEGMENTED_WORLD, PRUNED_WORLD):
        world = make_world(spec)
        grid = np.where(world.free_mask, FREE, OCCUPIED).astype(np.uint8)
        grid.setflags(write=False)
        segment_map(grid, world.free_geometry, clearance_m=0.2)
    # The path decomposition's shortest paths, measured when a mission ends.
    room = np.full((12, 12), FREE, np.uint8)
    room[[0, -1], :] = room[:, [0, -1]] = OCCUPIED
    geo = GridGeometry(0.1, 0.0, 0.0, 12, 12)
    shortest_clear_path_m(clear_cells(room, geo, 0.1), geo, (0.3, 0.3), (0.85, 0.75), 0.2)


def notice(text: str, out: TextIO) -> None:
    """Print ``text`` as a line of its own: above a tqdm bar this process is drawing on ``out``
    (never after it on the bar's line), else plainly."""
    try:
        from tqdm import tqdm

        active = bool(tqdm._instances)  # tqdm.write clears and redraws the bars on ``out``
    except (ImportError, AttributeError):  # pragma: no cover - tqdm is a dependency
        active = False
    if active:
        tqdm.write(text, file=out)
    else:
        print(text, file=out, flush=True)


def _cached_signatures(dispatcher: Any) -> list[Any] | None:
    """The signatures numba's disk cache holds for ``dispatcher`` (None: not cached on disk)."""
    if dispatcher._cache is None:
        return None
    try:  # numba internals: the cache index maps (signature, ...) -> data file
        return [key[0] for key in dispatcher._cache._cache_file._load_index()]
    except Exception:  # noqa: BLE001 - no disk cache, or another numba version
        return None


def _kernels(prefixes: tuple[str, ...]) -> list[Any]:
    """The numba dispatchers of the imported modules named ``prefixes...``."""
    from numba.core.dispatcher import Dispatcher

    return [
        obj
        for name, module in list(sys.modules.items())
        if module is not None and name.startswith(prefixes)
        for obj in list(vars(module).values())
        if isinstance(obj, Dispatcher)
    ]


def count_uncached_kernels(prefixes: tuple[str, ...] = ("semexplore_gym",)) -> int:
    """How many disk-cached kernels of the imported modules have no signature in the cache."""
    return sum(1 for k in _kernels(prefixes) if _cached_signatures(k) == [])


def load_cached_kernels(prefixes: tuple[str, ...] = ("semexplore_gym",)) -> int:
    """Load every signature the disk cache holds for the kernels of the imported modules.

    Returns:
        How many were loaded (0 where numba's cache layout is not the one this reads).
    """
    n = 0
    for obj in _kernels(prefixes):
        # None: another numba version or no disk cache; the mission loads lazily
        for sig in _cached_signatures(obj) or []:
            if tuple(sig) not in obj.overloads:
                try:
                    obj.compile(sig)
                except Exception:  # noqa: BLE001 - a stale entry: compiled lazily if used
                    continue
                n += 1
    return n
