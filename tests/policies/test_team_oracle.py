"""The team oracle: privileged channel of the multi-robot env, and a short team mission."""

from __future__ import annotations

import pytest

pytest.importorskip("pettingzoo")
pytest.importorskip("elkai")
pytest.importorskip("ortools")

from semexplore_gym.policies.oracle import PrivilegedPolicyError  # noqa: E402
from semexplore_gym.policies.team import make_team_policy  # noqa: E402

from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY, PrivilegedWorld  # noqa: E402
from semexplore_gym.envs.multi_robot import make_multi  # noqa: E402

OVERRIDES = ["episode.coverage_goal=1.0", "team.end_on_coverage=false", "episode.random_start=true"]


def test_only_a_privileged_team_env_hands_out_the_true_world():
    env = make_multi(world="maze:seed=0,size_m=4", n_robots=2, overrides=OVERRIDES)
    obs, infos = env.reset(seed=0)
    assert all(PRIVILEGED_INFO_KEY not in info for info in infos.values())
    with pytest.raises(PrivilegedPolicyError, match="privileged=True"):
        make_team_policy("oracle").reset(obs, infos, seed=0)
    env = make_multi(world="maze:seed=0,size_m=4", n_robots=2, overrides=OVERRIDES, privileged=True)
    obs, infos = env.reset(seed=0)
    truths = [infos[a][PRIVILEGED_INFO_KEY] for a in env.possible_agents]
    assert all(isinstance(t, PrivilegedWorld) for t in truths)
    # Each agent's truth starts at its own start; the world and the coverage mask are shared.
    for agent, truth in zip(env.possible_agents, truths, strict=True):
        assert truth.start_pose[:2] == pytest.approx(tuple(obs[agent]["pose"][:2]), abs=1e-5)
    assert truths[0].reachable_mask is not truths[1].reachable_mask
    assert (truths[0].reachable_mask == truths[1].reachable_mask).all()


@pytest.mark.slow
def test_two_robots_split_the_tour_and_reach_the_goal_sooner_than_one():
    from semexplore_gym.evaluation.team_benchmark import run_team_mission
    from semexplore_gym.evaluation.team_bound import team_lower_bound_s

    results = {}
    for k in (1, 2):
        env = make_multi(
            world="maze:seed=1,size_m=6", n_robots=k, overrides=OVERRIDES, privileged=True
        )
        team = make_team_policy("oracle")
        res = run_team_mission(env, team, seed=0, max_time_s=900)
        assert team.done and team.stop_reason == "coverage_goal"
        assert res.T99_s is not None and res.coverage >= 0.99
        assert res.T99_s >= team_lower_bound_s(env, ("maze:seed=1,size_m=6", 0))
        metrics = team.mission_metrics()
        assert metrics["oracle_makespan_m"] <= metrics["oracle_tour_m"] + 1e-9
        results[k] = (res, metrics)
    (one, m1), (two, m2) = results[1], results[2]
    assert m2["oracle_makespan_m"] < m1["oracle_makespan_m"]
    assert min(two.path_per_robot_m) > 1.0  # both robots drove
    assert two.T99_s < one.T99_s


def test_more_robots_than_viewpoints_is_one_clear_line(capsys: pytest.CaptureFixture[str]):
    from semexplore_gym.cli import main

    argv = ["explore", "--world", "maze:seed=3,size_m=2", "--robots", "8", "--policy", "oracle"]
    assert main([*argv, "--max-time-s", "60"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("8 robots, but the coverage tour of this world has 1")
    assert "Traceback" not in err and len(err.splitlines()) == 1


def test_team_members_drive_the_least_cost_path_whatever_drive_planned_legs_says():
    """A member's route is re-solved on distances alone: no leg of it was counted, so the
    one-robot oracle's ``drive_planned_legs`` leaves a team mission as it was."""
    from semexplore_gym.evaluation.team_benchmark import run_team_mission

    runs = []
    for flag in ("true", "false"):
        env = make_multi(
            world="maze:seed=1,size_m=5", n_robots=2, overrides=OVERRIDES, privileged=True
        )
        team = make_team_policy(f"oracle[member.drive_planned_legs={flag}]")
        res = run_team_mission(env, team, seed=0, max_time_s=600)
        assert team.done and res.T99_s is not None
        runs.append((res.T99_s, res.mission_time_s, tuple(res.path_per_robot_m)))
    assert runs[0] == runs[1]
