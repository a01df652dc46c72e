"""World limits, physics / reward / odometry validation, CLI argument checks (issue #18)."""

from __future__ import annotations

import json
import struct
import time
import zlib

import numpy as np
import pytest

from semexplore_gym.cli import main
from semexplore_gym.config import ConfigError
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.build import (
    MAX_WALL_SEGMENTS,
    WorldTooLargeError,
    count_wall_runs,
    world_from_free_mask,
)
from semexplore_gym.envs.env_config import load_env_config

YAML = "image: m.png\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"


def _png(arr: np.ndarray) -> bytes:
    from io import BytesIO

    from PIL import Image

    buf = BytesIO()
    Image.fromarray(arr).save(buf, format="PNG")
    return buf.getvalue()


def _png_claiming(width: int, height: int) -> bytes:
    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
        )

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(b"\0\xff"))
        + chunk(b"IEND", b"")
    )


def _map(tmp_path, image: bytes, yaml: str = YAML):
    (tmp_path / "m.png").write_bytes(image)
    (tmp_path / "m.yaml").write_text(yaml)
    return str(tmp_path / "m.yaml")


# ---- item 2: world size and complexity


def test_noise_image_is_refused_before_building(tmp_path, capsys) -> None:
    noise = (np.random.default_rng(0).random((1200, 1200)) < 0.5).astype(np.uint8) * 254
    t0 = time.perf_counter()
    assert main(["show-world", _map(tmp_path, _png(noise)), "--out", str(tmp_path / "o.png")]) == 2
    err = capsys.readouterr().err
    assert time.perf_counter() - t0 < 20
    assert (
        "wall segments" in err and f"{MAX_WALL_SEGMENTS:,}" in err and "coarser resolution" in err
    )


def test_segment_count_estimate_bounds_the_real_count() -> None:
    rng = np.random.default_rng(1)
    free = rng.random((40, 50)) < 0.6
    w = world_from_free_mask("n", free, GridGeometry(0.05, 0, 0, 40, 50), min_free_cells=1)
    assert count_wall_runs(w.free_mask) >= w.n_segments


@pytest.mark.parametrize("size", [(20000, 20000), (100000, 100000), (1 << 30, 1)])
def test_decompression_bomb_is_refused_before_decoding(tmp_path, capsys, size) -> None:
    assert main(["segment", _map(tmp_path, _png_claiming(*size))]) == 2
    err = capsys.readouterr().err
    assert "m.png" in err and "pixel" in err.lower() and err.count("\n") == 1


@pytest.mark.parametrize(
    "side_m,fragment", [(1000, "cell limit"), (1e5, "cell limit"), (1e6, "beyond")]
)
def test_huge_houseexpo_plan_is_refused_at_once(tmp_path, capsys, side_m, fragment) -> None:
    p = tmp_path / "h.json"
    p.write_text(json.dumps({"verts": [[0, 0], [side_m, 0], [side_m, side_m], [0, side_m]]}))
    t0 = time.perf_counter()
    assert main(["show-world", str(p), "--out", str(tmp_path / "o.png")]) == 2
    assert time.perf_counter() - t0 < 5
    err = capsys.readouterr().err
    assert fragment in err and "h.json" in err


def test_world_too_large_error_says_how_to_proceed() -> None:
    from semexplore_gym.core.worlds.build import world_from_segments

    walls = [[0, 0, 1e4, 0], [1e4, 0, 1e4, 1e4], [1e4, 1e4, 0, 1e4], [0, 1e4, 0, 0]]
    t0 = time.perf_counter()
    with pytest.raises(WorldTooLargeError, match="coarser resolution or crop"):
        world_from_segments("big", walls, [[1.0, 1.0]])
    assert time.perf_counter() - t0 < 1.0


# ---- items 3 and 4: physics, reward and odometry values


@pytest.mark.parametrize(
    "override,fragment",
    [
        ("robot.max_linear_speed_mps=5", "physics.max_substeps"),
        ("episode.dt_s=2", "physics.max_substeps"),
        ("physics.max_substeps=1", "physics.max_substeps"),
        ("robot.radius_m=1e-6", "robot.radius_m"),
        ("robot.mass_kg=1e-6", "robot.mass_kg"),
        ("robot.max_drive_force_n=1e9", "robot.max_drive_force_n"),
        ("physics.solver_iterations=1000000000", "physics.solver_iterations"),
        ("physics.collision_slop_m=0.04", "physics.collision_slop_m"),
        ("reward.time_weight=nan", "reward.time_weight"),
        ("reward.collision_weight=inf", "reward.collision_weight"),
        ("odometry.trans_from_trans=1e300", "odometry.trans_from_trans"),
        ("episode.start_clearance_margin_m=nan", "start_clearance_margin_m"),
    ],
)
def test_physics_reward_odometry_values_are_checked(override, fragment) -> None:
    with pytest.raises(ConfigError, match=fragment.replace(".", r"\.")):
        load_env_config(None, [override])


def test_fast_robot_is_accepted_with_enough_substeps() -> None:
    cfg = load_env_config(None, ["robot.max_linear_speed_mps=5", "physics.max_substeps=200"])
    assert cfg.physics.max_substeps == 200
    load_env_config("paper")
    load_env_config(None, ["robot.max_linear_speed_mps=1.0"])


@pytest.mark.slow
def test_no_penetration_at_the_accepted_extremes() -> None:
    from semexplore_gym.core.worlds.world import World
    from semexplore_gym.sim.robot import RobotSim, nearest_wall_distance_m

    box = np.array([[0, 0, 4, 0], [4, 0, 4, 4], [4, 4, 0, 4], [0, 4, 0, 0], [2, 0, 2, 1.5]], float)
    world = World(
        "box", box, (0.0, 0.0, 4.0, 4.0), np.ones((80, 80), bool), GridGeometry(0.05, 0, 0, 80, 80)
    )
    for overrides, dt in (
        (["robot.max_linear_speed_mps=5", "physics.max_substeps=200"], 0.2),
        (["episode.dt_s=2", "physics.max_substeps=88"], 2.0),
        (["robot.mass_kg=0.1", "robot.max_drive_force_n=20"], 0.2),
    ):
        cfg = load_env_config(None, [*overrides, f"episode.dt_s={dt}"])
        sim = RobotSim(world, cfg.robot, cfg.physics)
        sim.reset((1.0, 1.0, 0.3))
        rng = np.random.default_rng(0)
        v = cfg.robot.max_linear_speed_mps
        for _ in range(1500):
            sim.step(v * (1 if rng.random() < 0.7 else -1), rng.uniform(-1, 1) * 2.84, dt)
            x, y, _ = sim.pose
            assert 0 < x < 4 and 0 < y < 4
            assert nearest_wall_distance_m(box, x, y) > cfg.robot.radius_m - 0.01, overrides


# ---- item 6: compare-weights validates before tuning


@pytest.mark.parametrize(
    "flag,value,fragment",
    [
        ("--test-worlds", "mazee1", "--test-worlds"),
        ("--train-worlds", "maze:size_m=nan", "--train-worlds"),
        ("--max-time-s", "nan", "--max-time-s"),
        ("--max-time-s", "-1", "--max-time-s"),
        ("--target-coverage", "0", "--target-coverage"),
    ],
)
def test_compare_weights_fails_before_tuning(tmp_path, capsys, flag, value, fragment) -> None:
    argv = [
        "compare-weights",
        "--train-worlds",
        "maze:size_m=4",
        "--test-worlds",
        "maze1",
        "--trials",
        "50",
        "--out",
        str(tmp_path / "cw"),
        "--no-progress",
    ]
    argv = (
        [*argv, flag, value]
        if flag not in argv
        else [
            value if a == argv[argv.index(flag) + 1] and i == argv.index(flag) + 1 else a
            for i, a in enumerate(argv)
        ]
    )
    t0 = time.perf_counter()
    assert main(argv) == 2
    assert time.perf_counter() - t0 < 15
    err = capsys.readouterr().err
    assert fragment in err and "Traceback" not in err and "Trial" not in err
    assert not (tmp_path / "cw" / "tuning").exists()


# ---- items 7 and 8: CLI cases


@pytest.mark.parametrize(
    "argv,fragment",
    [
        (["explore", "--seed", "-1", "--max-time-s", "1"], "--seed"),
        (["show-world", "maze1", "--seed", "-1", "--out", "{d}/o.png"], "--seed"),
        (["segment", "maze1", "--export", "{d}"], "is a directory"),
        (["segment", "maze1", "--out", "{d}"], "is a directory"),
        (["segment", "maze1", "--out", "{d}/seg"], "must end in .png"),
        (["segment", "maze1", "--resolution", "1e-9"], "--resolution"),
        (["segment", "maze1", "--resolution", "50"], "--resolution"),
        (["segment", "maze1", "--resolution", "0.03"], "whole multiple"),
        (["segment", "maze1", "--clearance", "1e9"], "--clearance"),
        (["segment", "maze1", "--clearance", "2"], "no area is left"),
        (["explore", "--policy", "py:sys:exit", "--max-time-s", "1"], "SystemExit"),
        (
            ["explore", "--policy", "py:builtins:dict", "--max-time-s", "1"],
            "not a semexplore_gym.policies.base.Policy",
        ),
        (["explore", "--gif-every-s", "0", "--max-time-s", "1"], "--gif-every-s"),
        (["explore", "--gif", "{d}", "--max-time-s", "1"], "is a directory"),
        (["explore", "--max-time-s", "inf"], "--max-time-s"),
        (["show-world", "{d}/" + "a" * 300 + ".yaml", "--out", "{d}/o.png"], "too long"),
    ],
)
def test_cli_bad_arguments_are_clean_errors(tmp_path, capsys, argv, fragment) -> None:
    argv = [a.replace("{d}", str(tmp_path)) for a in argv]
    if argv[0] == "explore":
        argv += ["--policy", "random"] if "--policy" not in argv else []
        argv += ["--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1, err


def test_corrupt_sb3_zip_is_a_clean_error(tmp_path, capsys) -> None:
    z = tmp_path / "m.zip"
    z.write_bytes(b"PK\x03\x04" + bytes(range(256)) * 3)
    assert main(["explore", "--policy", f"sb3:{z}", "--max-time-s", "1", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "m.zip" in err and "Traceback" not in err


def test_complex_action_is_refused() -> None:
    import gymnasium as gym

    import semexplore_gym  # noqa: F401

    env = gym.make("SemanticExplore-v0", world="maze1")
    env.reset(seed=0)
    for a in (np.array([0.5 + 1j, 0.0]), [0.5 + 1j, 0.0], np.complex64(1)):
        with pytest.raises(ValueError, match="action"):
            env.unwrapped.step(a)
    env.close()
