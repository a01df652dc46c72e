"""Fuzz the command line, the map loaders, the env config and the env's actions with bad input.

Every case is one bad input (a malformed ROS map or HouseExpo file, a world spelling, an env
config value or override, an action, a policy spec, a CLI argument) and what must happen to it.
Each runs in a forked child of this process (which has imported the package once), with a
wall-clock timeout and an address-space limit, and is classified:

- ``clean``: exit code 1 or 2, a short error on stderr, no "Traceback";
- ``traceback``: an exception escaped (or the error was printed with a traceback);
- ``hang``: still running at the timeout, or killed by the memory limit;
- ``garbage``: exit code 0 (or an accepted action) on input that must be rejected;
- ``accepted``: exit code 0 on input that may be valid (not counted against anything).

    python scripts/fuzz.py                        # the full run (>= 2000 cases), table at the end
    python scripts/fuzz.py --sample 300 --seed 0  # a seeded sample
    python scripts/fuzz.py --category ros_map --show-failures
    python scripts/fuzz.py --list                 # print the cases, run nothing
"""

from __future__ import annotations

import argparse
import io
import json
import os
import random
import resource
import select
import signal
import struct
import sys
import tempfile
import time
import zlib
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

REJECT = "reject"
ANY = "any"
OUTCOMES = ("clean", "traceback", "hang", "garbage", "accepted")
#: An error message longer than this counts as a flood (the alias bomb wrote 2.1 GB).
MAX_STDERR_BYTES = 4000


@dataclass
class Case:
    """One fuzz input: ``argv`` for ``semexplore`` (``{d}`` is the case's directory), the files
    to create there, and whether the input must be rejected."""

    category: str
    name: str
    argv: list[str] = field(default_factory=list)
    files: dict[str, bytes] = field(default_factory=dict)
    expect: str = REJECT
    action: object = None  # for category "action": the action passed to env.step


# --------------------------------------------------------------------------- file builders


def pgm(arr) -> bytes:
    """Binary PGM bytes of a uint8 array."""
    h, w = arr.shape
    return b"P5\n%d %d\n255\n" % (w, h) + arr.astype("uint8").tobytes()


def box_map(n: int = 60):
    import numpy as np

    a = np.zeros((n, n), np.uint8)
    a[2:-2, 2:-2] = 254
    a[n // 2, 2 : n // 2] = 0
    return a


def png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png_claiming(width: int, height: int) -> bytes:
    """A tiny PNG whose header claims ``width x height`` 8-bit grey pixels (a decompression bomb
    once decoded; the data stream is short, so a decoder fails or stops early)."""
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    body = zlib.compress(b"\x00" + b"\xff" * min(width, 1 << 16))
    return (
        b"\x89PNG\r\n\x1a\n"
        + png_chunk(b"IHDR", ihdr)
        + png_chunk(b"IDAT", body)
        + png_chunk(b"IEND", b"")
    )


def png_bytes(arr) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(arr).save(buf, format="PNG")
    return buf.getvalue()


def alias_bomb(levels: int, width: int, key: str = "image") -> str:
    lines = ["l0: &l0 [" + ", ".join(['"lol"'] * width) + "]"]
    for i in range(1, levels):
        lines.append(f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * width) + "]")
    lines.append(f"{key}: *l{levels - 1}")
    return "\n".join(lines) + "\n"


def nested(depth: int, open_: str = "[", close: str = "]") -> str:
    return open_ * depth + "1" + close * depth


BASE_YAML = {
    "image": "m.pgm",
    "resolution": "0.05",
    "origin": "[0.0, 0.0, 0.0]",
    "negate": "0",
    "occupied_thresh": "0.65",
    "free_thresh": "0.196",
}

BAD_NUMBERS = [
    ".nan",
    ".inf",
    "-.inf",
    "nan",
    "1e400",
    "-1e400",
    "'abc'",
    "[1, 2]",
    "{a: 1}",
    "null",
    "true",
    "''",
    "0x",
    "1e300",
    "-1e300",
    '"0.05"',
    "[]",
    "!!binary aGk=",
]
BAD_RES = ["0", "-0.05", "1e-9", "50", "1e300", "-1", "2.0"]
BAD_THRESH = ["-0.1", "1.5", "2", "-1"]
BAD_ORIGIN = [
    "[.nan, 0, 0]",
    "[0]",
    "[0, 0, 0, 0]",
    "abc",
    "[0, 0, 1.0]",
    "[1e300, 0, 0]",
    "[[0], 0, 0]",
    "{x: 0}",
    "null",
    "[.inf, 0, 0]",
    "['a', 0, 0]",
    "[true, 0, 0]",
    "[0, 0, .nan]",
    "[]",
    "7",
]
BAD_NEGATE = ["2", "-1", "0.5", "'yes'", "[0]", ".nan", "null", "{}"]
BAD_MODE = ["foo", "1", "[]", "null", "'trinary x'", "{}"]
#: An image path whose basename exists next to the yaml is found there (documented fallback).
FALLBACK_IMAGE = "'" + "d/" * 200 + "m.pgm'"
BAD_IMAGE = [
    "missing.pgm",
    "''",
    "123",
    "[m.pgm]",
    "'" + "a" * 300 + ".pgm'",
    "'a\\0b.pgm'",
    "null",
    "'../../../../../../etc/passwd'",
    "'/dev/null'",
    "'.'",
    "{a: b}",
    "'   '",
]


def yaml_text(doc: dict[str, str]) -> bytes:
    return "".join(f"{k}: {v}\n" for k, v in doc.items()).encode()


# --------------------------------------------------------------------------- commands

CLI_FOR_MAP = {
    "show": lambda w: ["show-world", w, "--out", "{d}/o.png"],
    "segment": lambda w: ["segment", w],
    "explore": lambda w: [
        "explore",
        "--world",
        w,
        "--policy",
        "random",
        "--max-time-s",
        "1",
        "--no-progress",
    ],
    "bench": lambda w: [
        "benchmark",
        "--worlds",
        w,
        "--policies",
        "random",
        "--runs",
        "1",
        "--max-time-s",
        "1",
        "--out",
        "{d}/b",
        "--no-progress",
        "--no-plots",
    ],
}


def ros_map_cases(rng: random.Random) -> list[Case]:
    import numpy as np

    good_img = pgm(box_map())
    out: list[Case] = []

    def add(
        name: str,
        doc_bytes: bytes,
        extra: dict[str, bytes] | None = None,
        cmds=("show", "segment", "explore"),
        expect: str = REJECT,
    ) -> None:
        for c in cmds:
            files = {"m.yaml": doc_bytes, "m.pgm": good_img, **(extra or {})}
            out.append(Case("ros_map", f"{name}/{c}", CLI_FOR_MAP[c]("{d}/m.yaml"), files, expect))

    for key, bads in (
        ("resolution", BAD_NUMBERS + BAD_RES),
        ("occupied_thresh", BAD_NUMBERS + BAD_THRESH),
        ("free_thresh", BAD_NUMBERS + BAD_THRESH),
        ("origin", BAD_ORIGIN),
        ("negate", BAD_NEGATE),
        ("mode", BAD_MODE),
        ("image", BAD_IMAGE),
    ):
        for v in bads:
            doc = dict(BASE_YAML, **{key: v})
            add(
                f"{key}={v[:30]}",
                yaml_text(doc),
                cmds=(rng.choice(("show", "segment", "explore")),),
            )
        doc = {k: v for k, v in BASE_YAML.items() if k != key}
        if key in ("image", "resolution", "origin"):
            add(f"missing-{key}", yaml_text(doc), cmds=("show", "segment"))
    add(
        "image-fallback",
        yaml_text(dict(BASE_YAML, image=FALLBACK_IMAGE)),
        cmds=("show",),
        expect=ANY,
    )
    add("thresh-swapped", yaml_text(dict(BASE_YAML, occupied_thresh="0.1", free_thresh="0.9")))
    for levels, width in ((4, 10), (6, 9), (9, 9), (12, 5), (20, 3)):
        for key in ("image", "resolution", "origin", "mode", "extra"):
            text = alias_bomb(levels, width, key)
            # 10^4 values under an unknown key: within bounds, and map_server ignores the key.
            small = levels == 4 and key == "extra"
            if key == "extra":
                text = yaml_text(BASE_YAML).decode() + text
            add(
                f"alias-bomb-{levels}x{width}-{key}",
                text.encode(),
                cmds=("show", "segment"),
                expect=ANY if small else REJECT,
            )
    for depth in (70, 500, 5000, 50000):
        add(
            f"deep-list-{depth}", (yaml_text(BASE_YAML).decode() + f"x: {nested(depth)}\n").encode()
        )
        add(
            f"deep-map-{depth}",
            ("image: " + "{a: " * depth + "1" + "}" * depth + "\n").encode(),
            cmds=("show",),
        )
    add("recursive-alias", b"image: &a [*a]\nresolution: 0.05\norigin: [0,0,0]\n")
    add("recursive-map", b"a: &a {b: *a}\nimage: m.pgm\nresolution: 0.05\norigin: [0,0,0]\n")
    add("non-utf8", yaml_text(BASE_YAML) + b"# \xff\xfe\xfa\n")
    add(
        "latin1-image-name",
        "image: m\xe9.pgm\nresolution: 0.05\norigin: [0,0,0]\n".encode("latin-1"),
    )
    add("empty", b"")
    add("only-comment", b"# nothing\n")
    add("top-list", b"- image: m.pgm\n")
    add("top-scalar", b"42\n")
    add("top-string", b"hello\n")
    add("tabs", b"image:\tm.pgm\n\tresolution: 0.05\n")
    add(
        "python-tag",
        b"image: !!python/object/apply:os.system ['echo pwned']\nresolution: 0.05\norigin: [0,0,0]\n",
    )
    add("unknown-tag", b"image: !foo m.pgm\nresolution: 0.05\norigin: [0,0,0]\n")
    add("huge-file", yaml_text(BASE_YAML) + b"#" + b"x" * (3 << 20) + b"\n", cmds=("show",))
    add("bad-timestamp", yaml_text(dict(BASE_YAML, origin="2001-13-45")))
    add("unhashable-key", yaml_text(BASE_YAML) + b"? [1, 2]\n: 3\n")
    add("unclosed-bracket", b"image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0\n")
    for i in range(30):
        junk = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 400)))
        add(f"random-bytes-{i}", junk, cmds=(rng.choice(("show", "segment")),))
    # Mutations of a valid yaml: a random byte changed, deleted or duplicated.
    base = yaml_text(BASE_YAML)
    for i in range(60):
        b = bytearray(base)
        pos = rng.randrange(len(b))
        op = rng.choice(("flip", "delete", "insert"))
        if op == "flip":
            b[pos] = rng.choice(b"{}[]:&*!%@`|>-,'\"\x00\xff")
        elif op == "delete":
            del b[pos : pos + rng.randrange(1, 8)]
        else:
            b[pos:pos] = bytes([rng.choice(b"{}[]:&*!%@`|>-,'\"\x00\xff")]) * rng.randrange(1, 4)
        add(f"mutant-{i}-{op}", bytes(b), cmds=(rng.choice(("show", "segment")),), expect=ANY)
    # Images: corrupt, truncated, empty, claiming huge sizes, all walls, noise.
    imgs = {
        "corrupt": bytes(rng.randrange(256) for _ in range(500)),
        "empty": b"",
        "truncated-png": png_bytes(box_map())[:60],
        "bomb-20k": png_claiming(20000, 20000),
        "bomb-100k": png_claiming(100000, 100000),
        "bomb-wide": png_claiming(1 << 30, 1),
        "pgm-header-lies": b"P5\n60000 60000\n255\n" + b"\xff" * 100,
        "pgm-zero": b"P5\n0 0\n255\n",
        "all-wall": pgm(np.zeros((50, 50), np.uint8)),
        "all-unknown": pgm(np.full((50, 50), 205, np.uint8)),
        "one-pixel": pgm(np.full((1, 1), 254, np.uint8)),
        "text-file": b"this is not an image\n" * 10,
    }
    noise = (np.random.default_rng(0).random((1200, 1200)) < 0.5).astype(np.uint8) * 254
    imgs["noise-1200"] = png_bytes(noise)
    for name, data in imgs.items():
        add(f"image-{name}", yaml_text(BASE_YAML), {"m.pgm": data}, cmds=("show", "explore"))
        # segment reads the grid without building a world: a noise image is a valid (if odd) map
        add(
            f"image-{name}",
            yaml_text(BASE_YAML),
            {"m.pgm": data},
            cmds=("segment",),
            expect=ANY if name == "noise-1200" else REJECT,
        )
    # A valid map: must be accepted (a control, so rejecting everything is not a pass).
    add("valid", yaml_text(BASE_YAML), cmds=("show", "segment"), expect=ANY)
    return out


HX_BASE = {"id": "x", "verts": [[0, 0], [5, 0], [5, 4], [0, 4]], "room_num": 1}


def houseexpo_cases(rng: random.Random) -> list[Case]:
    out: list[Case] = []

    def add(
        name: str, text: bytes, cmds=("show", "segment", "explore"), expect: str = REJECT
    ) -> None:
        for c in cmds:
            out.append(
                Case(
                    "houseexpo",
                    f"{name}/{c}",
                    CLI_FOR_MAP[c]("{d}/h.json"),
                    {"h.json": text},
                    expect,
                )
            )

    def doc(**kw) -> bytes:
        d = dict(HX_BASE, **kw)
        return json.dumps({k: v for k, v in d.items() if v is not ...}).encode()

    bad_verts = {
        "missing": ...,
        "string": "abc",
        "one": [[0, 0]],
        "two": [[0, 0], [1, 1]],
        "three-d": [[0, 0, 0], [1, 0, 0], [1, 1, 0]],
        "strings": [[0, "a"], [1, 0], [1, 1]],
        "nulls": [[0, None], [1, 0], [1, 1]],
        "flat": [0, 0, 1, 0, 1, 1],
        "empty": [],
        "dict": {"a": 1},
        "number": 5,
        "ragged": [[0, 0], [1], [1, 1]],
        "collinear": [[0, 0], [1, 0], [2, 0]],
        "tiny": [[0, 0], [0.01, 0], [0.01, 0.01], [0, 0.01]],
        "km": [[0, 0], [1000, 0], [1000, 1000], [0, 1000]],
        "100km": [[0, 0], [1e5, 0], [1e5, 1e5], [0, 1e5]],
        "far": [[1e9, 0], [1e9 + 5, 0], [1e9 + 5, 4], [1e9, 4]],
        "huge-coord": [[0, 0], [1e300, 0], [1e300, 1e300]],
        "thin-long": [[0, 0], [5000, 0], [5000, 0.3], [0, 0.3]],
        "nested": [[[0, 0]], [[1, 0]], [[1, 1]]],
        "bool": [[True, False], [1, 0], [1, 1]],
        "duplicate-points": [[0, 0], [0, 0], [0, 0], [0, 0]],
    }
    for name, v in bad_verts.items():
        add(f"verts-{name}", doc(verts=v))
    for lit in ("NaN", "Infinity", "-Infinity", "1e999", "-1e999"):
        add(f"literal-{lit}", f'{{"verts": [[0, 0], [{lit}, 0], [5, 4]]}}'.encode())
    many = [[10 * rng.random(), 10 * rng.random()] for _ in range(300000)]
    add("zigzag-300k", json.dumps({"verts": many}).encode(), cmds=("show",))
    for depth in (70, 1000, 100000):
        add(
            f"deep-{depth}", ('{"verts": ' + nested(depth) + "}").encode(), cmds=("show", "segment")
        )
        add(f"deep-obj-{depth}", ('{"a": ' * depth + "1" + "}" * depth).encode(), cmds=("show",))
    add("top-list", b"[[0, 0], [5, 0], [5, 4]]")
    add("top-number", b"3")
    add("empty", b"")
    add("non-utf8", doc() + b"\xff")
    add("utf16", json.dumps(HX_BASE).encode("utf-16"))
    add("truncated", doc()[:-5])
    add("trailing-garbage", doc() + b"}}")
    add(
        "huge-file",
        b'{"verts": [[0,0],[5,0],[5,4]], "pad": "' + b"x" * (17 << 20) + b'"}',
        cmds=("show",),
    )
    for i in range(40):
        b = bytearray(doc())
        pos = rng.randrange(len(b))
        b[pos] = rng.choice(b'{}[],:"0-eE.\x00\xff')
        add(f"mutant-{i}", bytes(b), cmds=(rng.choice(("show", "segment")),), expect=ANY)
    add("valid", doc(), cmds=("show", "segment"), expect=ANY)
    return out


WORLD_SPELLINGS_BAD = [
    "maze:seed=-1",
    "maze:seed=abc",
    "maze:seed=1.5",
    "maze:seed=1e30",
    "maze:seed=nan",
    "maze:size_m=nan",
    "maze:size_m=inf",
    "maze:size_m=-1",
    "maze:size_m=0",
    "maze:size_m=1e9",
    "maze:corridor_width_m=0",
    "maze:corridor_width_m=-1",
    "maze:corridor_width_m=nan",
    "maze:braid=2",
    "maze:braid=-0.1",
    "maze:braid=nan",
    "maze:foo=1",
    "maze:=",
    "maze:seed",
    "maze:seed=",
    "maze:=1",
    "maze::",
    "office:size_m=1e9",
    "office:seed=-5",
    "office:foo=bar",
    "office:size_m=nan",
    "cave:size_m=-3",
    "cave:seed=x",
    "cave:size_m=1e12",
    "cave:foo=1",
    "unknownfamily",
    "",
    " ",
    ",",
    "maze3",
    "MAZE1",
    "maze1:seed=1",
    "nonexistent.yaml",
    "nonexistent.json",
    "dir/",
    "/",
    "maze:seed=1;rm -rf /",
    "m\u00e4ze",
    "x" * 5000,
    "maze:" + "a=1," * 2000,
    "office:size_m=0.1",
    "cave:size_m=0.1",
    "maze:size_m=1e-300",
    "maze:size_m=1e308",
    "maze:seed=0x10",
    "maze:seed=True",
    "..",
    "~",
    "maze1.yaml",
    "/dev/null",
    "/etc/passwd",
    "/proc/self/mem",
    "a" * 300 + ".yaml",
    "a" * 300 + ".json",
]


def world_cases(rng: random.Random) -> list[Case]:
    out = []
    for w in WORLD_SPELLINGS_BAD:
        for c in ("show", "segment", "explore", "bench"):
            out.append(Case("world", f"{w[:40]}/{c}", CLI_FOR_MAP[c](w)))
    # Valid: defaults ("maze:"), a trailing comma, any integer seed; Python's int() reads any
    # Unicode digit ("seed=\u0661" is seed 1).
    for w in (
        "maze1",
        "maze:seed=3,size_m=6",
        "office:seed=1",
        "cave:seed=2",
        "maze:seed=\u0661",
        "maze:",
        "maze:seed=1,",
        "maze:seed=99999999999999999999999",
    ):
        out.append(Case("world", f"valid-{w}", CLI_FOR_MAP["show"](w), expect=ANY))
    return out


#: Env config keys and values every one of them must reject.
ENV_KEYS = {
    "robot": [
        "radius_m",
        "mass_kg",
        "max_linear_speed_mps",
        "max_angular_speed_radps",
        "max_drive_force_n",
        "max_turn_torque_nm",
    ],
    "physics": ["max_substep_travel_m", "max_substeps", "collision_slop_m", "solver_iterations"],
    "lidar": ["n_beams", "max_range_m", "min_range_m", "range_noise_std_m", "dropout_prob"],
    "odometry": [
        "rot_from_rot",
        "rot_from_trans",
        "trans_from_trans",
        "trans_from_rot",
        "min_translation_m",
    ],
    "reward": ["free_area_change_weight", "time_weight", "collision_weight"],
    "episode": ["dt_s", "max_time_s", "coverage_goal", "start_clearance_margin_m"],
    "mapping": [],
}
ALWAYS_BAD = [
    "nan",
    ".nan",
    "inf",
    "-inf",
    "1e300",
    "-1e300",
    "abc",
    "[1, 2]",
    "{a: 1}",
    "''",
    "1e400",
    "[[[[[[[[1]]]]]]]]",
]
#: Values that are bad for the keys listed (ranges of the physics and the no-penetration promise).
RANGE_BAD = {
    "robot.radius_m": ["0", "-0.1", "1e-6", "0.005", "100"],
    "robot.mass_kg": ["0", "-1", "1e-9", "1e9"],
    "robot.max_linear_speed_mps": ["0", "-1", "5", "6", "100"],
    "robot.max_angular_speed_radps": ["0", "-1", "1e6"],
    "robot.max_drive_force_n": ["0", "-1", "1e9"],
    "robot.max_turn_torque_nm": ["0", "-1", "1e9"],
    "physics.max_substep_travel_m": ["0", "-1", "1", "0.5"],
    "physics.max_substeps": ["0", "-1", "1", "2", "1000000000"],
    "physics.collision_slop_m": ["-1", "1"],
    "physics.solver_iterations": ["0", "-1", "1000000000"],
    "lidar.n_beams": ["0", "-1", "3", "100000", "1.5"],
    "lidar.max_range_m": ["0", "-1"],
    "lidar.dropout_prob": ["-0.1", "1", "2"],
    "odometry.trans_from_trans": ["-1", "1e300", "1e30"],
    "odometry.rot_from_rot": ["-1", "1e300", "1e30"],
    "reward.time_weight": ["1e300"],
    "reward.collision_weight": ["1e300"],
    "episode.dt_s": ["0", "-1", "2", "3", "100"],
    "episode.max_time_s": ["0", "-1"],
    "episode.coverage_goal": ["0", "-1", "2"],
}


def env_config_cases(rng: random.Random) -> list[Case]:
    out = []
    explore = [
        "explore",
        "--world",
        "maze1",
        "--policy",
        "random",
        "--max-time-s",
        "1",
        "--no-progress",
    ]
    for section, keys in ENV_KEYS.items():
        for key in keys:
            dotted = f"{section}.{key}"
            for v, how in (
                (v, h)
                for v in ALWAYS_BAD + RANGE_BAD.get(dotted, [])
                for h in ("env-set", "yaml", "bench")
            ):
                # explore sets episode.max_time_s from its own --max-time-s after the config file
                expect = ANY if (dotted == "episode.max_time_s" and how == "yaml") else REJECT
                if how == "env-set":
                    argv = [*explore, "--env-set", f"{dotted}={v}"]
                    files = {}
                elif how == "yaml":
                    argv = [*explore, "--env-config", "{d}/c.yaml"]
                    files = {"c.yaml": f"{section}:\n  {key}: {v}\n".encode()}
                else:
                    argv = [*CLI_FOR_MAP["bench"]("maze1"), "--env-set", f"{dotted}={v}"]
                    files = {}
                out.append(Case("env_config", f"{dotted}={v[:20]}/{how}", argv, files, expect))
    for text in [
        "robot.foo=1",
        "foo.bar=1",
        "robot=1",
        "=1",
        "robot.",
        "noequals",
        ".=.",
        "robot..radius_m=0.1",
        "robot.radius_m.x=1",
        "episode.start_pose=[1,2]",
        "episode.start_pose=[nan,0,0]",
        "episode.start_pose=[1e300,0,0]",
        "episode.start_pose=[1,2,3,4]",
        "episode.random_start=maybe",
        "lidar.n_beams=" + "9" * 5000,
        "robot.radius_m=" + alias_bomb(9, 9, "x").replace("\n", " "),
        "robot.radius_m=" + nested(5000),
        "robot.radius_m=&a [*a]",
        "robot.radius_m=!!python/name:os.system",
        "robot.radius_m=\x00",
        "episode.dt_s=2001-01-01",
        "robot.mass_kg=0x1p3",
    ]:
        out.append(Case("env_config", f"override-{text[:30]}", [*explore, "--env-set", text]))
    bomb = alias_bomb(9, 9, "robot").encode()
    out.append(
        Case(
            "env_config",
            "config-alias-bomb",
            [*explore, "--env-config", "{d}/c.yaml"],
            {"c.yaml": bomb},
        )
    )
    out.append(
        Case(
            "env_config",
            "config-deep",
            [*explore, "--env-config", "{d}/c.yaml"],
            {"c.yaml": ("robot: " + nested(20000) + "\n").encode()},
        )
    )
    out.append(
        Case(
            "env_config",
            "config-non-utf8",
            [*explore, "--env-config", "{d}/c.yaml"],
            {"c.yaml": b"robot:\n  radius_m: 0.1 # \xff\n"},
        )
    )
    out.append(Case("env_config", "config-missing", [*explore, "--env-config", "{d}/nope.yaml"]))
    out.append(Case("env_config", "config-dir", [*explore, "--env-config", "{d}"]))
    out.append(
        Case(
            "env_config",
            "config-list",
            [*explore, "--env-config", "{d}/c.yaml"],
            {"c.yaml": b"- 1\n"},
        )
    )
    out.append(Case("env_config", "unknown-preset", [*explore, "--env-config", "nosuchpreset"]))
    # Policy config files and --set values.
    # Policy weights: relative, so any finite value is a (possibly odd) weight set.
    for v in ALWAYS_BAD[:6] + ["-1"]:
        out.append(
            Case(
                "env_config",
                f"policy-set-w_v={v}",
                [
                    *explore[:-3],
                    "--policy",
                    "semantic",
                    "--max-time-s",
                    "1",
                    "--no-progress",
                    "--policy-set",
                    f"cost.w_v={v}",
                ],
                expect=ANY if v in ("-1", "1e300", "-1e300") else REJECT,
            )
        )
    out.append(
        Case(
            "env_config",
            "policy-config-bomb",
            [*explore, "--policy-config", "{d}/p.yaml"],
            {"p.yaml": alias_bomb(9, 9, "params").encode()},
        )
    )
    out.append(
        Case(
            "env_config",
            "valid-override",
            [*explore, "--env-set", "robot.max_linear_speed_mps=0.15"],
            expect=ANY,
        )
    )
    return out


POLICY_SPECS = [
    "unknown",
    "sb3",
    "sb3:",
    "sb3:{d}/missing.zip",
    "sb3:{d}/corrupt.zip",
    "sb3:{d}/empty.zip",
    "sb3:{d}/notazip.txt",
    "sb3:{d}",
    "py:sys:exit",
    "py:os:getcwd",
    "py:nonexistent_mod_xyz:f",
    "py:math:pi",
    "py:builtins:dict",
    "py:",
    "py:sys",
    "py::",
    "py:{d}/bad.py:P",
    "py:{d}/raises.py:P",
    "py:{d}/missing.py:P",
    "py:{d}/exits.py:P",
    "semantic:foo",
    "random:abc",
    "random:-1",
    "frontier:x",
    "nearest:1",
    "[label]",
    "semantic[",
    "semantic[]",
    "py:os:_exit",
    "py:builtins:exit",
    "py:builtins:quit",
    "py:time:sleep",
    "py:builtins:input",
]


def policy_cases(rng: random.Random) -> list[Case]:
    import zipfile

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("data", "{}")
    files = {
        "corrupt.zip": b"PK\x03\x04" + bytes(rng.randrange(256) for _ in range(300)),
        "empty.zip": buf.getvalue(),
        "notazip.txt": b"hello",
        "bad.py": b"def P(:\n",
        "raises.py": b"def P(**kw):\n    raise RuntimeError('boom')\n",
        "exits.py": b"import sys\ndef P(**kw):\n    sys.exit(0)\n",
    }
    out = []
    for spec in POLICY_SPECS:
        expect = ANY if spec == "semantic[]" else REJECT  # an empty label is no label
        out.append(
            Case(
                "policy",
                f"explore-{spec}",
                [
                    "explore",
                    "--world",
                    "maze1",
                    "--policy",
                    spec,
                    "--max-time-s",
                    "1",
                    "--no-progress",
                ],
                files,
                expect,
            )
        )
        out.append(
            Case(
                "policy",
                f"bench-{spec}",
                [
                    "benchmark",
                    "--worlds",
                    "maze1",
                    "--policies",
                    spec,
                    "--runs",
                    "1",
                    "--max-time-s",
                    "1",
                    "--out",
                    "{d}/b",
                    "--no-progress",
                    "--no-plots",
                ],
                files,
                expect,
            )
        )
    return out


def cli_cases(rng: random.Random) -> list[Case]:
    out = []
    nums_bad = ["nan", "-1", "0", "inf", "-inf", "1e300", "abc", ""]
    ex = ["explore", "--world", "maze1", "--policy", "random", "--no-progress"]
    for v in nums_bad:
        out.append(Case("cli", f"explore-max-time={v}", [*ex, "--max-time-s", v]))
        out.append(
            Case(
                "cli",
                f"explore-gif-every={v}",
                [*ex, "--max-time-s", "1", "--gif", "{d}/a.gif", "--gif-every-s", v],
                expect=ANY if v == "1e300" else REJECT,
            )
        )  # one frame: valid
    for v in ["-1", "-100", str(2**64), "abc", "1.5", ""]:
        out.append(Case("cli", f"explore-seed={v}", [*ex, "--max-time-s", "1", "--seed", v]))
        out.append(
            Case(
                "cli", f"show-seed={v}", ["show-world", "maze1", "--out", "{d}/o.png", "--seed", v]
            )
        )
        out.append(Case("cli", f"segment-seed={v}", ["segment", "maze:size_m=4", "--seed", v]))
    out.append(Case("cli", "explore-gif-dir", [*ex, "--max-time-s", "1", "--gif", "{d}"]))
    out.append(
        Case(
            "cli",
            "explore-gif-noparent",
            [*ex, "--max-time-s", "1", "--gif", "/proc/nonexistent/a.gif"],
        )
    )
    for o in [
        "{d}",
        "{d}/f.txt",
        "/proc/nonexistent/x.png",
        "{d}/noext",
        "{d}/" + "a" * 300 + ".png",
        "",
    ]:
        out.append(
            Case("cli", f"show-out={o[:20]}", ["show-world", "maze1", "--out", o], {"f.txt": b"x"})
        )
        out.append(
            Case(
                "cli",
                f"segment-out={o[:20]}",
                ["segment", "maze:size_m=4", "--out", o],
                {"f.txt": b"x"},
            )
        )
    for e in ["{d}", "/proc/nonexistent/x.json", "{d}/" + "a" * 300 + ".json", ""]:
        out.append(
            Case("cli", f"segment-export={e[:20]}", ["segment", "maze:size_m=4", "--export", e])
        )
    for v in ["1e-9", "50", "nan", "-1", "0", "inf", "1e300", "10", "abc", "1e-5"]:
        out.append(
            Case("cli", f"segment-resolution={v}", ["segment", "maze:size_m=4", "--resolution", v])
        )
    for v in ["1e9", "-1", "nan", "0", "inf", "-inf", "abc", "1e300", "100"]:
        out.append(
            Case("cli", f"segment-clearance={v}", ["segment", "maze:size_m=4", "--clearance", v])
        )
    bench = [
        "benchmark",
        "--worlds",
        "maze1",
        "--policies",
        "random",
        "--max-time-s",
        "1",
        "--no-progress",
        "--no-plots",
    ]
    for flag, vals in (
        ("--runs", ["0", "-1", "1000000000", "abc", "1.5"]),
        ("--workers", ["0", "-1", "1000000", "abc"]),
        ("--seed0", ["-1", str(2**64), "abc"]),
        ("--max-time-s", ["nan", "-1", "0", "inf", "abc"]),
        ("--backend", ["foo", ""]),
    ):
        for v in vals:
            out.append(Case("cli", f"bench{flag}={v}", [*bench, "--out", "{d}/b", flag, v]))
    out.append(Case("cli", "bench-out-file", [*bench, "--out", "{d}/f.txt"], {"f.txt": b"x"}))
    out.append(
        Case("cli", "bench-dup-policies", [*bench, "--out", "{d}/b", "--policies", "random,random"])
    )
    out.append(
        Case("cli", "bench-dup-worlds", [*bench, "--out", "{d}/b", "--worlds", "maze1,maze1"])
    )
    out.append(Case("cli", "bench-empty-policies", [*bench, "--out", "{d}/b", "--policies", ","]))
    out.append(Case("cli", "bench-empty-worlds", [*bench, "--out", "{d}/b", "--worlds", ","]))
    out.append(
        Case("cli", "bench-bad-csv", [*bench, "--out", "{d}/b"], {"b/runs.csv": b"a,b\n1,2\n"})
    )
    cw = [
        "compare-weights",
        "--train-worlds",
        "maze:size_m=4",
        "--test-worlds",
        "maze:size_m=4,seed=9",
        "--trials",
        "1",
        "--train-runs",
        "1",
        "--runs",
        "1",
        "--max-time-s",
        "5",
        "--no-progress",
    ]

    def cw_with(flag: str, v: str) -> list[str]:
        a = [*cw, "--out", "{d}/cw"]
        if flag in a:
            a[a.index(flag) + 1] = v
            return a
        return [*a, flag, v]

    for flag, vals in (
        ("--test-worlds", ["mazee1", "maze:seed=-1", "", "nonexistent.yaml"]),
        ("--train-worlds", ["mazee1", "maze:size_m=nan", ""]),
        ("--max-time-s", ["nan", "-1", "0", "inf"]),
        ("--trials", ["0", "-1", "100000000"]),
        ("--runs", ["0", "-1", "1000000000"]),
        ("--train-runs", ["0", "-1", "1000000000"]),
        ("--target-coverage", ["nan", "-1", "2", "0"]),
        ("--penalty-s", ["nan", "-1", "inf"]),
        ("--workers", ["0", "-1", "1000000"]),
        ("--test-seed0", ["-1"]),
        ("--train-seed0", ["-5"]),
        ("--seed", ["-1"]),
        ("--agents", ["semantic", "unknown", "sb3:{d}/missing.zip"]),
        ("--env-config", ["nosuchpreset", "{d}/missing.yaml"]),
    ):
        for v in vals:
            out.append(Case("cli", f"compare-weights{flag}={v[:20]}", cw_with(flag, v)))
    out.append(
        Case("cli", "compare-weights-out-file", [*cw, "--out", "{d}/f.txt"], {"f.txt": b"x"})
    )
    for a in (
        ["train", "--algo", "nope", "--out", "{d}/t"],
        ["train", "--out", "{d}/f.txt"],
        ["train", "--train-config", "{d}/missing.yaml", "--out", "{d}/t"],
        ["train", "--train-set", "foo.bar=1", "--out", "{d}/t"],
        ["train", "--train-set", "robot.radius_m=" + nested(3000), "--out", "{d}/t"],
    ):
        out.append(Case("cli", f"train-{' '.join(a[1:3])[:30]}", a, {"f.txt": b"x"}))
    for a in (
        ["nosuchcommand"],
        ["explore", "--nosuchflag"],
        ["segment"],
        ["show-world"],
        ["benchmark"],
        ["explore", "--world"],
        ["explore", "--max-time-s"],
    ):
        out.append(Case("cli", f"argparse-{' '.join(a)[:30]}", a))
    return out


def action_cases(rng: random.Random) -> list[Case]:
    import numpy as np

    bad = {
        "nan": [np.nan, 0.0],
        "inf": [np.inf, 0.0],
        "-inf": [0.0, -np.inf],
        "complex": [0.5 + 1j, 0.0],
        "complex-array": np.array([0.5 + 0j, 0.1]),
        "short": [0.5],
        "long": [0.1, 0.2, 0.3],
        "empty": [],
        "3x1": [[0.1], [0.2], [0.3]],
        "string": "go",
        "strings": ["a", "b"],
        "none": None,
        "dict": {"v": 1},
        "object": object(),
        "obj-array": np.array([None, None]),
        "nan-f32": np.array([np.nan, 0], np.float32),
        "bool-str": ["1", "0"],
        "scalar": 0.5,
        "set": {1, 2},
    }
    out = [Case("action", k, action=v) for k, v in bad.items()]
    for i in range(20):  # random non-finite positions and huge/odd dtypes
        a = [rng.uniform(-1, 1), rng.uniform(-1, 1)]
        a[rng.randrange(2)] = rng.choice([float("nan"), float("inf"), -float("inf")])
        out.append(Case("action", f"random-nonfinite-{i}", action=a))
    # Clipped to [-1, 1] or flattened (a (1, 2) or (2, 1) action): documented, accepted.
    for v in (
        [1e300, 0.0],
        [-5.0, 7.0],
        np.array([2, -2], np.int64),
        [True, False],
        [[0.1, 0.2]],
        [[0.1], [0.2]],
    ):
        out.append(Case("action", f"out-of-range-{v!r}"[:40], action=v, expect=ANY))
    return out


CATEGORIES = {
    "ros_map": ros_map_cases,
    "houseexpo": houseexpo_cases,
    "world": world_cases,
    "env_config": env_config_cases,
    "policy": policy_cases,
    "cli": cli_cases,
    "action": action_cases,
}


def generate_cases(seed: int = 0, categories: list[str] | None = None) -> list[Case]:
    """All cases, deterministic for ``seed``."""
    rng = random.Random(seed)
    out: list[Case] = []
    for name, fn in CATEGORIES.items():
        if categories and name not in categories:
            continue
        out.extend(fn(random.Random(rng.randrange(1 << 30))))
    return out


# --------------------------------------------------------------------------- running


def _child_cli(case: Case, d: str) -> int:
    from semexplore_gym.cli import main

    argv = [a.replace("{d}", d) for a in case.argv]
    try:
        return main(argv)
    except SystemExit as e:  # argparse
        return e.code if isinstance(e.code, int) else (0 if e.code is None else 1)


def _child_action(case: Case) -> int:
    import gymnasium as gym
    import numpy as np

    import semexplore_gym  # noqa: F401

    env = gym.make("SemanticExplore-v0", world="maze1")
    env.reset(seed=0)
    try:
        obs, reward, *_ = env.unwrapped.step(case.action)
    except (ValueError, TypeError) as e:
        print(f"error: {str(e)[:300]}", file=sys.stderr)
        return 2
    finite = np.isfinite(reward) and all(
        np.isfinite(np.asarray(v, dtype=np.float64)).all() for v in obs.values()
    )
    if not finite:
        print("non-finite observation or reward", file=sys.stderr)
        return 3
    return 0


def _run_child(case: Case, d: str, mem_bytes: int) -> None:
    """In the forked child: limit memory, redirect output, run, exit with the code."""
    os.setsid()
    resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))
    os.chdir(d)
    out_fd = os.open(os.path.join(d, ".stdout"), os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    err_fd = os.open(os.path.join(d, ".stderr"), os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(out_fd, 1)
    os.dup2(err_fd, 2)
    code = 99
    try:
        if case.category == "action":
            code = _child_action(case)
        else:
            code = _child_cli(case, d)
    except MemoryError:
        os.write(2, b"\nFUZZ-MEMORY-LIMIT\n")
        code = 98
    except BaseException:  # noqa: BLE001 - this is exactly what the fuzz looks for
        import traceback

        traceback.print_exc()
        code = 99
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    finally:
        os._exit(code if isinstance(code, int) and 0 <= code < 256 else 1)


@dataclass
class Result:
    case: Case
    outcome: str
    code: int | None
    seconds: float
    stderr_tail: str


def classify(case: Case, code: int | None, stderr: bytes, timed_out: bool) -> str:
    if timed_out or code == 98 or b"FUZZ-MEMORY-LIMIT" in stderr:
        return "hang"
    if b"Traceback (most recent call last)" in stderr or code == 99 or code is None or code < 0:
        return "traceback"
    if len(stderr) > MAX_STDERR_BYTES:
        return "traceback"  # a flood of output is no clean error either
    if code == 0:
        return "garbage" if case.expect == REJECT else "accepted"
    if case.category == "action" and code == 3:
        return "garbage"
    return "clean"


def run_case(case: Case, timeout_s: float, mem_bytes: int, root: str) -> Result:
    d = tempfile.mkdtemp(prefix="case", dir=root)
    for name, data in case.files.items():
        p = Path(d, name)
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(data)
    t0 = time.monotonic()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        _run_child(case, d, mem_bytes)
    timed_out = False
    code: int | None = None
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            code = os.waitstatus_to_exitcode(status)
            break
        if time.monotonic() - t0 > timeout_s:
            timed_out = True
            try:
                os.killpg(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            os.waitpid(pid, 0)
            break
        select.select([], [], [], 0.01)
    seconds = time.monotonic() - t0
    try:
        err = Path(d, ".stderr").read_bytes()
    except OSError:
        err = b""
    outcome = classify(case, code, err, timed_out)
    tail = err[-600:].decode("utf-8", "replace").strip()
    import shutil

    shutil.rmtree(d, ignore_errors=True)
    return Result(case, outcome, code, seconds, tail)


def warm_up() -> None:
    """Load the compiled kernels and run each subcommand once in this process, so that every
    forked case starts warm (a case's time is then its own, not numba's cache loading)."""
    import contextlib

    from semexplore_gym.cli import main

    with (
        tempfile.TemporaryDirectory() as d,
        contextlib.redirect_stdout(io.StringIO()),
        contextlib.redirect_stderr(io.StringIO()),
    ):
        main(["show-world", "maze1", "--out", f"{d}/w.png"])
        main(["segment", "maze:size_m=4", "--out", f"{d}/s.png"])
        for policy in ("random", "semantic", "frontier"):
            main(
                [
                    "explore",
                    "--world",
                    "maze1",
                    "--policy",
                    policy,
                    "--max-time-s",
                    "2",
                    "--no-progress",
                    "--gif",
                    f"{d}/a.gif",
                ]
            )


def run_cases(
    cases: list[Case],
    timeout_s: float = 60.0,
    mem_gb: float = 3.0,
    jobs: int = 1,
    progress: bool = False,
) -> list[Result]:
    """Run ``cases`` (``jobs`` at a time, each in its own forked child) and classify them."""
    import numpy  # noqa: F401  (import heavy modules once, before forking)

    import semexplore_gym  # noqa: F401
    import semexplore_gym.cli  # noqa: F401

    semexplore_gym.cli.build_parser()  # imports every subcommand module once
    warm_up()
    mem = int(mem_gb * (1 << 30))
    results: list[Result | None] = [None] * len(cases)
    with tempfile.TemporaryDirectory(prefix="semexplore-fuzz-") as root:
        if jobs <= 1:
            for i, c in enumerate(cases):
                results[i] = run_case(c, timeout_s, mem, root)
                if progress:
                    _progress(i + 1, len(cases), results[i])
        else:
            from concurrent.futures import ThreadPoolExecutor

            with ThreadPoolExecutor(jobs) as pool:
                futs = {
                    pool.submit(run_case, c, timeout_s, mem, root): i for i, c in enumerate(cases)
                }
                for n, f in enumerate(
                    __import__("concurrent.futures").futures.as_completed(futs), 1
                ):
                    results[futs[f]] = f.result()
                    if progress:
                        _progress(n, len(cases), results[futs[f]])
    return [r for r in results if r is not None]


def _progress(n: int, total: int, r: Result) -> None:
    flag = "" if r.outcome in ("clean", "accepted") else f"  <-- {r.outcome.upper()}"
    print(
        f"[{n}/{total}] {r.case.category}:{r.case.name[:60]} {r.outcome} {r.seconds:.1f}s{flag}",
        file=sys.stderr,
        flush=True,
    )


def table(results: list[Result]) -> str:
    """A markdown table: cases by category and outcome."""
    cats = sorted({r.case.category for r in results}, key=list(CATEGORIES).index)
    counts = Counter((r.case.category, r.outcome) for r in results)
    lines = [
        "| category | cases | clean error | traceback | hang | silent garbage | accepted (valid) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for c in [*cats, "total"]:
        pick = (
            (lambda o, c=c: counts[(c, o)])
            if c != "total"
            else (lambda o: sum(counts[(k, o)] for k in cats))
        )
        n = sum(pick(o) for o in OUTCOMES)
        lines.append(f"| {c} | {n} | " + " | ".join(str(pick(o)) for o in OUTCOMES) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=__doc__,
    )
    p.add_argument("--seed", type=int, default=0, help="case generation and sampling seed")
    p.add_argument(
        "--sample", type=int, default=None, help="run a seeded sample of this many cases"
    )
    p.add_argument(
        "--category", action="append", choices=list(CATEGORIES), help="only these (repeatable)"
    )
    p.add_argument("--jobs", type=int, default=2, help="cases in parallel (default: %(default)s)")
    p.add_argument("--timeout-s", type=float, default=60.0, help="per case (default: %(default)s)")
    p.add_argument("--mem-gb", type=float, default=3.0, help="address-space limit per case")
    p.add_argument("--list", action="store_true", help="print the cases and exit")
    p.add_argument("--show-failures", action="store_true", help="print every non-clean case")
    p.add_argument("--json", default=None, help="write every result to this JSON file")
    args = p.parse_args(argv)
    cases = generate_cases(args.seed, args.category)
    if args.sample is not None:
        cases = random.Random(args.seed).sample(cases, min(args.sample, len(cases)))
    if args.list:
        for c in cases:
            print(f"{c.category}\t{c.expect}\t{c.name}\t{' '.join(c.argv)[:200]}")
        print(f"{len(cases)} cases", file=sys.stderr)
        return 0
    t0 = time.monotonic()
    results = run_cases(cases, args.timeout_s, args.mem_gb, args.jobs, progress=True)
    bad = [r for r in results if r.outcome in ("traceback", "hang", "garbage")]
    if args.show_failures or bad:
        for r in bad:
            print(
                f"\n### {r.outcome}: {r.case.category}:{r.case.name} (exit {r.code}, {r.seconds:.1f}s)\n"
                f"argv: {' '.join(r.case.argv)[:300]}\n{r.stderr_tail[-400:]}"
            )
    if args.json:
        Path(args.json).write_text(
            json.dumps(
                [
                    {
                        "category": r.case.category,
                        "name": r.case.name,
                        "outcome": r.outcome,
                        "code": r.code,
                        "seconds": round(r.seconds, 2),
                        "stderr": r.stderr_tail[-300:],
                    }
                    for r in results
                ],
                indent=1,
            )
        )
    print()
    print(table(results))
    print(
        f"\n{len(results)} cases in {time.monotonic() - t0:.0f} s (seed {args.seed}, "
        f"timeout {args.timeout_s:g} s, {args.mem_gb:g} GB per case)"
    )
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
