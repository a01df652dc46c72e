"""run_mission: the mission loop, its metrics and the GIF."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.base import Policy, StepStats
from semexplore_gym.policies.random_policy import RandomPolicy

import semexplore_gym  # noqa: F401
from semexplore_gym.evaluation.rollout import STAGES, GifOptions, run_mission, time_to_coverage


class StopAfter(Policy):
    """Drives straight and declares the mission over after ``n`` actions."""

    name = "stop_after"

    def __init__(self, n: int) -> None:
        super().__init__()
        self.n = n
        self.calls = 0

    def act(self, obs, info):
        self.calls += 1
        self.last_stats = StepStats(
            map_generation_ms=1.0 if self.calls % 2 else 0.0, replanned=bool(self.calls % 2)
        )
        if self.calls > self.n:
            self.done = True
            self.stop_reason = "enough"
        return np.array([0.2, 0.0], dtype=np.float32)


@pytest.fixture(scope="module")
def env():
    e = gym.make("SemanticExplore-v0", world="maze1")
    yield e
    e.close()


def test_mission_ends_when_the_policy_is_done(env):
    pol = StopAfter(5)
    res = run_mission(env, pol, seed=0, max_time_s=100.0, progress=False)
    assert res.self_stopped and res.stop_reason == "enough"
    assert res.steps == 5 and res.mission_time_s == pytest.approx(1.0)
    assert len(res.coverage_trace) == 6 and res.trajectory.shape == (6, 3)
    assert res.coverage_trace[-1][1] == pytest.approx(res.coverage)
    assert res.n_replans == 3 and res.mean_map_generation_ms == pytest.approx(1.0)
    assert set(res.stage_time_s) == set(STAGES) and res.stage_time_s["env_step"] > 0
    assert res.path_length_m == pytest.approx(5 * 0.2 * 0.22 * 0.2, rel=0.05)
    s = res.summary()
    assert s["self_stopped"] is True and s["collisions"] == 0 and "T90_s" in s


def test_max_time_and_random_policy_determinism(env):
    a = run_mission(env, RandomPolicy(), seed=3, max_time_s=4.0, progress=False)
    b = run_mission(env, RandomPolicy(), seed=3, max_time_s=4.0, progress=False)
    assert not a.self_stopped and a.truncated and a.stop_reason.startswith("max_time_s")
    assert a.steps == 20 and a.mission_time_s == pytest.approx(4.0)
    np.testing.assert_array_equal(a.trajectory, b.trajectory)
    with pytest.raises(ValueError, match="max_time_s"):
        run_mission(env, RandomPolicy(), seed=0, max_time_s=0.0, progress=False)
    with pytest.raises(ValueError, match="rgb_array"):
        run_mission(
            env, RandomPolicy(), seed=0, max_time_s=1.0, progress=False, gif=GifOptions("x.gif")
        )


def test_on_step_and_gif(tmp_path):
    e = gym.make("SemanticExplore-v0", world="maze1", render_mode="rgb_array")
    seen = []
    out = tmp_path / "m.gif"
    res = run_mission(
        e,
        StopAfter(10),
        seed=0,
        max_time_s=100.0,
        progress=False,
        on_step=lambda i, *_: seen.append(i),
        gif=GifOptions(out, every_s=0.6),
    )
    e.close()
    assert seen == list(range(1, 11))
    from PIL import Image

    with Image.open(out) as im:
        # first frame, every 0.6 s of 2 s (3 frames), and the final frame
        assert im.n_frames == 5
    assert res.stage_time_s["render"] > 0


def test_time_to_coverage():
    trace = [(0.0, 0.1, 1.0), (1.0, 0.5, 2.0), (2.0, 0.95, 3.0)]
    assert time_to_coverage(trace, 0.9) == 2.0
    assert time_to_coverage(trace, 0.99) is None
    assert time_to_coverage(trace, 0.1) == 0.0 and not math.isnan(time_to_coverage(trace, 0.5))


def test_gif_frames_stream_to_the_file_with_bounded_memory(tmp_path):
    """A long mission's GIF must not hold every frame: memory stays at about one frame."""
    import tracemalloc

    from PIL import Image

    from semexplore_gym.evaluation.rollout import GifStreamWriter

    rng = np.random.default_rng(0)
    frame = (rng.random((240, 320, 3)) * 255).astype(np.uint8)  # 230 kB

    def peak(n: int) -> int:
        writer = GifStreamWriter(tmp_path / f"{n}.gif", fps=5)
        tracemalloc.start()
        for i in range(n):
            writer.append(np.roll(frame, i, axis=1))
        writer.close()
        _, top = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        return top

    small, large = peak(5), peak(60)
    assert large < 1.5 * small + frame.nbytes  # no growth with the number of frames
    assert large < 8 * frame.nbytes  # a few frames' worth at most, not 60
    with Image.open(tmp_path / "60.gif") as im:
        assert im.n_frames == 60 and im.info["loop"] == 0 and im.info["duration"] == 200
        im.seek(7)
        err = np.abs(np.asarray(im.convert("RGB")).astype(int) - np.roll(frame, 7, axis=1))
        assert err.mean() < 25  # an adaptive 128-colour palette of noise
    assert not (tmp_path / "60.gif.part").exists()


def test_explore_gif_every_0_2_s_through_the_cli(tmp_path, capsys):
    from PIL import Image

    from semexplore_gym.cli import main

    out = tmp_path / "sub" / "m.gif"
    argv = ["explore", "--world", "maze1", "--policy", "random", "--max-time-s", "3"]
    assert main([*argv, "--gif", str(out), "--gif-every-s", "0.2"]) == 0
    with Image.open(out) as im:
        assert im.n_frames == 17  # t = 0, 0.2, ..., 3.0 and the final frame


class CountingStop(StopAfter):
    """Reports its own figures for benchmark rows through ``mission_metrics``."""

    def mission_metrics(self):
        return {"scored_replans": self.calls, "semantic_share": 0.25, "other": "x"}


def test_policy_columns_come_from_mission_metrics(env):
    from semexplore_gym.evaluation.harness import Task, mission_row

    res = run_mission(env, CountingStop(3), seed=0, max_time_s=10.0, progress=False)
    assert res.policy_metrics == {"scored_replans": 4, "semantic_share": 0.25, "other": "x"}
    row = mission_row(Task("maze1", "counting", 0), res).to_dict()
    assert row["scored_replans"] == 4 and row["semantic_share"] == 0.25 and "other" not in row
    plain = run_mission(env, StopAfter(3), seed=0, max_time_s=10.0, progress=False)
    assert plain.policy_metrics == {}
    row = mission_row(Task("maze1", "plain", 0), plain).to_dict()
    assert row["scored_replans"] is None and row["semantic_share"] is None


def test_the_progress_bar_ends_full_when_the_mission_ends(env, capsys):
    # The policy stops after 3 actions (0.6 s) of a 100 s limit: the bar ends at 100 %, not 1 %.
    res = run_mission(env, StopAfter(3), seed=0, max_time_s=100.0, progress=True)
    assert res.mission_time_s < 1.0
    drawings = [s for s in capsys.readouterr().err.split("\r") if s.strip()]
    assert "100%" in drawings[-1], drawings
