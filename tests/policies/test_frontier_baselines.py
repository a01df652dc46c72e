"""Frontier baselines: goal selection on hand-built maps, and missions in the real env."""

from __future__ import annotations

import math

import numpy as np
import pytest
from semexplore_gym.policies.base import Policy
from semexplore_gym.policies.frontier_baselines import (
    FrontierExplorationParams,
    FrontierExplorationPolicy,
    NearestFrontierPolicy,
)
from semexplore_gym.policies.navigation import NavStatus
from semexplore_gym.policies.registry import make_policy

from semexplore_gym.config import ConfigError
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

RES_M = 0.05


def _corridor_room() -> tuple[np.ndarray, GridGeometry]:
    """A 3 m x 1 m room: a 2-cell slit to unknown space on the left, a 0.6 m doorway on the right."""
    grid = np.full((41, 90), UNKNOWN, dtype=np.uint8)
    grid[9:32, 9:72] = OCCUPIED
    grid[10:31, 10:71] = FREE
    grid[19:21, 9] = FREE  # the slit: far too narrow for the robot
    grid[14:26, 71] = FREE  # the doorway
    return grid, GridGeometry(RES_M, 0.0, 0.0, *grid.shape)


def _obs_info(grid: np.ndarray, geo: GridGeometry, pose: tuple[float, float, float]):
    obs = {
        "map": grid,
        "pose": np.asarray(pose, dtype=np.float32),
        "scan": np.full(360, 3.5, dtype=np.float32),  # no returns within range
    }
    # Only the static facts a policy may read.
    info = {
        "map_geometry": geo.to_dict(),
        "robot": {"radius_m": 0.105, "max_linear_speed_mps": 0.22, "max_angular_speed_radps": 2.84},
        "lidar": {
            "n_beams": 360,
            "min_range_m": 0.12,
            "max_range_m": 3.5,
            "angle_increment_rad": math.radians(1),
        },
        "dt_s": 0.2,
    }
    return obs, info


ROBOT = (0.725, 1.025, 0.0)  # in the room, 0.3 m from the slit


def _first_goal(policy: Policy) -> tuple[float, float]:
    grid, geo = _corridor_room()
    obs, info = _obs_info(grid, geo, ROBOT)
    policy.reset(obs, info, seed=0)
    action = policy.act(obs, info)
    assert action.shape == (2,) and action.dtype == np.float32
    assert (np.abs(action) <= 1.0).all()
    assert policy.nav is not None and policy.nav.goal_xy_m is not None
    return policy.nav.goal_xy_m


def test_fe_commits_to_the_nearest_frontier_even_if_unreachable() -> None:
    goal = _first_goal(FrontierExplorationPolicy(search_on_costmap=False))
    assert goal[0] < 0.5  # the slit on the left (x = 0.45 m), which the robot cannot pass


def test_fe_with_reachability_check_picks_the_doorway() -> None:
    goal = _first_goal(FrontierExplorationPolicy(search_on_costmap=False, check_reachability=True))
    assert goal[0] > 3.5  # the doorway on the right


def test_fe_on_its_costmap_does_not_see_the_slit() -> None:
    # FE searches its inflated explore costmap: the slit is inside the inflation, so hidden.
    policy = FrontierExplorationPolicy()
    goal = _first_goal(policy)
    assert goal[0] > 3.5
    assert len(policy.frontiers) == 1


def test_nearest_frontier_uses_path_length() -> None:
    goal = _first_goal(NearestFrontierPolicy())
    assert goal[0] > 3.4  # the slit is nearer in a straight line but not reachable


def test_travel_points() -> None:
    grid, geo = _corridor_room()
    obs, info = _obs_info(grid, geo, ROBOT)
    goals = {}
    for tp in ("closest", "middle", "centroid"):
        p = FrontierExplorationPolicy(travel_point=tp)
        p.reset(obs, info)
        p.act(obs, info)
        goals[tp] = p.nav.goal_xy_m
    # The doorway frontier is the column x = 3.625 (col 72), rows 14-25 less the inflated ends.
    for tp in ("closest", "middle"):
        assert goals[tp][0] == pytest.approx(3.625)
    assert goals["centroid"][0] == pytest.approx(3.625)
    assert goals["centroid"][1] == pytest.approx(1.0, abs=0.03)  # doorway centre y = 1.0
    # "middle" (FE: the Euclidean-nearest cell) is the one nearest to the robot's y = 1.025.
    assert abs(goals["middle"][1] - 1.025) <= 0.05


def test_reachability_check_drops_a_goal_that_turns_out_to_be_a_wall() -> None:
    grid, geo = _corridor_room()
    obs, info = _obs_info(grid, geo, ROBOT)
    for check, expect_abort in ((True, True), (False, False)):
        p = FrontierExplorationPolicy(check_reachability=check)
        p.reset(obs, info)
        p.act(obs, info)
        gx, gy = p.nav.goal_xy_m
        r, c = geo.world_to_grid(gx, gy)
        walled = grid.copy()
        walled[int(r) - 1 : int(r) + 2, int(c)] = OCCUPIED  # the goal is mapped as a wall
        obs2, _ = _obs_info(walled, geo, ROBOT)
        p.act(obs2, info)
        assert (p.nav.status == NavStatus.ABORTED) == expect_abort
        if expect_abort:
            p.act(obs2, info)  # next step: blacklisted, another goal or none
            assert p.counters["blacklisted"] == 1


def test_no_frontier_stops_after_retries() -> None:
    grid = np.full((30, 30), OCCUPIED, dtype=np.uint8)
    grid[5:25, 5:25] = FREE
    geo = GridGeometry(RES_M, 0.0, 0.0, *grid.shape)
    obs, info = _obs_info(grid, geo, (0.75, 0.75, 0.0))
    for policy in (FrontierExplorationPolicy(), NearestFrontierPolicy()):
        policy.reset(obs, info)
        steps = 0
        while not policy.done and steps < 20:
            a = policy.act(obs, info)
            assert (a == 0).all()
            steps += 1
        assert policy.done
        assert "no frontiers" in policy.stop_reason
        assert steps == policy.params.no_frontier_retries + 1


def test_params_validation_and_registry() -> None:
    with pytest.raises(ValueError, match="travel_point"):
        FrontierExplorationParams(travel_point="random")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="selection"):
        FrontierExplorationPolicy(selection="utility")
    p = make_policy(
        "frontier", check_reachability=True, **{"navigation.dwa.max_linear_speed_mps": 0.15}
    )
    assert isinstance(p, FrontierExplorationPolicy)
    assert p.params.check_reachability and p.params.navigation.dwa.max_linear_speed_mps == 0.15
    assert isinstance(make_policy("nearest"), NearestFrontierPolicy)
    with pytest.raises(ConfigError, match="bogus"):
        make_policy("nearest", bogus=1)
    with pytest.raises(ValueError, match="reset"):
        NearestFrontierPolicy().reset({}, {})


# ---------------------------------------------------------------- missions in the real env

gym = pytest.importorskip("gymnasium")


def _make_env(world: str, **config):
    import semexplore_gym  # noqa: F401  (registers the env)

    return gym.make("SemanticExplore-v0", world=world, config=config or None)


STATIC_INFO = ("map_geometry", "robot", "lidar", "dt_s")


def test_fe_updates_goals_at_2_hz_by_default_and_0_hz_on_request() -> None:
    # 2 Hz is what FE's launch files set; 0 Hz (the explore_server default) waits for each goal.
    assert FrontierExplorationParams().frequency_hz == 2.0
    assert make_policy("frontier", frequency_hz=0).params.frequency_hz == 0.0
    # FE's navigator fails a goal that turned out to be a wall, as ROS's DWA does.
    assert FrontierExplorationParams().navigation.local_goal_check


@pytest.mark.parametrize(
    ("spec", "overrides"),
    [("frontier", {}), ("frontier", {"frequency_hz": 0.0}), ("nearest", {})],
    ids=["frontier-2hz", "frontier-0hz", "nearest"],
)
def test_short_mission_on_maze1_makes_progress(spec: str, overrides: dict) -> None:
    env = _make_env("maze1")
    policy = make_policy(spec, **overrides)
    obs, info = env.reset(seed=0)
    start_cov = info["coverage"]
    policy.reset(obs, {k: info[k] for k in STATIC_INFO}, seed=0)
    mapgen, glob = [], []
    for _ in range(300):  # 60 s
        action = policy.act(obs, {k: info[k] for k in STATIC_INFO})
        assert action.shape == (2,) and (np.abs(action) <= 1.0).all()
        mapgen.append(policy.last_stats.map_generation_ms)
        glob.append(policy.last_stats.global_planning_ms)
        obs, _, terminated, truncated, info = env.step(action)
        if terminated or truncated or policy.done:
            break
    env.close()
    assert info["coverage"] > start_cov + 0.1  # from 0.10 to over 0.20 in 60 s
    assert info["collisions"] == 0
    assert max(mapgen) > 0.0 and max(glob) > 0.0
    assert policy.counters["nav_plans"] >= 1  # the navigator's counts travel with the policy's
    ov = policy.overlay()
    assert isinstance(ov["frontiers_m"], list) and isinstance(ov["paths_m"], list)
    assert all(np.asarray(p).ndim == 2 and np.asarray(p).shape[1] == 2 for p in ov["paths_m"])


@pytest.mark.parametrize(
    ("spec", "overrides", "min_coverage"),
    [
        # At 2 Hz FE here aborts three goals and its blacklist (cleared only when a goal is
        # reached) hides the last frontiers: it stops at 0.92, as FE can.
        ("frontier", {}, 0.9),
        ("frontier", {"frequency_hz": 0.0}, 0.95),
        ("nearest", {}, 0.95),
    ],
    ids=["frontier-2hz", "frontier-0hz", "nearest"],
)
def test_full_mission_on_a_small_maze_self_stops_with_high_coverage(
    spec: str, overrides: dict, min_coverage: float
) -> None:
    # coverage_goal 1.0 so that the env does not end the mission first; the loop keeps going
    # after the env has terminated (full coverage) until the policy stops by itself.
    env = _make_env("maze:size_m=4,seed=1", episode={"coverage_goal": 1.0, "max_time_s": 600.0})
    policy = make_policy(spec, **overrides)
    obs, info = env.reset(seed=0)
    policy.reset(obs, info, seed=0)
    for _ in range(1500):  # 300 s of simulated time
        action = policy.act(obs, info)
        if policy.done:
            break
        obs, _, _, truncated, info = env.step(action)
        if truncated:
            break
    env.close()
    assert policy.done, f"{spec} did not stop by itself (coverage {info['coverage']:.3f})"
    assert info["coverage"] >= min_coverage
    assert policy.stop_reason
