"""Behaviour cloning of an SB3 policy on an :class:`ImitationDataset`.

:func:`train_bc` can mirror samples left-right, keep the best epoch by held-out action error
and decay the learning rate; ``scripts/bench_imitation.py`` compares a trained model with the
expert at the expert's own mission time on held-out worlds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from semexplore_gym.core.features.egocentric import EgocentricParams, mirror_observations
from semexplore_gym.training.dataset import ImitationDataset
from semexplore_gym.training.progress import with_progress
from semexplore_gym.training.train_config import BCSection


def _to_tensors(obs: dict[str, np.ndarray], idx: np.ndarray, device: Any) -> dict[str, Any]:
    import torch as th

    return {k: th.as_tensor(v[idx], device=device) for k, v in obs.items()}


def action_error(policy: Any, dataset: ImitationDataset, batch_size: int = 512) -> float:
    """Mean absolute difference between the policy's deterministic actions and the labels."""
    import torch as th

    if len(dataset) == 0:
        raise ValueError("action_error needs a non-empty dataset")
    policy.set_training_mode(False)
    errs = []
    with th.no_grad():
        for start in range(0, len(dataset), batch_size):
            idx = np.arange(start, min(start + batch_size, len(dataset)))
            dist = policy.get_distribution(_to_tensors(dataset.obs, idx, policy.device))
            act = dist.get_actions(deterministic=True).cpu().numpy()
            errs.append(np.abs(np.clip(act, -1, 1) - dataset.actions[idx]).mean(axis=1))
    return float(np.concatenate(errs).mean())


def _mirror_half(
    obs: dict[str, np.ndarray],
    actions: np.ndarray,
    params: EgocentricParams,
    rng: np.random.Generator,
) -> None:
    """Replace each sample of a minibatch by its left-right mirror image with probability 1/2."""
    flip = rng.random(len(actions)) < 0.5
    if flip.any():
        m_obs, m_act = mirror_observations(
            {k: v[flip] for k, v in obs.items()}, actions[flip], params
        )
        for k in obs:
            obs[k][flip] = m_obs[k]
        actions[flip] = m_act


def _fit_epoch(
    dataset: ImitationDataset,
    policy: Any,
    optimizer: Any,
    bc: BCSection,
    rng: np.random.Generator,
    mirror_params: EgocentricParams | None,
) -> np.ndarray:
    """One pass over ``dataset`` in shuffled minibatches; the mean loss, neglogp, entropy."""
    import torch as th

    policy.set_training_mode(True)
    order = rng.permutation(len(dataset))
    sums = np.zeros(3)
    for start in range(0, len(order), bc.batch_size):
        idx = np.sort(order[start : start + bc.batch_size])  # sorted: faster gathers
        obs_b = {k: v[idx] for k, v in dataset.obs.items()}
        act_b = dataset.actions[idx]
        if mirror_params is not None:
            _mirror_half(obs_b, act_b, mirror_params, rng)
        _values, log_prob, entropy = policy.evaluate_actions(
            {k: th.as_tensor(v, device=policy.device) for k, v in obs_b.items()},
            th.as_tensor(act_b, device=policy.device),
        )
        neglogp = -log_prob.mean()
        ent = entropy.mean() if entropy is not None else th.zeros(())
        loss = neglogp - bc.ent_weight * ent
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()
        sums += np.array([loss.item(), neglogp.item(), ent.item()]) * len(idx)
    return sums / len(order)


def train_bc(
    dataset: ImitationDataset,
    policy: Any,
    bc: BCSection | None = None,
    *,
    seed: int = 0,
    eval_data: ImitationDataset | None = None,
    egocentric: EgocentricParams | None = None,
    progress: bool = False,
    log_fn: Callable[[str, float, int], None] | None = None,
) -> dict[str, list[float]]:
    """Behaviour cloning: minimise ``-log pi(a_expert | o) - ent_weight * entropy`` with Adam.

    Args:
        dataset: Egocentric observations and expert actions.
        policy: An SB3 ``ActorCriticPolicy`` (changed in place).
        bc: The settings (:class:`~semexplore_gym.training.train_config.BCSection`; None: defaults).
        seed: Seeds the minibatch order (numpy Generator) and torch.
        eval_data: Held-out samples; their :func:`action_error` is recorded after each epoch.
        egocentric: The data's egocentric parameters (needed by ``bc.mirror``).
        progress: Show a tqdm bar over epochs.
        log_fn: ``log_fn(tag, value, epoch)`` for per-epoch scalars.

    Returns:
        ``{"loss": [...], "neglogp": [...], "entropy": [...]}`` one value per epoch, plus
        ``"eval_action_error"`` when ``eval_data`` is given (and ``"best_epoch"``, a
        one-element list, when ``select_best`` restored a checkpoint).
    """
    import copy

    import torch as th

    bc = bc if bc is not None else BCSection()
    if len(dataset) == 0:
        raise ValueError("train_bc needs a non-empty dataset")
    if bc.mirror and egocentric is None:
        raise ValueError("bc.mirror needs the data's egocentric parameters (egocentric=...)")
    epochs, batch_size, lr, lr_final_fraction = (
        bc.epochs,
        bc.batch_size,
        bc.lr,
        bc.lr_final_fraction,
    )
    mirror_params = egocentric if bc.mirror else None
    if not 0.0 < lr_final_fraction <= 1.0:
        raise ValueError(f"lr_final_fraction must be in (0, 1], got {lr_final_fraction!r}")
    if epochs < 1 or batch_size < 1 or not lr > 0:
        raise ValueError(
            f"epochs, batch_size and lr must be positive, got {epochs}, {batch_size}, {lr}"
        )
    th.manual_seed(seed)
    rng = np.random.default_rng(seed)
    optimizer = th.optim.Adam(policy.parameters(), lr=lr, weight_decay=bc.l2_weight)
    history: dict[str, list[float]] = {"loss": [], "neglogp": [], "entropy": []}
    best_err, best_state, best_epoch = math.inf, None, -1
    for epoch in with_progress(range(epochs), progress, "BC epochs"):
        frac = 0.5 * (1.0 + math.cos(math.pi * epoch / max(1, epochs - 1))) if epochs > 1 else 1.0
        for group in optimizer.param_groups:
            group["lr"] = lr * (lr_final_fraction + (1.0 - lr_final_fraction) * frac)
        means = _fit_epoch(dataset, policy, optimizer, bc, rng, mirror_params)
        for k, v in zip(("loss", "neglogp", "entropy"), means, strict=True):
            history[k].append(float(v))
            if log_fn is not None:
                log_fn(f"bc/{k}", float(v), epoch)
        if eval_data is not None and len(eval_data):
            err = action_error(policy, eval_data)
            history.setdefault("eval_action_error", []).append(err)
            if log_fn is not None:
                log_fn("bc/eval_action_error", err, epoch)
            if bc.select_best and err < best_err:
                best_err, best_epoch = err, epoch
                best_state = copy.deepcopy(policy.state_dict())
    if best_state is not None:
        policy.load_state_dict(best_state)
        history["best_epoch"] = [float(best_epoch)]
    policy.set_training_mode(False)
    return history
