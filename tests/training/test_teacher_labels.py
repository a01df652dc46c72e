"""The oracle's labels for a student: right on a corridor whose answer is obvious, computed only
where training code asks for them, and never seen by a student policy."""

from __future__ import annotations

import ast
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.registry import make_policy

import semexplore_gym  # noqa: F401  (registers the env)
from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY, PrivilegedWorld
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.worlds.build import world_from_free_mask
from semexplore_gym.core.worlds.raster import rasterize_free
from semexplore_gym.evaluation.rollout import make_mission_env, map_observation_for, run_mission
from semexplore_gym.training.teacher_labels import NotPrivilegedError, OracleTeacher

pytest.importorskip("elkai")

RES = 0.05
RADIUS = 0.105
RANGE_M = 1.0
ROOT = Path(__file__).resolve().parents[2]


def _corridor(pw, start_x: float) -> PrivilegedWorld:
    """A 12 m x 0.6 m corridor along x, the robot at ``start_x``; LiDAR range 1 m."""
    h, w = int(round(0.6 / RES)), int(round(12.0 / RES))
    world = world_from_free_mask(
        "corridor", np.ones((h, w), dtype=bool), GridGeometry(RES, 0.0, 0.0, h, w)
    )
    return pw(world, (start_x, 0.3, 0.0), RADIUS, RANGE_M, RES)


def _mapped(facts: PrivilegedWorld, x0: float, x1: float) -> np.ndarray:
    """The live map after seeing x in [x0, x1]: free cells FREE, walls there OCCUPIED."""
    geo = facts.geometry
    grid = np.full(geo.shape, UNKNOWN, dtype=np.uint8)
    free = rasterize_free(facts.world, geo)
    xs, _ = geo.grid_to_world(np.zeros(geo.width), np.arange(geo.width))
    cols = (xs >= x0) & (xs <= x1)
    grid[:, cols] = np.where(free[:, cols], FREE, OCCUPIED)
    return grid


def test_corridor_short_end_first_and_costs_to_go(privileged_world) -> None:
    # Known: x in [3, 5]; the robot at x = 4. Left end 4 m away, right end 8 m away. Seeing an
    # end needs driving to within R of it: left first costs (4 - 1) + (11 - 1) = 13 m, right
    # first (11 - 4) + (11 - 1) = 17 m.
    facts = _corridor(privileged_world, 4.0)
    teacher = OracleTeacher(facts)
    obs = {"map": _mapped(facts, 3.0, 5.0), "pose": np.array([4.0, 0.3, 0.0])}
    labels = teacher.labels(obs)
    assert labels.n_frontiers == 2
    xs = [
        float(facts.geometry.grid_to_world(c[:, 0], c[:, 1])[0].mean())
        for c in labels.frontier_cells
    ]
    left, right = int(np.argmin(xs)), int(np.argmax(xs))
    assert labels.first == left
    assert labels.cost_to_go_m[left] == pytest.approx(13.0, abs=0.8)
    assert labels.cost_to_go_m[right] == pytest.approx(17.0, abs=0.8)
    assert labels.tour_length_m == pytest.approx(labels.cost_to_go_m[left], abs=0.3)
    visits = [
        int(f)
        for i, f in enumerate(labels.tour_frontiers)
        if i == 0 or f != labels.tour_frontiers[i - 1]
    ]
    assert visits == [left, right]  # all of the short end, then all of the long one
    assert labels.unseen_cells[right] > 2 * labels.unseen_cells[left] > 0
    # Mirrored (robot at x = 8, known [7, 9]): now the right end is the short one.
    facts = _corridor(privileged_world, 8.0)
    obs = {"map": _mapped(facts, 7.0, 9.0), "pose": np.array([8.0, 0.3, 0.0])}
    labels = OracleTeacher(facts).labels(obs)
    xs = [
        float(facts.geometry.grid_to_world(c[:, 0], c[:, 1])[0].mean())
        for c in labels.frontier_cells
    ]
    assert labels.first == int(np.argmax(xs))
    assert labels.cost_to_go_m[labels.first] < labels.cost_to_go_m[1 - labels.first] - 2.0


def test_a_frontier_that_owns_no_viewpoint_still_gets_a_cost(privileged_world) -> None:
    facts = _corridor(privileged_world, 4.0)
    teacher = OracleTeacher(facts)
    obs = {"map": _mapped(facts, 3.0, 5.0), "pose": np.array([4.0, 0.3, 0.0])}
    fake = np.array([[5, 80], [6, 80]])  # two cells mid-corridor, behind the robot's column
    labels = teacher.labels(obs, frontiers=[fake])
    assert labels.n_frontiers == 1 and np.isfinite(labels.cost_to_go_m[0])


def test_labels_need_the_privileged_world_of_a_privileged_env() -> None:
    env = gym.make("SemanticExplore-v0", world="maze:seed=0,size_m=4")
    _, info = env.reset(seed=0)
    with pytest.raises(NotPrivilegedError, match="privileged=True"):
        OracleTeacher.from_reset_info(info)
    env = gym.make("SemanticExplore-v0", world="maze:seed=0,size_m=4", privileged=True)
    obs, info = env.reset(seed=0)
    labels = OracleTeacher.from_reset_info(info).labels(obs)
    assert labels.n_frontiers >= 1 and 0 <= labels.first < labels.n_frontiers
    assert np.isfinite(labels.cost_to_go_m).all()
    assert labels.cost_to_go_m[labels.first] == labels.cost_to_go_m.min()
    assert labels.cost_to_go_m.min() <= labels.tour_length_m


class _Spy:
    """Wraps a student policy and records every key and value type it is handed."""

    def __init__(self, inner) -> None:
        self.inner = inner
        self.seen: set[str] = set()
        self.types: set[type] = set()

    def __getattr__(self, name):
        return getattr(self.inner, name)

    def _look(self, obs, info) -> None:
        self.seen |= set(obs) | set(info)
        self.types |= {type(v) for v in (*obs.values(), *info.values())}

    def reset(self, obs, info, seed=None) -> None:
        self._look(obs, info)
        self.inner.reset(obs, info, seed=seed)

    def act(self, obs, info):
        self._look(obs, info)
        return self.inner.act(obs, info)


@pytest.mark.parametrize("spec", ["nearest", "semantic"])
def test_a_student_policy_never_reads_the_true_world(spec: str) -> None:
    policy = make_policy(spec)
    assert not getattr(policy, "privileged", False)
    spy = _Spy(policy)
    env = make_mission_env("maze:seed=0,size_m=4", **map_observation_for(policy))
    run_mission(env, spy, seed=0, max_time_s=5.0)
    assert spy.seen and PRIVILEGED_INFO_KEY not in spy.seen
    assert PrivilegedWorld not in spy.types


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
        elif isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
    return out


ORACLE_FILES = ("policies/oracle.py", "policies/team/oracle_team.py")


def test_only_training_code_computes_labels_and_only_the_oracle_policy_reads_ground_truth() -> None:
    for path in sorted((ROOT / "semexplore_gym").rglob("*.py")) + sorted(
        (ROOT / "policies").rglob("*.py")
    ):
        rel = path.relative_to(ROOT).as_posix()
        text = path.read_text()
        if "teacher_labels" in " ".join(_imports(path)):
            assert rel.startswith("semexplore_gym/training/"), rel
        # the privileged policies: the oracle and the team oracle (which drives its tour)
        if rel.startswith("policies/") and rel not in ORACLE_FILES:
            assert "privileged_world" not in text and "PRIVILEGED_INFO_KEY" not in text, rel
            # the registry may ask whether the tour solver is installed; nothing more
            assert "PrivilegedWorld" not in text and "plan_coverage_tour" not in text, rel
