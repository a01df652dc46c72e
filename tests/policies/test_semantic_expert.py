"""The semantic expert: unit behaviour on hand-built maps, then whole missions in the env."""

from __future__ import annotations

import math

import numpy as np
import pytest
from semexplore_gym.policies.expert.expert import (
    SemanticExpertParams,
    SemanticExpertPolicy,
    area_type_raster,
)
from semexplore_gym.policies.expert.recipes import PAPER_METHOD, SEMANTIC_V3
from semexplore_gym.policies.registry import make_policy

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.topometric.types import (
    Area,
    AreaType,
    Frontier,
    GraphEdge,
    Opening,
    TopometricMap,
)

RES = 0.05
GEOM = GridGeometry(RES, 0.0, 0.0, 40, 100)  # 5 m x 2 m


def corridor_grid(known_until_m: float = 3.0, closed: bool = False) -> np.ndarray:
    """A corridor along x (y 0.5..1.5 m free, walls beside), known up to ``known_until_m``."""
    g = np.full(GEOM.shape, UNKNOWN, dtype=np.uint8)
    cols = int(known_until_m / RES)
    g[:, :cols] = OCCUPIED
    g[10:30, 1:cols] = FREE
    if closed:
        g[:, cols - 1] = OCCUPIED
    return g


def corridor_tmap(grid: np.ndarray, *_: object, **__: object) -> TopometricMap:
    """One frontier pathway: opening 0 at the left end, frontier opening 1 at x = 2.95 m."""
    ids = np.where(grid == FREE, 0, -1).astype(np.int32)
    path = np.array([[0.1, 1.0], [2.95, 1.0]])
    openings = [
        Opening(0, np.array([[0.1, 0.5], [0.1, 1.5]]), (0.1, 1.0), 1.0, (0, -1), False),
        Opening(1, np.array([[2.95, 0.5], [2.95, 1.5]]), (2.95, 1.0), 1.0, (0, -1), True),
    ]
    area = Area(
        0,
        AreaType.FRONTIER_PATHWAY,
        (1.5, 1.0),
        (0, 1),
        {0: path, 1: path[::-1].copy()},
        int((ids == 0).sum()),
    )
    frontier = Frontier(0, 1, (2.95, 1.0), 1.0, None, 2.85)
    return TopometricMap(
        GEOM,
        ids,
        {0: area},
        openings,
        [frontier],
        [GraphEdge(0, 1, 0, 2.85, path)],
        float("nan"),
        0.155,
    )


def empty_tmap(grid: np.ndarray, *_: object, **__: object) -> TopometricMap:
    return TopometricMap(
        GEOM, np.full(grid.shape, -1, np.int32), {}, [], [], [], float("nan"), 0.155
    )


INFO = {
    "map_geometry": GEOM.to_dict(),
    "robot": {"radius_m": 0.105, "max_linear_speed_mps": 0.22, "max_angular_speed_radps": 2.84},
    "lidar": {
        "n_beams": 360,
        "min_range_m": 0.12,
        "max_range_m": 3.5,
        "angle_increment_rad": 2 * math.pi / 360,
    },
    "dt_s": 0.2,
}


def obs_at(
    grid: np.ndarray, x: float, y: float, yaw: float, scan: np.ndarray | None = None
) -> dict[str, np.ndarray]:
    return {
        "map": grid,
        "pose": np.array([x, y, yaw], dtype=np.float32),
        "scan": scan if scan is not None else np.full(360, 3.5, dtype=np.float32),
    }


def test_semantic_plan_drives_towards_the_frontier_and_reports_stats():
    grid = corridor_grid()
    # along the map's path (the grid's route instead: test_expert_semantic_grid_route.py)
    recipe = SEMANTIC_V3.with_semantic(grid_route=False)
    pol = SemanticExpertPolicy(segmenter=corridor_tmap, recipe=recipe)
    obs = obs_at(grid, 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)
    a = pol.act(obs, INFO)
    assert a.dtype == np.float32 and a.shape == (2,)
    assert a[0] == pytest.approx(1.0) and abs(a[1]) < 1e-6
    assert pol.mode == "semantic" and not pol.done
    assert pol.last_stats.replanned
    assert pol.last_stats.map_generation_ms > 0 and pol.last_stats.global_planning_ms > 0
    assert [c.goal_xy_m for c in pol.candidates] == [(2.95, 1.0)]
    # Within the replanning period the plan is only followed.
    pol.act(obs, INFO)
    assert not pol.last_stats.replanned and pol.last_stats.map_generation_ms == 0.0
    ov = pol.overlay()
    assert ov["area_types"].shape == GEOM.shape and ov["area_types"].dtype == np.int16
    assert set(np.unique(ov["area_types"])) == {-1, int(AreaType.FRONTIER_PATHWAY)}
    assert ov["goal_m"] == (2.95, 1.0) and ov["frontiers_m"] == [(2.95, 1.0)]
    np.testing.assert_allclose(ov["paths_m"][0][-1], (2.95, 1.0))


def test_goal_behind_the_robot_turns_it_round_first():
    grid = corridor_grid()
    pol = SemanticExpertPolicy(segmenter=corridor_tmap)
    obs = obs_at(grid, 0.5, 1.0, math.pi)
    pol.reset(obs, INFO, seed=0)
    a = pol.act(obs, INFO)
    assert a[0] == 0.0 and abs(a[1]) == pytest.approx(1.0)


def test_fallback_without_frontier_pathways_then_stop_when_nothing_is_left():
    pol = SemanticExpertPolicy(segmenter=empty_tmap)
    grid = corridor_grid()
    obs = obs_at(grid, 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)
    a = pol.act(obs, INFO)
    assert pol.mode == "fallback" and a[0] > 0.5
    assert pol.overlay()["goal_m"][0] > 2.5  # the corridor's open end
    # A closed corridor has no frontier: the policy stops after the confirmations.
    closed = corridor_grid(closed=True)
    pol = SemanticExpertPolicy(SemanticExpertParams(stop_confirmations=2), segmenter=empty_tmap)
    obs = obs_at(closed, 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)
    a1 = pol.act(obs, INFO)
    assert not pol.done and np.all(a1 == 0)
    pol.act(obs, INFO)
    # The stop reason names the rule that ended the mission (#13).
    assert pol.done and pol.mode == "done"
    assert pol.stop_reason == "no frontier left (grid check: none reachable)"
    assert np.all(pol.act(obs, INFO) == 0)


def test_without_the_fallback_sources_the_mission_stops_with_algorithm_1():
    pol = SemanticExpertPolicy(
        SemanticExpertParams(stop_confirmations=1), segmenter=empty_tmap, recipe=PAPER_METHOD
    )
    obs = obs_at(corridor_grid(), 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)
    pol.act(obs, INFO)
    assert pol.done and pol.stop_reason == "no semantic frontier left"


def test_stuck_robot_backs_off_and_blacklists_its_goal():
    prm = SemanticExpertParams(
        stuck_timeout_s=2.0, backoff_duration_s=1.0, local_min_timeout_s=100.0
    )
    pol = SemanticExpertPolicy(prm, segmenter=corridor_tmap)
    grid = corridor_grid()
    obs = obs_at(grid, 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)
    modes = []
    actions = []
    for _ in range(200):  # the pose never changes: the robot is stuck
        actions.append(pol.act(obs, INFO))
        modes.append(pol.mode)
        if pol.done:
            break
    assert "recovery" in modes
    k = modes.index("recovery")
    assert k == pytest.approx(2.0 / 0.2, abs=1)
    assert actions[k][0] < 0  # backs off (nothing behind it in this scan)
    assert pol.counters["recoveries"] >= 1 and pol.counters["blacklisted"] >= 1
    # The goal is retried by other approaches (a grid route, another side) before it is
    # dropped (#13); then the fallback's frontier is the same place, also excluded.
    assert pol.counters["retries"] == prm.max_goal_attempts - 1
    assert pol.counters["recoveries"] == prm.max_goal_attempts
    assert pol.done and "1 failed 3 approaches" in pol.stop_reason


def test_commitment_keeps_the_current_goal_against_a_slightly_cheaper_one():
    from semexplore_gym.core.planning.graph_search import FrontierCandidate

    def cand(x: float, cost: float, area: int) -> FrontierCandidate:
        f = Frontier(area, area, (x, 1.0), 1.0, None, 1.0)
        return FrontierCandidate(
            f,
            (x, 1.0),
            np.array([[0.0, 1.0], [x, 1.0]]),
            (area,),
            x,
            0.0,
            1.0,
            0,
            0,
            2.0,
            cost,
            0.0,
            cost,
        )

    pol = SemanticExpertPolicy(SemanticExpertParams(switch_margin=0.5))
    from semexplore_gym.policies.expert.expert import Plan, PlanKind

    current = cand(3.0, 1.0, 7)
    pol._plan = Plan(PlanKind.SEMANTIC, current.goal_xy_m, current.path_m, current)
    other = cand(-2.0, 0.8, 8)
    moved = cand(3.4, 1.1, 7)  # the same frontier pathway, its frontier receded
    assert pol.choose_goal([other, moved]) is moved
    much_cheaper = cand(-2.0, 0.2, 8)
    assert pol.choose_goal([much_cheaper, moved]) is much_cheaper


def test_public_hooks_report_replans_and_force_one():
    class Recording(SemanticExpertPolicy):
        def __init__(self) -> None:
            super().__init__(segmenter=corridor_tmap)
            self.calls: list[tuple[str, object]] = []

        def on_replan_due(self, reason: str) -> None:
            self.calls.append(("due", reason))

        def on_replanned(self, source) -> None:  # type: ignore[no-untyped-def]
            self.calls.append(("replanned", source))

    pol = Recording()
    obs = obs_at(corridor_grid(), 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)
    assert pol.goal_xy_m is None and pol.plan_source is None
    pol.act(obs, INFO)
    assert pol.calls == [("due", "no_plan"), ("replanned", "semantic")]
    assert pol.goal_xy_m == (2.95, 1.0) and pol.plan_source == "semantic"
    pol.act(obs, INFO)
    assert not pol.last_stats.replanned and len(pol.calls) == 2
    pol.request_replan()
    pol.act(obs, INFO)
    assert pol.last_stats.replanned and pol.calls[2] == ("due", "period")
    cands = pol.frontier_candidates(obs)
    assert [c.goal_xy_m for c in cands] == [(2.95, 1.0)]


def test_reset_needs_the_env_facts_and_params_validate():
    pol = SemanticExpertPolicy(segmenter=empty_tmap)
    with pytest.raises(ValueError, match="map_geometry"):
        pol.reset(obs_at(corridor_grid(), 0.5, 1.0, 0.0), {"dt_s": 0.2}, seed=0)
    with pytest.raises(ValueError, match="replan_period_s"):
        SemanticExpertParams(replan_period_s=0.0)
    with pytest.raises(ValueError, match="prune_by"):
        SemanticExpertParams(prune_by="node")  # type: ignore[arg-type]


def test_registry_builds_the_expert_with_overrides():
    pol = make_policy(
        "semantic", **{"cost.w_v": 2.0, "potential_field": {"f_l": 1.2}, "replan_period_s": 2}
    )
    assert isinstance(pol, SemanticExpertPolicy)
    assert pol.params.cost.w_v == 2.0 and pol.params.cost.w_p == 0.2
    assert pol.params.potential_field.f_l == 1.2 and pol.params.replan_period_s == 2.0
    with pytest.raises(ValueError, match="cost.w_x"):
        make_policy("semantic", **{"cost.w_x": 1.0})
    with pytest.raises(ValueError, match="unknown policy"):
        make_policy("telepathy")
    rnd = make_policy("random")
    rnd.reset(obs_at(corridor_grid(), 0.5, 1.0, 0.0), INFO, seed=3)
    a = rnd.act({}, {})
    rnd.reset(obs_at(corridor_grid(), 0.5, 1.0, 0.0), INFO, seed=3)
    assert np.array_equal(a, rnd.act({}, {})) and np.all(np.abs(a) <= 1)


def test_area_type_raster_maps_ids_to_types():
    tm = corridor_tmap(corridor_grid())
    r = area_type_raster(tm)
    assert (r[tm.area_ids == 0] == int(AreaType.FRONTIER_PATHWAY)).all()
    assert (r[tm.area_ids < 0] == -1).all()


# --- whole missions in the env -------------------------------------------------------------------


def _mission(world: str, seed: int = 0, max_time_s: float = 1200.0):
    import gymnasium as gym

    import semexplore_gym  # noqa: F401
    from semexplore_gym.evaluation.rollout import run_mission

    env = gym.make("SemanticExplore-v0", world=world)
    try:
        # ignore_terminated: the env stops at 99 % coverage; the expert must stop by itself.
        return run_mission(
            env,
            SemanticExpertPolicy(),
            seed=seed,
            max_time_s=max_time_s,
            progress=False,
            ignore_terminated=True,
        )
    finally:
        env.close()


def _check_mission(res) -> None:
    assert res.self_stopped, (
        f"{res.world}: did not stop by itself ({res.stop_reason}, coverage {res.coverage:.3f})"
    )
    assert res.stop_reason.startswith("no frontier left")
    assert res.coverage >= 0.97, f"{res.world}: coverage {res.coverage:.3f}"
    assert res.collisions == 0, f"{res.world}: {res.collisions} collisions"
    assert res.mission_time_s < 1200.0


@pytest.mark.parametrize("world", ["maze1", "maze2"])
def test_expert_explores_the_paper_mazes(world):
    res = _mission(world)
    _check_mission(res)
    # The expert plans with the topometric map for most of the mission.
    assert res.policy_counters["semantic_plans"] > res.policy_counters["fallback_plans"]
    c = res.policy_counters
    assert 0 <= c["semantic_decisive"] <= c["scored_replans"] and c["scored_replans"] > 0


def test_semantic_decisive_counts_replans_where_the_metric_cost_alone_disagrees():
    from types import SimpleNamespace

    pol = SemanticExpertPolicy(segmenter=corridor_tmap)
    obs = obs_at(corridor_grid(), 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)

    def cands(*metric: float) -> list:
        return [SimpleNamespace(metric_cost=m) for m in metric]  # cheapest C first

    pol.counts.record_scored_replan(cands(1.0, 2.0))  # same choice
    pol.counts.record_scored_replan(cands(2.0, 1.0))  # the semantic gain overturned the metric
    pol.counts.record_scored_replan(cands(1.0, 1.0))  # a metric tie is no disagreement
    pol.counts.record_scored_replan([])  # nothing scored
    assert (pol.counters["scored_replans"], pol.counters["semantic_decisive"]) == (3, 1)
    pol.act(obs, INFO)  # a real replan with one candidate
    assert (pol.counters["scored_replans"], pol.counters["semantic_decisive"]) == (4, 1)


@pytest.mark.slow
@pytest.mark.parametrize(
    "world",
    [
        "maze:seed=1",
        "maze:seed=2",
        "maze:seed=3,braid=0.3",
        "office:seed=1,size_m=12",
        "office:seed=2,size_m=12",
        "office:seed=2",
        "cave:seed=1",
        "cave:seed=2",
        "cave:seed=3",
    ],
)
def test_expert_explores_procedural_worlds(world):
    _check_mission(_mission(world))


def test_expert_mission_is_deterministic():
    a = _mission("maze1", seed=4, max_time_s=60.0)
    b = _mission("maze1", seed=4, max_time_s=60.0)
    assert a.steps == 300
    np.testing.assert_array_equal(a.trajectory, b.trajectory)


# ---------------------------------------------------------------------- the plug-in points
def test_counters_keep_their_names_and_mission_metrics_follow_them():
    pol = SemanticExpertPolicy(segmenter=corridor_tmap)
    obs = obs_at(corridor_grid(), 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)
    pol.act(obs, INFO)
    names = list(pol.counters)
    assert names[:3] == ["replans", "segmentations", "semantic_plans"]
    assert names[-3:] == ["scored_replans", "semantic_decisive", "replan_no_plan"]
    assert len(names) == 25 and pol.counters["semantic_plans"] == 1
    assert pol.mission_metrics() == {"scored_replans": 1, "semantic_share": 0.0}
    pol.reset(obs, INFO, seed=0)
    assert pol.mission_metrics() == {"scored_replans": 0, "semantic_share": None}
    assert "replan_no_plan" not in pol.counters


def test_a_ranker_reorders_the_frontiers_before_goal_commitment():
    from semexplore_gym.core.planning.graph_search import FrontierCandidate

    def cand(x: float, cost: float) -> FrontierCandidate:
        f = Frontier(0, 0, (x, 1.0), 1.0, None, 1.0)
        path = np.array([[0.0, 1.0], [x, 1.0]])
        return FrontierCandidate(f, (x, 1.0), path, (0,), x, 0.0, 1.0, 0, 0, 2.0, cost, 0.0, cost)

    near, far = cand(1.0, 1.0), cand(4.0, 2.0)
    assert SemanticExpertPolicy().choose_goal([near, far]) is near
    farthest_first = SemanticExpertPolicy(ranker=lambda cs: sorted(cs, key=lambda c: -c.d_m))
    assert farthest_first.choose_goal([near, far]) is far


def test_plan_sources_are_an_ordered_list_that_can_take_a_new_source():
    from semexplore_gym.policies.expert.expert import (
        DEFAULT_PLAN_SOURCES,
        Plan,
        PlanKind,
        PlanSource,
        insert_plan_source,
    )

    names = [s.name for s in DEFAULT_PLAN_SOURCES]
    assert names == [
        "commanded",
        "retry",
        "view",
        "semantic",
        "committed_fallback",
        "nearest_fallback",
        "pocket_escape",
        "room_beyond_gap",
        "narrow_fallback",
        "look",
    ]

    class Stay(PlanSource):
        name = "stay"

        def propose(self, ctx):  # type: ignore[no-untyped-def]
            return Plan(PlanKind.FALLBACK, (1.0, 1.0), np.array([ctx.xy_m, (1.0, 1.0)]))

    sources = insert_plan_source(DEFAULT_PLAN_SOURCES, Stay(), before="semantic")
    assert [s.name for s in sources].index("stay") == 3
    with pytest.raises(ValueError, match="no plan source named"):
        insert_plan_source(DEFAULT_PLAN_SOURCES, Stay(), after="nope")
    pol = SemanticExpertPolicy(segmenter=corridor_tmap, plan_sources=sources)
    obs = obs_at(corridor_grid(), 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)
    pol.act(obs, INFO)
    assert pol.plan_source == "fallback" and pol.goal_xy_m == (1.0, 1.0)
    # Without it the expert plans as always.
    pol = SemanticExpertPolicy(segmenter=corridor_tmap)
    pol.reset(obs, INFO, seed=0)
    pol.act(obs, INFO)
    assert pol.plan_source == "semantic"


def test_drive_to_a_goal_then_choose_again():
    grid = corridor_grid()
    pol = SemanticExpertPolicy(segmenter=corridor_tmap)
    obs = obs_at(grid, 0.5, 1.0, 0.0)
    pol.reset(obs, INFO, seed=0)
    pol.drive_to((2.0, 1.2))
    a = pol.act(obs, INFO)
    assert pol.plan_source == "commanded" and pol.mode == "commanded" and a[0] > 0.5
    assert pol.goal_xy_m == (2.0, 1.2) and pol.commanded_goal_xy_m == (2.0, 1.2)
    # The goal lies in known space: it lasts until reached, then the expert chooses again.
    pol.request_replan()
    pol.act(obs_at(grid, 1.0, 1.0, 0.0), INFO)
    assert pol.plan_source == "commanded"
    pol.act(obs_at(grid, 2.0, 1.15, 0.0), INFO)
    assert pol.commanded_goal_xy_m is None and pol.plan_source == "semantic"
    assert any(e == "command_reached" for _t, e, _d in pol.events)
    # A goal inside a wall is unreachable: the command ends at once.
    pol.drive_to((2.0, 0.1))
    pol.act(obs_at(grid, 2.0, 1.15, 0.0), INFO)
    assert pol.commanded_goal_xy_m is None and pol.plan_source == "semantic"
    assert any(e == "command_unreachable" for _t, e, _d in pol.events)
