"""Training the frontier student on the oracle's labels (DAgger)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from semexplore_gym.policies.frontier_student import FrontierStudentModel, FrontierStudentPolicy

from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY
from semexplore_gym.core.features.frontier_option_features import OPTION_FEATURE_NAMES
from semexplore_gym.training.oracle_student import (
    EpisodeJob,
    LabelledDecisions,
    choice_regret,
    collect_episode,
    fit_student_model,
    load_oracle_student_config,
    training_worlds,
)

K = len(OPTION_FEATURE_NAMES)
PATH = OPTION_FEATURE_NAMES.index("path_m")
FAR = OPTION_FEATURE_NAMES.index("unknown_far")


def _synthetic(n: int, seed: int) -> LabelledDecisions:
    """Decisions whose best option is cheap by path and has much unknown beyond it."""
    rng = np.random.default_rng(seed)
    data = LabelledDecisions()
    for _ in range(n):
        f = rng.uniform(0.0, 1.0, size=(int(rng.integers(2, 7)), K))
        f[:, PATH] *= 10.0
        cost = f[:, PATH] + 12.0 * (1.0 - f[:, FAR]) + rng.normal(0.0, 0.3, len(f))
        data.features.append(f)
        data.cost_to_go_m.append(cost)
        data.choice.append(int(np.argmin(f[:, PATH])))
    return data


def test_the_fit_learns_what_the_teacher_prefers() -> None:
    train, test = _synthetic(400, 0), _synthetic(200, 1)
    model = FrontierStudentModel(**{k: tuple(v) for k, v in fit_student_model(train).items()})
    assert model.weights[FAR] > 0 and model.weights[PATH] < 0
    learned = choice_regret(test, model.scores)
    nearest = choice_regret(test, lambda f: -f[:, PATH])
    assert learned["n"] == nearest["n"] == 200
    assert learned["regret_m"] < 0.5 * nearest["regret_m"]
    assert learned["agree"] > nearest["agree"]
    with pytest.raises(ValueError, match="nothing to fit"):
        fit_student_model(LabelledDecisions([np.zeros((1, K))], [np.zeros(1)], [0]))


def test_labelled_decisions_round_trip(tmp_path) -> None:
    data = _synthetic(5, 2)
    data.save(tmp_path / "d.npz")
    back = LabelledDecisions.load(tmp_path / "d.npz")
    assert back.choice == data.choice
    for a, b in zip(
        back.features + back.cost_to_go_m, data.features + data.cost_to_go_m, strict=True
    ):
        np.testing.assert_array_equal(a, b)


def test_an_episode_labels_the_students_choices_and_the_student_sees_no_truth(monkeypatch) -> None:
    seen: list[set[str]] = []
    reset = FrontierStudentPolicy.reset

    def spy(self, obs, info, seed=None):
        seen.append(set(obs) | set(info))
        reset(self, obs, info, seed=seed)

    monkeypatch.setattr(FrontierStudentPolicy, "reset", spy)
    job = EpisodeJob("maze:seed=1,size_m=6", 3, 0, 0, {}, 0.0, 6.0, 300.0, 1)
    data, summary = collect_episode(job)
    assert seen and all(PRIVILEGED_INFO_KEY not in s for s in seen)
    assert len(data) == summary["labels"] >= 3 and summary["coverage"] > 0.5
    for f, c, ch in zip(data.features, data.cost_to_go_m, data.choice, strict=True):
        assert f.shape == (len(c), K) and len(c) >= 2 and np.isfinite(c).any()
        assert ch == int(np.argmin(f[:, PATH]))  # round 0's student is the nearest frontier
        assert not f[:, OPTION_FEATURE_NAMES.index("current")].any()  # a new goal each time
    # beta = 1: the teacher's choice is driven, a different mission on the same world
    _, teacher_driven = collect_episode(
        EpisodeJob(job.world, job.seed, 0, 0, {}, 1.0, 6.0, 300.0, 1)
    )
    assert teacher_driven["labels"] >= 3


def test_training_worlds_come_from_the_train_parts_only() -> None:
    from semexplore_gym.evaluation.splits import load_split

    cfg = load_oracle_student_config(None, ["splits=[mazes,offices]", "max_size_m=10"])
    worlds = training_worlds(cfg)
    train = set(load_split("mazes").parts["train"]) | set(load_split("offices").parts["train"])
    assert worlds and set(worlds) <= train
    with pytest.raises(ValueError, match="no training world"):
        training_worlds(load_oracle_student_config(None, ["max_size_m=1"]))
    with pytest.raises(Exception, match="rounds"):
        load_oracle_student_config(None, ["rounds=0"])


@pytest.mark.slow
def test_semexplore_train_resumes_and_the_student_runs_through_benchmark(tmp_path) -> None:
    from semexplore_gym.cli import main

    out = tmp_path / "student"
    argv = ["train", "--algo", "oracle_student", "--out", str(out), "--no-progress"]
    argv += ["--train-config", "configs/agents/oracle_student.yml"]
    for s in (
        "rounds=2",
        "episodes_per_round=2",
        "max_size_m=6",
        "splits=[mazes]",
        "max_time_s=150",
        "workers=1",
    ):
        argv += ["--train-set", s]
    assert main(argv) == 0
    for name in (
        "model.yaml",
        "model_round0.yaml",
        "model_round1.yaml",
        "config.yaml",
        "args.json",
        "metrics.json",
        "episodes.jsonl",
        "rounds.jsonl",
    ):
        assert (out / name).is_file(), name
    episodes = (out / "episodes.jsonl").read_text().splitlines()
    assert len(episodes) == 4
    model = (out / "model.yaml").read_text()
    assert main(argv) == 0  # resumed: every episode read back, none rerun
    assert (out / "episodes.jsonl").read_text().splitlines() == episodes
    assert (out / "model.yaml").read_text() == model
    rounds = [json.loads(x) for x in (out / "rounds.jsonl").read_text().splitlines()]
    assert [r["round"] for r in rounds] == [0, 1]
    bench = tmp_path / "bench"
    assert (
        main(
            [
                "benchmark",
                "--worlds",
                "maze:seed=*,size_m=4",
                "--runs",
                "1",
                "--max-time-s",
                "60",
                "--no-oracle",
                "--no-progress",
                "--out",
                str(bench),
                "--policies",
                f"nearest,frontier-student:{out / 'model.yaml'}",
            ]
        )
        == 0
    )
    rows = (bench / "runs.csv").read_text()
    assert "frontier-student" in rows


def test_training_without_the_tour_solver_fails_at_once_naming_the_extra(
    tmp_path, monkeypatch, capsys
) -> None:
    from semexplore_gym.cli import main
    from semexplore_gym.core.coverage_tour import tour

    def missing() -> None:
        raise ImportError(tour.SOLVER_HINT)

    monkeypatch.setattr(tour, "require_solver", missing)
    out = tmp_path / "run"
    assert main(["train", "--algo", "oracle_student", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "semexplore-gym[oracle]" in err and "Traceback" not in err
    assert not out.exists()
