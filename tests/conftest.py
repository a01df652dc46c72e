"""Shared test helpers."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

#: ``SEMEXPLORE_TEST_HIDE_SHARED=1`` runs the tests as on a clean clone, without ``../shared``
#: beside the repository: tests marked ``shared_maps`` skip, and ``tests/test_readme.py`` skips
#: the commands that need the real maps (``.ci/run`` runs it so once more).
HIDE_SHARED_ENV = "SEMEXPLORE_TEST_HIDE_SHARED"
SHARED = Path(__file__).resolve().parents[1].parent / "shared"


def shared_hidden() -> bool:
    """Whether ``../shared`` is hidden from the tests (see :data:`HIDE_SHARED_ENV`)."""
    return os.environ.get(HIDE_SHARED_ENV) == "1"


@pytest.fixture(scope="session")
def shared_dir() -> Path | None:
    """``../shared`` beside the repository, or None when it is absent or hidden."""
    return None if shared_hidden() or not SHARED.is_dir() else SHARED


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if not shared_hidden():
        return
    skip = pytest.mark.skip(reason=f"../shared hidden ({HIDE_SHARED_ENV}=1)")
    for item in items:
        if item.get_closest_marker("shared_maps") is not None:
            item.add_marker(skip)


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """``-n auto`` (pyproject's addopts): one worker per core, at most 4 (each worker loads the
    numba kernels and the env once; more workers than that mostly wait on each other)."""
    return max(1, min(4, os.cpu_count() or 1))


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        f"clean_clone: run once more by .ci/run with ../shared hidden ({HIDE_SHARED_ENV}=1)",
    )


# ------------------------------------------------------------------------------ the fast tier
#: Simulated seconds of env missions a test not marked ``slow`` may run in this process (every
#: ``SemanticExploreEnv.advance``, which ``step`` and the vector env call, and every
#: ``SemanticExploreMultiEnv.step`` counts its ``dt_s``). ``pytest -m "not slow"`` is the
#: contributors' fast tier (DEVELOPERS.md, "Tests"): a whole mission with a big budget belongs
#: in the slow tier, and this limit says so by failing the test. Simulated time, not wall time:
#: the same verdict on any machine and under any load (the fast tier's largest was 999 s when
#: the limit was set). Not counted: missions in worker processes (``--workers 2``,
#: subprocesses) and policies driven without the env; mark those by hand.
FAST_TIER_SIMULATED_S = 1200.0


class _SimulatedClock:
    """Simulated seconds of env steps since the last :meth:`reset`."""

    def __init__(self) -> None:
        self.seconds = 0.0

    def reset(self) -> None:
        self.seconds = 0.0

    def count(self, cls: type, method: str) -> Callable[[], None]:
        """Count ``cls.method``'s calls (``dt_s`` of the env's config each); returns the undo."""
        original = getattr(cls, method)

        def counted(env, *args, **kwargs):
            self.seconds += env.config.episode.dt_s
            return original(env, *args, **kwargs)

        setattr(cls, method, counted)
        return lambda: setattr(cls, method, original)


@pytest.fixture(scope="session")
def _simulated_clock() -> Iterator[_SimulatedClock]:
    from semexplore_gym.envs.semantic_explore import SemanticExploreEnv

    clock = _SimulatedClock()
    undo = [clock.count(SemanticExploreEnv, "advance")]
    try:  # the multi-robot env needs the 'multi' extra (pettingzoo)
        from semexplore_gym.envs.multi_robot import SemanticExploreMultiEnv
    except ImportError:
        pass
    else:
        undo.append(clock.count(SemanticExploreMultiEnv, "step"))
    yield clock
    for restore in undo:
        restore()


@pytest.fixture(autouse=True)
def _fast_tier_budget(request: pytest.FixtureRequest, _simulated_clock: _SimulatedClock):
    """Fail a test not marked ``slow`` whose missions simulate more than
    :data:`FAST_TIER_SIMULATED_S`."""
    _simulated_clock.reset()
    yield
    simulated_s = _simulated_clock.seconds
    request.node.user_properties.append(("simulated_s", round(simulated_s, 1)))
    if simulated_s > FAST_TIER_SIMULATED_S and request.node.get_closest_marker("slow") is None:
        pytest.fail(
            f"{request.node.nodeid} runs {simulated_s:.0f} s of simulated missions (fast-tier "
            f"limit {FAST_TIER_SIMULATED_S:.0f} s): shrink its budget or mark it "
            "@pytest.mark.slow",
            pytrace=False,
        )


@pytest.fixture(scope="session")
def docs_commands_checker():
    """``scripts/check_docs_commands.py`` as a module (the docs' long-block checker)."""
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "scripts" / "check_docs_commands.py"
    spec = importlib.util.spec_from_file_location("check_docs_commands", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def tiny_macro_train_args() -> Callable[[float], list[str]]:
    """``semexplore train`` overrides for a few-step macro-env training on a 4 m maze.

    Call it with the decision length in simulated seconds (``max_macro_time_s`` and
    ``decision_period_s``).
    """

    def args(decision_s: float) -> list[str]:
        return [
            "--train-set", "env.world=maze:seed=0,size_m=4",
            "--train-set", "env.overrides=[episode.max_time_s=30]",
            "--train-set", "ppo.total_timesteps=8",
            "--train-set", "ppo.n_steps=4",
            "--train-set", "ppo.batch_size=4",
            "--train-set", "ppo.n_epochs=1",
            "--train-set", f"env.macro.max_macro_time_s={decision_s:g}",
            "--train-set", f"env.macro.decision_period_s={decision_s:g}",
            "--no-progress",
        ]  # fmt: skip

    return args


@pytest.fixture(scope="module")
def one_torch_thread() -> Iterator[None]:
    """Torch on one thread for the module: small nets on a shared 2-core machine train several
    times faster than with threads competing (restored afterwards; no-op without torch)."""
    try:
        import torch
    except ImportError:
        yield
        return
    n = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(n)


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _segments_intersect(p0, p1, q0, q1) -> bool:
    """Closed segments p0-p1 and q0-q1 share a point (independent of the package's kernels)."""
    p0, p1, q0, q1 = (np.asarray(v, dtype=float) for v in (p0, p1, q0, q1))
    d1 = _cross(p1 - p0, q0 - p0)
    d2 = _cross(p1 - p0, q1 - p0)
    d3 = _cross(q1 - q0, p0 - q0)
    d4 = _cross(q1 - q0, p1 - q0)
    if (
        ((d1 > 0) != (d2 > 0))
        and ((d3 > 0) != (d4 > 0))
        and d1 != 0
        and d2 != 0
        and d3 != 0
        and d4 != 0
    ):
        return True

    def on(a, b, c) -> bool:
        return (
            abs(_cross(b - a, c - a)) < 1e-12
            and min(a[0], b[0]) - 1e-12 <= c[0] <= max(a[0], b[0]) + 1e-12
            and (min(a[1], b[1]) - 1e-12 <= c[1] <= max(a[1], b[1]) + 1e-12)
        )

    return on(p0, p1, q0) or on(p0, p1, q1) or on(q0, q1, p0) or on(q0, q1, p1)


def _blocked(segments: np.ndarray, a, b) -> bool:
    """Some wall segment crosses the straight line from ``a`` to ``b``."""
    return any(_segments_intersect(a, b, s[:2], s[2:]) for s in segments)


@pytest.fixture
def segments_block():
    """``segments_block(segments, a, b)``: a wall segment (rows ``x0, y0, x1, y1``) crosses the
    straight line a-b, by plain geometry independent of the package's kernels."""
    return _blocked


def _privileged_world(world, start, radius_m: float, range_m: float, res_m: float):
    """The oracle's view of ``world`` from ``start``: the reachable mask at the env's coverage
    clearance (radius + 0.01 m) and a 360-beam LiDAR of ``range_m``."""
    from semexplore_gym.core.coverage_tour import PrivilegedWorld, SensorModel
    from semexplore_gym.core.grid import GridGeometry
    from semexplore_gym.core.worlds.start import reachable_free_mask

    geo = GridGeometry.covering(*world.bounds_m, res_m, 0.5)
    reach = reachable_free_mask(world, geo, start[:2], radius_m, radius_m + 0.01)
    return PrivilegedWorld(
        world=world,
        geometry=geo,
        start_pose=start,
        radius_m=radius_m,
        clearance_m=radius_m + 0.01,
        reachable_mask=reach,
        sensor=SensorModel(360, range_m, 0.12),
        max_linear_speed_mps=0.22,
        coverage_goal=0.99,
    )


@pytest.fixture
def privileged_world():
    """``privileged_world(world, start, radius_m, range_m, res_m)``: a ``PrivilegedWorld`` of a
    test world, as the privileged env hands it out."""
    return _privileged_world


def _write_ros_map(
    directory: Path, pixels: np.ndarray, name: str, origin_m: tuple[float, float] = (0.0, 0.0)
) -> str:
    """A ROS map_server pair (``name.pgm`` at 0.05 m per pixel, ``name.yaml``) in ``directory``;
    the yaml's path. Pixels: 0 wall, 254 free (rows from the image's top)."""
    from PIL import Image

    Image.fromarray(np.asarray(pixels, dtype=np.uint8)).save(directory / f"{name}.pgm")
    path = directory / f"{name}.yaml"
    path.write_text(
        f"image: {name}.pgm\nresolution: 0.05\norigin: [{origin_m[0]}, {origin_m[1]}, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return str(path)


@pytest.fixture
def ros_map_file(tmp_path: Path):
    """``ros_map_file(pixels, name, origin_m=(0, 0))``: write a small ROS map in ``tmp_path``
    and return its yaml's path (a world spelling the env takes)."""
    return lambda pixels, name, origin_m=(0.0, 0.0): _write_ros_map(
        tmp_path, pixels, name, origin_m
    )


def _short_mission(world: str, policy, seed: int, max_time_s: float):
    """One mission from a random start: ``policy`` is a spec (``make_policy``) or a Policy;
    returns ``(MissionResult, policy)``."""
    import gymnasium as gym
    from semexplore_gym.policies.registry import make_policy

    import semexplore_gym  # noqa: F401  (registers the env)
    from semexplore_gym.evaluation.rollout import map_observation_for, run_mission

    policy = make_policy(policy) if isinstance(policy, str) else policy
    env = gym.make(
        "SemanticExplore-v0",
        world=world,
        overrides=[f"episode.max_time_s={max_time_s}", "episode.random_start=true"],
        **map_observation_for(policy),
    )
    return run_mission(env, policy, seed=seed, ignore_terminated=True), policy


@pytest.fixture
def short_mission():
    """``short_mission(world, policy, seed, max_time_s)``: one mission from the seed's random
    start with the policy's own map observation; ``(result, policy)``."""
    return _short_mission


def _plan_context(grid, geometry, params, pose, candidates=(), current=None):
    """A plan source's context on ``grid`` (the robot at ``pose``, the planners' clearance
    0.155 m, fresh counters and goal memory, ``choose_goal`` taking the first candidate)."""
    from semexplore_gym.policies.expert.counters import ExpertCounters
    from semexplore_gym.policies.expert.goal_memory import GoalMemory
    from semexplore_gym.policies.expert.plan_context import PlanContext

    counts = ExpertCounters()
    memory = GoalMemory(params.goal_memory, counts, lambda *_: None)
    memory.reset(geometry, params.goal_memory)
    return PlanContext(
        grid=grid,
        pose=pose,
        geometry=geometry,
        params=params,
        clearance_m=0.155,
        robot_radius_m=0.105,
        candidates=list(candidates),
        current=current,
        memory=memory,
        counts=counts,
        choose_goal=lambda cands: cands[0],
        log=lambda *_: None,
    )


@pytest.fixture
def plan_context():
    """``plan_context(grid, geometry, params, pose, candidates=(), current=None)``: a
    :class:`PlanContext` for calling one plan source's ``propose`` by hand."""
    return _plan_context


def _bound_problem(spec: str, seed: int, factor: int, hop_cells: int):
    """``(facts, allowed, problem)``: the privileged facts of ``spec`` after a random-start
    ``reset(seed=seed)``, the allowed map cells, and the lower bound's fixed parts on
    ``factor``-cell distance cells with ``hop_cells`` hops (the env's LiDAR, no mount offset)."""
    from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY
    from semexplore_gym.core.coverage_tour.lower_bound import (
        _Problem,
        allowed_cells,
        coarse_moves,
        merge_walls,
    )
    from semexplore_gym.envs.semantic_explore import SemanticExploreEnv

    env = SemanticExploreEnv(spec, privileged=True, overrides=["episode.random_start=true"])
    try:
        facts = env.reset(seed=seed)[1][PRIVILEGED_INFO_KEY]
    finally:
        env.close()
    allowed, _ = allowed_cells(facts, 0.01)
    problem = _Problem(
        allowed=allowed,
        coarse=coarse_moves(allowed, factor),
        factor=factor,
        walls=merge_walls(facts.world.segments_m),
        geometry=facts.geometry,
        reach_m=facts.sensor.max_range_m + 1e-6,
        widen_m=1e-6,
        hop_cells=hop_cells,
        split_depth=3,
    )
    return facts, allowed, problem


@pytest.fixture
def bound_problem():
    """``bound_problem(spec, seed, factor, hop_cells)``: ``(facts, allowed, problem)`` of the
    certified lower bound's proof steps on a world spelling (see :func:`_bound_problem`)."""
    return _bound_problem
