"""The oracle explorer: privileged channel, determinism, and short missions on small worlds."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.oracle import (
    OracleParams,
    OraclePolicy,
    PrivilegedPolicyError,
    refuse_privileged,
)
from semexplore_gym.policies.registry import make_policy

import semexplore_gym  # noqa: F401  (registers the env)
from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY, PrivilegedWorld
from semexplore_gym.evaluation.rollout import map_observation_for

pytest.importorskip("elkai")


def _env(world: str, privileged: bool) -> gym.Env:
    return gym.make(
        "SemanticExplore-v0",
        world=world,
        overrides=["episode.max_time_s=900", "episode.random_start=true"],
        privileged=privileged,
    )


def test_only_a_privileged_env_hands_out_the_true_world():
    env = _env("maze:seed=0,size_m=4", privileged=False)
    _, info = env.reset(seed=0)
    assert PRIVILEGED_INFO_KEY not in info
    with pytest.raises(PrivilegedPolicyError, match="privileged"):
        make_policy("oracle").reset(*env.reset(seed=0), seed=0)
    env = _env("maze:seed=0,size_m=4", privileged=True)
    obs, info = env.reset(seed=0)
    facts = info[PRIVILEGED_INFO_KEY]
    assert isinstance(facts, PrivilegedWorld)
    assert PRIVILEGED_INFO_KEY not in obs
    # The env's own coverage denominator, read-only.
    assert facts.reachable_mask.sum() == env.unwrapped._n_reachable
    assert not facts.reachable_mask.flags.writeable
    _, _, _, _, step_info = env.step(np.zeros(2, dtype=np.float32))
    assert PRIVILEGED_INFO_KEY not in step_info


def test_runners_ask_for_the_channel_and_learning_code_refuses_the_oracle():
    oracle = make_policy("oracle")
    assert isinstance(oracle, OraclePolicy) and oracle.privileged
    assert map_observation_for(oracle)["privileged"] is True
    assert "privileged" not in map_observation_for(make_policy("semantic"))
    with pytest.raises(PrivilegedPolicyError, match="training expert"):
        refuse_privileged(oracle, "training expert")
    refuse_privileged(make_policy("nearest"), "training expert")  # honest: no error


def test_make_expert_refuses_the_oracle_unless_asked_by_name():
    from semexplore_gym.training.factories import make_expert, make_learner_env, make_raw_env
    from semexplore_gym.training.train_config import load_train_config

    world = ["env.world=maze:seed=0,size_m=4"]
    with pytest.raises(PrivilegedPolicyError, match="expert.privileged_teacher=true"):
        make_expert(load_train_config(None, [*world, "expert.spec=oracle"]))
    with pytest.raises(ValueError, match="expert.spec='semantic'"):
        make_expert(load_train_config(None, [*world, "expert.privileged_teacher=true"]))
    cfg = load_train_config(None, [*world, "expert.spec=oracle", "expert.privileged_teacher=true"])
    assert isinstance(make_expert(cfg), OraclePolicy)
    # The teacher's env hands out the true world; the learner's never does.
    _, info = make_raw_env(cfg).reset(seed=0)
    assert PRIVILEGED_INFO_KEY in info
    _, info = make_learner_env(cfg).reset(seed=0)
    assert PRIVILEGED_INFO_KEY not in info
    _, info = make_raw_env(load_train_config(None, world)).reset(seed=0)
    assert PRIVILEGED_INFO_KEY not in info


def test_the_oracle_labels_a_dataset_when_asked_and_the_student_sees_only_features(tmp_path):
    from semexplore_gym.training.factories import make_expert, make_learner_env, make_raw_env
    from semexplore_gym.training.imitation import record
    from semexplore_gym.training.train_config import load_train_config

    cfg = load_train_config(
        None,
        [
            "env.world=maze:seed=0,size_m=4",
            "expert.spec=oracle",
            "expert.privileged_teacher=true",
            "expert.episodes=1",
            "expert.max_steps=40",
            "expert.holdout_fraction=0",
        ],
    )
    data = record(
        cfg, make_raw_env(cfg), make_expert(cfg), tmp_path / "d.npz", lambda *a: None, False
    )
    assert len(data) == 40
    assert np.abs(data.actions).sum() > 0  # the oracle drives
    # What the student learns from: exactly its own env's egocentric features, nothing more.
    assert set(data.obs) == set(make_learner_env(cfg).observation_space.spaces)


@pytest.mark.parametrize(
    "world",
    [
        "maze:seed=3,size_m=5",
        "cave:seed=1,size_m=6",
        "office:seed=2,size_m=8",
        "forest:seed=2,size_m=6",
    ],
)
def test_an_oracle_mission_stops_itself_at_the_goal_no_later_than_the_expert(world, short_mission):
    res, _ = short_mission(world, "oracle", 1, 900)
    assert res.self_stopped and res.stop_reason == "coverage_goal"
    assert res.coverage >= 0.99 and res.collisions == 0
    expert, _ = short_mission(world, "semantic", 1, 900)
    assert res.t99_s is not None
    assert expert.t99_s is None or res.t99_s <= expert.t99_s


def test_the_oracle_is_deterministic_for_a_fixed_seed(short_mission):
    a, _ = short_mission("maze:seed=3,size_m=4", "oracle", 2, 900)
    b, _ = short_mission("maze:seed=3,size_m=4", "oracle", 2, 900)
    assert a.mission_time_s == b.mission_time_s
    assert np.array_equal(a.trajectory, b.trajectory)


def test_train_cli_refuses_the_oracle_in_one_line_and_names_the_opt_in(tmp_path, capsys):
    from semexplore_gym.cli import main

    argv = ["train", "--algo", "bc", "--train-config", "configs/agents/bc_maze.yml"]
    code = main([*argv, "--train-set", "expert.spec=oracle", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "privileged" in err[0] and "expert.privileged_teacher=true" in err[0]


def _two_rooms_and_a_gap(gap_px: int) -> np.ndarray:
    """Map pixels (0.05 m): two 1.5 m rooms joined by a corridor ``gap_px`` wide with a
    dog-leg (no line of sight from one room into the other)."""
    img = np.zeros((90, 40), dtype=np.uint8)  # black: walls
    img[5:35, 5:35] = 254  # room A (image top)
    img[55:85, 5:35] = 254  # room B
    img[35:45, 8 : 8 + gap_px] = 254  # down from room A ...
    img[40 : 40 + gap_px, 8:32] = 254  # ... across ...
    img[40:55, 32 - gap_px : 32] = 254  # ... and down into room B
    return img


def test_the_oracle_drives_through_a_passage_just_wider_than_the_robot(ros_map_file, short_mission):
    # 0.25 m: the robot is 0.21 m wide, the env counts the far room as reachable (clearance
    # radius + 0.01 m), and the potential field alone balances its two walls and stalls there.
    world = ros_map_file(_two_rooms_and_a_gap(gap_px=5), "gap")

    def mission(**params):
        return short_mission(world, OraclePolicy(OracleParams(**params)), 0, 400)

    res, policy = mission()
    assert res.self_stopped and res.stop_reason == "coverage_goal"
    assert res.coverage >= 0.99 and res.collisions == 0
    assert policy.counters["tight_steps"] > 0
    # Without the tight mode (the field everywhere) the robot never gets to the far room.
    stalled, _ = mission(tight_margin_m=0.0)
    assert not stalled.self_stopped and stalled.coverage < 0.8


def _ring_pixels() -> np.ndarray:
    """Map pixels (0.05 m): a 5 m square room round a 2.5 m block, symmetric about its middle
    row, so that the ways north and south of the block between the middles of the west and
    east corridors cost the same."""
    img = np.zeros((105, 105), dtype=np.uint8)
    img[2:103, 2:103] = 254
    img[27:78, 27:78] = 0
    return img


def test_the_oracle_drives_the_leg_its_tour_counted(ros_map_file):
    world = ros_map_file(_ring_pixels(), "ring")
    env = gym.make("SemanticExplore-v0", world=world, privileged=True)
    obs, info = env.reset(seed=0)
    policy = OraclePolicy()
    policy.reset(obs, info, seed=0)
    geo, legs = policy.geometry, policy.tour.legs
    west = tuple(int(v) for v in geo.world_to_grid(0.1 + 0.625, 2.625))
    east = tuple(int(v) for v in geo.world_to_grid(5.25 - 0.1 - 0.625, 2.625))
    leg = legs.path(west, east)
    side = int(np.sign(leg[:, 0].mean() - west[0]))
    assert side != 0
    # The robot stopped two cells short of the viewpoint, towards the other side of the block.
    x, y = geo.grid_to_world(west[0] - 2 * side, west[1])
    pose = (float(x), float(y), 0.0)

    def driven_side(path: np.ndarray) -> int:
        rows, _ = geo.world_to_grid(path[:, 0], path[:, 1])
        return int(np.sign(np.mean(rows) - west[0]))

    for drive_planned_legs, expected in ((True, side), (False, -side)):
        policy.params = OracleParams(drive_planned_legs=drive_planned_legs)
        policy._leg_from = west
        assert policy._set_goal(east, "tour", pose)
        assert driven_side(policy._path) == expected
        assert policy._leg_from is None  # a leg is driven once; replans start from the robot
    # Too far from where the leg starts (a timeout, a detour): the least-cost path from the robot.
    x, y = geo.grid_to_world(west[0] - 10 * side, west[1])
    assert policy._planned_leg(west, east, (float(x), float(y), 0.0)) is None
