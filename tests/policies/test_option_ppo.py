"""The option actor-critic: the actor ignores the privileged input, scores options as a set."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("sb3_contrib")

import torch as th  # noqa: E402
from gymnasium import spaces  # noqa: E402
from semexplore_gym.policies.option_ppo import option_network_classes  # noqa: E402

from semexplore_gym.core.features.frontier_option_features import OPTION_FEATURE_NAMES  # noqa: E402

N, K = 5, len(OPTION_FEATURE_NAMES)


def _space(privileged: bool) -> spaces.Dict:
    d = {
        "options": spaces.Box(-5.0, 5.0, (N, K), np.float32),
        "valid": spaces.Box(0.0, 1.0, (N,), np.float32),
        "global": spaces.Box(0.0, 1.0, (3,), np.float32),
    }
    if privileged:
        d["privileged"] = spaces.Box(0.0, np.inf, (N + 1, 2), np.float32)
    return spaces.Dict(d)


def _policy(privileged: bool = True) -> object:
    cls = option_network_classes()["OptionActorCriticPolicy"]
    th.manual_seed(0)
    return cls(_space(privileged), spaces.Discrete(N), lambda _: 1e-3, hidden=16)


def _obs(b: int, rng: np.random.Generator, privileged: bool = True) -> dict[str, th.Tensor]:
    valid = np.ones((b, N), dtype=np.float32)
    valid[:, 3:] = 0.0
    opts = rng.normal(size=(b, N, K)).astype(np.float32) * valid[:, :, None]
    out = {
        "options": th.as_tensor(opts),
        "valid": th.as_tensor(valid),
        "global": th.as_tensor(rng.random((b, 3), dtype=np.float32)),
    }
    if privileged:
        out["privileged"] = th.as_tensor(rng.random((b, N + 1, 2), dtype=np.float32))
    return out


def test_actor_output_does_not_depend_on_privileged_input() -> None:
    policy = _policy()
    rng = np.random.default_rng(0)
    obs = _obs(4, rng)
    other = dict(obs, privileged=obs["privileged"] * 7.0 + 3.0)
    with th.no_grad():
        a = policy.get_distribution(obs).distribution.logits
        b = policy.get_distribution(other).distribution.logits
        va, vb = policy.predict_values(obs), policy.predict_values(other)
    assert th.equal(a, b)
    assert not th.allclose(va, vb)  # the critic does read it


def test_actor_scores_options_as_a_set() -> None:
    policy = _policy()
    obs = _obs(1, np.random.default_rng(1))
    perm = th.tensor([2, 0, 1, 3, 4])
    swapped = dict(obs, options=obs["options"][:, perm])
    with th.no_grad():
        a = policy.mlp_extractor.forward_actor(policy.extract_features(obs))
        b = policy.mlp_extractor.forward_actor(policy.extract_features(swapped))
    assert th.allclose(a[:, perm], b, atol=1e-6)
    assert (a[:, 3:] < -1e7).all()  # padding rows are never chosen


def test_bc_warm_start_fits_a_tiny_dataset() -> None:
    from semexplore_gym.training.option_ppo import fit_bc

    policy = _policy()
    rng = np.random.default_rng(2)
    obs = _obs(48, rng)
    # The label: the valid row with the largest first feature (a rule the actor can learn).
    label = obs["options"][:, :3, 0].argmax(1).numpy()
    data = {k: v.numpy() for k, v in obs.items()}
    data["label"] = label.astype(np.int64)
    data["return"] = rng.normal(size=48).astype(np.float32)
    with th.no_grad():
        before = policy.mlp_extractor.forward_actor(policy.extract_features(obs)).argmax(1)
    agree0 = float((before.numpy() == label).mean())
    out = fit_bc(policy, data, epochs=150, lr=3e-3)
    assert out["bc_agree"] >= 0.9 > agree0 + 0.2


def test_policy_saves_and_loads_by_reference(tmp_path: object) -> None:
    from sb3_contrib import MaskablePPO
    from semexplore_gym.policies.option_ppo import load_option_model

    env = _fake_env()
    model = MaskablePPO(option_network_classes()["OptionActorCriticPolicy"], env, n_steps=8,
                        batch_size=8, policy_kwargs={"hidden": 8}, device="cpu")  # fmt: skip
    path = tmp_path / "m.zip"  # type: ignore[operator]
    model.save(str(path))
    back = load_option_model(path)
    assert back.policy.mlp_extractor.hidden == 8
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_option_model(tmp_path / "none.zip")  # type: ignore[operator]


def _fake_env() -> object:
    import gymnasium as gym

    class E(gym.Env):  # type: ignore[type-arg]
        observation_space = _space(True)
        action_space = spaces.Discrete(N)

        def reset(self, *, seed: int | None = None, options: object = None) -> object:
            return self.observation_space.sample(), {}

        def step(self, action: object) -> object:
            return self.observation_space.sample(), 0.0, True, False, {}

        def action_masks(self) -> np.ndarray:
            return np.ones(N, dtype=bool)

    return E()
