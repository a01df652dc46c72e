"""Bit-exact pins of :meth:`EgocentricEncoder.encode` over recorded random walks.

The pins (sha256 over every step's ``image``, ``scan`` and ``features`` bytes) were generated
with the straightforward encoder (one crop per channel, the frontier field recomputed at every
step), before it was fused and made incremental; any faster encoder must reproduce them bit for
bit. The raw observations are pinned too, so a change of the env's dynamics or maps fails
with its own message (regenerate the pins with an encoder known to be right:
``python tests/core/features/test_egocentric_pins.py``).
"""

from __future__ import annotations

import hashlib
import sys

import numpy as np
import pytest

from semexplore_gym.core.features.egocentric import EgocentricEncoder, EgocentricParams

ALL = ("occupancy", "frontier_distance", "trail")
#: Settings pinned: the training configs' (all channels, centred bins), the defaults, a coarse
#: crop (3 x 3 samples per crop cell) and the map's own resolution (one sample).
SETTINGS: dict[str, EgocentricParams] = {
    "train": EgocentricParams(n_scan_bins=72, scan_bins_centred=True, channels=ALL),
    "default": EgocentricParams(),
    "coarse": EgocentricParams(crop_cells=36, crop_resolution_m=0.15, channels=ALL[::-1]),
    "native": EgocentricParams(
        crop_cells=48, crop_resolution_m=None, channels=("frontier_distance", "trail"),
        frontier_clearance_m=0.0, trail_radius_m=0.25,
    ),
}  # fmt: skip
WORLDS = {"maze1": 300, "cave:seed=1": 300}

PINS: dict[str, dict[str, str]] = {
    "maze1": {
        "raw": "63d597af9a1c86f0cc70800447e82f487b1ee0d6e2c856d519bc0f04da76466a",
        "train.image": "cb223eb349796097690268e814d49b68cea0d1890a563860aec445239b1b187e",
        "train.scan": "9cb8570fc24a115795de3f366a05a2f58b2b4601eed5f540874d0f630e353a8f",
        "train.features": "b84a59094f9dcd58d69384ad59ca700a18f990c2fe76bf33ce0c1ad1a946a084",
        "default.image": "ee71d84f713a6a53ea71b8cded2e59e516959a845463c7c5279b556abe875cc3",
        "default.scan": "7dd3f6cc28996f3f98dcd3ac22a8027001207fac49475acd20acde1df7d0236a",
        "default.features": "a4624c6c483f22929469fd43758dc9e2ee6ca02aa1b0d737c13576a81aa0ca80",
        "coarse.image": "8cf8e5c1669f0538d0f5422a5b056ead1c3ae882f1a8fb7ad6c94943c92c7115",
        "coarse.scan": "7dd3f6cc28996f3f98dcd3ac22a8027001207fac49475acd20acde1df7d0236a",
        "coarse.features": "e511e8ba2f75129d18eddec60f6ba1d5890a8554ab2038fe67b5fc82595099b1",
        "native.image": "e87059b069320cf1f936a500ada8dcc95fae81a8ce705fd14678f74044a5615c",
        "native.scan": "7dd3f6cc28996f3f98dcd3ac22a8027001207fac49475acd20acde1df7d0236a",
        "native.features": "c73b796fb3051e5dca9f352f0a6ea889e2c9dbe516125d3fc6d4fdd9c529dea7",
    },
    "cave:seed=1": {
        "raw": "0ac19c32e140230db02286ddd394accaf9f51201766c123e1456001b7b4fc38a",
        "train.image": "f19baf641adc441ee250ade478aecf5a992b13a2365c51f09be85e0a8b8024f2",
        "train.scan": "6a1cfcc83467683cf9bf558f29c966f0be473538530cb5bcceb039717dadd752",
        "train.features": "71f6bf1d4e4d0b0fb9a51bd26864550eeea509e81c863961379303e4f1d45e88",
        "default.image": "b510dd9b0147485c73c7629e9306e90864eeac04954411ea26783e629bbf8706",
        "default.scan": "c91fea5bd87a76a0ad81c8f0158f0f790ac322b06db1a42e074dd139c17e661e",
        "default.features": "c2d00a8768ce7293ff26a1bc00d91162a762424b0b3ef5bff650ee5d66776a49",
        "coarse.image": "74d3d032bffec1d7e14e582af6f672872c65597482abd9711df6c8fc1e0bbe61",
        "coarse.scan": "c91fea5bd87a76a0ad81c8f0158f0f790ac322b06db1a42e074dd139c17e661e",
        "coarse.features": "320da0a3532141a6dec838d4d100a96deb69f94696d3e8ca8179eba9665c45f8",
        "native.image": "c375484d8719e6cce7d271827d92436d3f7479034d1e78a09455e57690d42794",
        "native.scan": "c91fea5bd87a76a0ad81c8f0158f0f790ac322b06db1a42e074dd139c17e661e",
        "native.features": "fb39518156d1f3d18365aa9bbd7dfaccc25a53c2253e822bbbd04d74185f4046",
    },
}


def _walk(world: str, n_steps: int) -> tuple[list[dict[str, np.ndarray]], list[bool], dict]:
    """Raw observations of a seeded random walk; ``starts[i]`` marks an episode's first step."""
    import gymnasium as gym

    import semexplore_gym  # noqa: F401

    env = gym.make("SemanticExplore-v0", world=world)
    obs, info = env.reset(seed=0)
    rng = np.random.default_rng(0)
    raws, starts, start = [], [], True
    for _ in range(n_steps):
        raws.append({k: np.array(v, copy=True) for k, v in obs.items()})
        starts.append(start)
        action = np.array([rng.uniform(-0.2, 1.0), rng.uniform(-1.0, 1.0)], np.float32)
        obs, _r, terminated, truncated, info = env.step(action)
        start = terminated or truncated
        if start:
            obs, info = env.reset()
    env.close()
    return raws, starts, info


def _digests(world: str, n_steps: int) -> dict[str, str]:
    raws, starts, info = _walk(world, n_steps)
    h = hashlib.sha256()
    for raw in raws:
        for k in sorted(raw):
            h.update(k.encode())
            h.update(np.ascontiguousarray(raw[k]).tobytes())
    out = {"raw": h.hexdigest()}
    for name, params in SETTINGS.items():
        enc = EgocentricEncoder.from_info(params, info)
        hs = {k: hashlib.sha256() for k in ("image", "scan", "features")}
        for raw, start in zip(raws, starts, strict=True):
            if start:
                enc.reset()
            f = enc.encode(raw)
            for k, hk in hs.items():
                a = f[k]
                hk.update(f"{a.dtype}{a.shape}".encode())
                hk.update(np.ascontiguousarray(a).tobytes())
        out.update({f"{name}.{k}": hk.hexdigest() for k, hk in hs.items()})
    return out


@pytest.mark.parametrize("world", list(WORLDS))
def test_encode_matches_the_pinned_outputs(world: str) -> None:
    got = _digests(world, WORLDS[world])
    want = PINS[world]
    if got["raw"] != want["raw"]:
        pytest.fail(
            f"the random walk on {world} no longer gives the recorded observations (the env "
            "changed): regenerate the pins with an encoder known to be right"
        )
    bad = sorted(k for k in want if got[k] != want[k])
    assert not bad, f"egocentric outputs differ from the pins on {world}: {bad}"


if __name__ == "__main__":
    for w, n in WORLDS.items():
        print(f"    {w!r}: {{")
        for k, v in _digests(w, n).items():
            print(f"        {k!r}: {v!r},")
        print("    },")
    sys.exit(0)
