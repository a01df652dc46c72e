"""A drop-in :class:`gymnasium.vector.SyncVectorEnv` that batches results with less overhead.

gymnasium's ``SyncVectorEnv`` spends a large share of a fast env's step on bookkeeping: per
step and env it merges every ``info`` key (allocating a fresh mask array each time), stacks
each observation key through its generic ``concatenate``, and deep-copies the batch. With
``SemanticExplore-v0`` on maze1 (about 70-100 µs per env step) that is 25-30 % of the time.
:class:`FastSyncVectorEnv` returns exactly what ``SyncVectorEnv`` returns (same observations,
rewards, flags, ``info`` arrays and ``_key`` masks, same autoreset behaviour) but

* merges the ``info`` of all envs key by key at the end of the step, building each key's
  array and mask in one call when every env has the key;
* writes ``Dict``-of-``Box`` observations into the batch buffers directly, and copies them
  with one ``ndarray.copy`` per key when ``copy=True`` (instead of ``deepcopy``);
* steps ``SemanticExplore-v0`` envs directly when nothing but ``gym.make``'s own wrappers
  (``OrderEnforcing``, ``PassiveEnvChecker``, which only check the first calls) wraps them
  and their observation is the whole map: after those first checks, each step advances the
  env itself, writes its pose and scan into the batch row (no per-env observation dict) and
  its ``info`` numbers into one array per key. The map is not copied at all: each env's grid
  keeps its cells in the env's row of the batch (``OccupancyGrid.keep_encoded_in``), so with
  ``copy=False`` the returned batch's ``map`` is read-only (writing into it would change the
  envs' maps; ``copy=True`` returns copies, as usual). Steps in which an env resets, and
  ``AutoresetMode.SAME_STEP``, take the general path. The env's public fast-path methods
  (``advance``, ``write_obs_into``, ``info_numbers``, ``static_info_entries``, ``step_info``;
  see ``SemanticExploreEnv.advance``) are what this path calls: they and ``step()`` change
  together.

Other observation spaces fall back to gymnasium's ``concatenate``/``deepcopy``. Use it like
``SyncVectorEnv``::

    from semexplore_gym.envs.observation_options import ObservationOptions
    from semexplore_gym.envs.vector import FastSyncVectorEnv
    options = ObservationOptions(static_info="reset")
    venv = FastSyncVectorEnv(
        [lambda: gym.make("SemanticExplore-v0", observation_options=options)] * 4
    )

``AsyncVectorEnv`` runs each env in a worker process: it pays off only with a free core per
worker and env steps long enough (hundreds of µs, e.g. large real maps) to hide the
inter-process messaging; on a busy 2-core machine it is slower than a plain loop.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from copy import deepcopy
from typing import Any, cast

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, SyncVectorEnv
from gymnasium.vector.utils import concatenate, iterate
from gymnasium.wrappers import OrderEnforcing, PassiveEnvChecker

from semexplore_gym.envs.semantic_explore import INFO_NUMBERS, SemanticExploreEnv

_SCALAR_TYPES = (int, float, bool)
#: The number types of ``INFO_NUMBERS`` (``collisions`` counts, the rest are floats).
_INFO_TYPES = tuple(int if k == "collisions" else float for k in INFO_NUMBERS)


def _direct_target(env: Any) -> tuple[SemanticExploreEnv, list[Any]] | None:
    """``(SemanticExploreEnv, wrappers)`` when stepping the env itself can stand in for
    ``env.step``: only gymnasium's ``OrderEnforcing`` and ``PassiveEnvChecker`` (what
    ``gym.make`` adds) wrap it, and its observation is the whole map (``"copy"``/``"shared"``)
    without human rendering. Otherwise None."""
    wrappers = []
    while isinstance(env, gym.Wrapper):
        if type(env) not in (OrderEnforcing, PassiveEnvChecker):
            return None
        wrappers.append(env)
        env = env.env
    if type(env) is not SemanticExploreEnv:  # a subclass may step differently
        return None
    if env.map_observation not in ("copy", "shared") or env.render_mode == "human":
        return None
    return env, wrappers


def _wrappers_done(wrappers: list[Any]) -> bool:
    """Whether the wrappers now only pass ``step`` through (checks done, env reset)."""
    for w in wrappers:
        if isinstance(w, PassiveEnvChecker):
            if not (w.checked_step and w.checked_data_reuse):
                return False
        elif not w._has_reset:
            return False
    return True


class FastSyncVectorEnv(SyncVectorEnv):
    """:class:`gymnasium.vector.SyncVectorEnv` with cheaper batching (same results).

    Takes the same arguments as ``SyncVectorEnv``.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        space = self.single_observation_space
        self._box_keys: tuple[str, ...] | None = None
        if isinstance(space, spaces.Dict) and all(
            isinstance(s, spaces.Box) for s in space.spaces.values()
        ):
            self._box_keys = tuple(space.spaces)
        # The direct path: every env a SemanticExploreEnv under gym.make's two wrappers, the
        # batch a dict of map, pose and scan, all with static_info alike. It starts once the
        # wrappers are done with their first-step checks (see _direct_step).
        targets = [_direct_target(env) for env in self.envs]
        self._direct: list[SemanticExploreEnv] | None = None
        self._direct_wrappers: list[list[Any]] = []
        if (
            all(t is not None for t in targets)
            and self._box_keys is not None
            and set(self._box_keys) == {"map", "pose", "scan"}
            and len({t[0].static_info for t in targets if t is not None}) == 1
        ):
            self._direct_candidates = [t[0] for t in targets if t is not None]
            self._direct_wrappers = [t[1] for t in targets if t is not None]
        else:
            self._direct_candidates = []
        self._static_merged: dict[str, Any] | None = None
        self._info_layout: list[tuple[str, str, type]] | None = None
        self._env_obs_stale = False
        self._no_pending_reset = False  # no direct step before the first reset
        # Direct steps keep each env's map in its batch row (see _map_rows_of_batch).
        self._map_rows: list[np.ndarray] = []
        self._map_batch: np.ndarray | None = None
        self._read_only_batch: dict[str, np.ndarray] = {}

    def _merge_infos(self, entries: list[tuple[int, dict[str, Any]]]) -> dict[str, Any]:
        """gymnasium's merge of ``(env index, info)`` pairs, one key at a time (same arrays)."""
        n = self.num_envs
        if len(entries) == n:
            fast = self._merge_same_keys([info for _, info in entries])
            if fast is not None:
                return fast
        by_key: dict[str, list[tuple[int, Any]]] = {}
        for i, info in entries:
            for key, value in info.items():
                by_key.setdefault(key, []).append((i, value))
        out: dict[str, Any] = {}
        for key, items in by_key.items():
            first = items[0][1]
            nested = key != "final_obs" and isinstance(first, dict)
            if any((key != "final_obs" and isinstance(v, dict)) != nested for _, v in items):
                for i, v in items:  # mixed kinds: gymnasium's own merge, entry by entry
                    out = super()._add_info(out, {key: v}, i)
                continue
            if nested:
                array: Any = self._merge_infos(items)
            else:
                array = self._base_array(key, first, items)
            if len(items) == n:
                mask = np.ones(n, dtype=np.bool_)
            else:
                mask = np.zeros(n, dtype=np.bool_)
                mask[[i for i, _ in items]] = True
            out[key] = array
            out[f"_{key}"] = mask
        return out

    def _merge_same_keys(self, infos: list[dict[str, Any]]) -> dict[str, Any] | None:
        """The common case: every env gives the same keys with values of one type each.

        Returns None when that does not hold (the caller then merges entry by entry).
        """
        first = infos[0]
        keys = first.keys()
        for info in infos:
            if info.keys() != keys:
                return None
        out: dict[str, Any] = {}
        ones = np.ones(len(infos), dtype=np.bool_)
        for key, v0 in first.items():
            col = [info[key] for info in infos]
            kind = type(v0)
            if key == "final_obs" or any(type(v) is not kind for v in col):
                return None
            if isinstance(v0, dict):
                array: Any = self._merge_same_keys(col)
                if array is None:
                    return None
            elif kind in _SCALAR_TYPES or issubclass(kind, np.number):
                array = np.array(col, dtype=kind)
            elif isinstance(v0, np.ndarray):
                return None
            else:
                array = np.empty(len(col), dtype=object)
                for i, v in enumerate(col):
                    array[i] = v
            out[key] = array
            out[f"_{key}"] = ones.copy()
        return out

    def _base_array(self, key: str, first: Any, items: list[tuple[int, Any]]) -> np.ndarray:
        n = self.num_envs
        kind = type(first)
        if key != "final_obs" and (kind in _SCALAR_TYPES or issubclass(kind, np.number)):
            if len(items) == n:
                return np.array([v for _, v in items], dtype=kind)
            array = np.zeros(n, dtype=kind)
        elif key != "final_obs" and isinstance(first, np.ndarray):
            array = np.zeros((n, *first.shape), dtype=first.dtype)
        else:
            array = np.full(n, fill_value=None, dtype=object)
        for i, v in items:
            array[i] = v
        return array

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict]:
        """Step every env; the same results as ``SyncVectorEnv.step``."""
        mode = self.autoreset_mode
        if (
            self._no_pending_reset
            and self._direct_candidates
            and mode != AutoresetMode.SAME_STEP
            and (self._direct is not None or self._direct_ready())
        ):
            return self._direct_step(actions)
        entries: list[tuple[int, dict[str, Any]]] = []
        for i, (action, env) in enumerate(
            zip(iterate(self.action_space, actions), self.envs, strict=True)
        ):
            if mode == AutoresetMode.NEXT_STEP and self._autoreset_envs[i]:
                self._env_obs[i], env_info = env.reset()
                self._rewards[i] = 0.0
                self._terminations[i] = False
                self._truncations[i] = False
            elif mode in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
                (
                    self._env_obs[i],
                    self._rewards[i],
                    self._terminations[i],
                    self._truncations[i],
                    env_info,
                ) = env.step(action)
                if mode == AutoresetMode.SAME_STEP and (
                    self._terminations[i] or self._truncations[i]
                ):
                    entries.append((i, {"final_obs": self._env_obs[i], "final_info": env_info}))
                    self._env_obs[i], env_info = env.reset()
            elif mode == AutoresetMode.DISABLED:
                assert not self._autoreset_envs[i], f"{self._autoreset_envs=}"
                (
                    self._env_obs[i],
                    self._rewards[i],
                    self._terminations[i],
                    self._truncations[i],
                    env_info,
                ) = env.step(action)
            else:
                raise ValueError(f"Unexpected autoreset mode, {mode}")
            entries.append((i, env_info))
        obs = self._returned(self._batch_observations())
        self._autoreset_envs = np.logical_or(self._terminations, self._truncations)
        self._no_pending_reset = not self._autoreset_envs.any()
        return (
            obs,
            np.copy(self._rewards),
            np.copy(self._terminations),
            np.copy(self._truncations),
            self._merge_infos(entries),
        )

    def _direct_ready(self) -> bool:
        if not all(_wrappers_done(ws) for ws in self._direct_wrappers):
            return False
        self._direct = self._direct_candidates
        return True

    def _direct_step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict]:
        """A step without autoresets over envs stepped directly (what their wrappers' ``step``
        would do once their checks are done): observations written into the batch, the
        ``info`` numbers into one array per key. The same results as the general path.

        Rewards and flags go straight into fresh arrays (gymnasium's step copies its buffers
        ``_rewards``, ``_terminations``, ``_truncations`` to return them; only its general
        path writes them, before reading them in the same step)."""
        envs = cast(list[SemanticExploreEnv], self._direct)
        self._env_obs_stale = True
        batch = cast(dict, self._observations)
        map_rows = self._map_rows_of_batch(batch)
        rewards: list[float] = []
        values: list[Any] = []  # each env's info numbers and reward terms, env after env
        all_terms = []
        ended: list[tuple[int, bool, bool]] = []
        # A batch of actions as an array: its rows (what iterate() yields for a Box space).
        plain = type(actions) is np.ndarray and actions.shape == self.action_space.shape
        for i, (action, env) in enumerate(
            zip(actions if plain else iterate(self.action_space, actions), envs, strict=True)
        ):
            reward, term, trunc, terms = env.advance(action)
            rewards.append(reward)
            if term or trunc:
                ended.append((i, term, trunc))
            env.write_obs_into(batch, i, map_rows[i])
            values += env.info_numbers()
            values += terms.values()
            all_terms.append(terms)
        n = self.num_envs
        terminations = np.zeros(n, dtype=np.bool_)
        truncations = np.zeros(n, dtype=np.bool_)
        for i, term, trunc in ended:
            terminations[i] = term
            truncations[i] = trunc
        # Its own array: a partial reset clears entries of it in place.
        self._autoreset_envs = terminations | truncations if ended else np.zeros(n, np.bool_)
        self._no_pending_reset = not ended
        obs = {key: batch[key].copy() for key in batch} if self.copy else self._read_only_batch
        if self._info_layout is None:
            self._info_layout = self._direct_layout(envs, values, all_terms)
        if self._info_layout:
            info = self._direct_info(envs[0].static_info == "every_step", values)
        else:  # numbers of unusual types: gymnasium's own merge rules
            pairs = zip(envs, all_terms, strict=True)
            info = self._merge_infos([(i, env.step_info(t)) for i, (env, t) in enumerate(pairs)])
        return obs, np.array(rewards, dtype=np.float64), terminations, truncations, info

    def _direct_layout(
        self,
        envs: list[SemanticExploreEnv],
        values: list[Any],
        all_terms: list[dict[str, float]],
    ) -> list[tuple[str, str, type]]:
        """The keys, mask keys and number types of a direct step's ``info`` (checked once:
        the config fixes them), or ``[]`` when they are not the usual ones (then every step
        merges as gymnasium does). ``values`` holds each env's numbers, env after env."""
        keys = [*INFO_NUMBERS, *all_terms[0]]
        types = [*_INFO_TYPES, *(float for _ in all_terms[0])]
        width = len(keys)
        usual = len(values) == width * len(envs) and all(
            list(map(type, values[i * width : (i + 1) * width])) == types
            and list(terms) == keys[len(INFO_NUMBERS) :]
            for i, terms in enumerate(all_terms)
        )
        if usual and envs[0].static_info == "every_step":
            self._static_merged = self._merge_same_keys([env.static_info_entries() for env in envs])
            usual = self._static_merged is not None
        return [(k, "_" + k, t) for k, t in zip(keys, types, strict=True)] if usual else []

    def _direct_info(self, static: bool, values: list[Any]) -> dict[str, Any]:
        """gymnasium's merged ``info`` of a direct step from each env's numbers (usual types,
        env after env in ``values``)."""
        layout = cast(list, self._info_layout)
        n = self.num_envs
        out: dict[str, Any] = {}
        if static:
            out = {k: v.copy() for k, v in cast(dict, self._static_merged).items()}
        # Each key's array (and mask) is a row of one fresh block: contiguous, its own values.
        block = np.array(values, dtype=np.float64).reshape(n, len(layout)).T.copy()
        masks = np.ones((len(layout) + 1, n), dtype=np.bool_)
        n_info = len(INFO_NUMBERS)
        nested: dict[str, Any] = {}
        for k, (key, mask_key, typ) in enumerate(layout):
            d = out if k < n_info else nested
            d[key] = block[k] if typ is float else block[k].astype(typ)
            d[mask_key] = masks[k]
        out["reward_terms"] = nested
        out["_reward_terms"] = masks[-1]
        return out

    def _map_rows_of_batch(self, batch: dict[str, np.ndarray]) -> list[np.ndarray]:
        """The batch's map rows, one view object per env (the same objects every step).

        Direct steps hand each env its row and the env's grid keeps its cells there, so the
        map is never copied into the batch. With ``copy=False`` the batch is then returned
        with a read-only map (writing into it would change the envs' maps)."""
        maps = batch["map"]
        if maps is not self._map_batch:
            self._map_batch = maps
            self._map_rows = list(maps)
            read_only = maps.view()
            read_only.flags.writeable = False
            self._read_only_batch = {**batch, "map": read_only}
        return self._map_rows

    def _returned(self, obs: Any) -> Any:
        """What a step or reset returns: with ``copy=False`` and envs that direct steps put
        into the batch (from the first reset on, so that no writable handle to the batch is
        ever out), the batch with its read-only map."""
        if (
            obs is self._observations
            and self._direct_candidates
            and self.autoreset_mode != AutoresetMode.SAME_STEP
        ):
            self._map_rows_of_batch(cast(dict, obs))
            return self._read_only_batch
        return obs

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        """``SyncVectorEnv.reset``; after direct steps, first brings each env's last
        observation up to date (a partial reset batches the others' as they are)."""
        if self._env_obs_stale:
            for i, env in enumerate(cast(list[SemanticExploreEnv], self._direct)):
                cast(list, self._env_obs)[i] = env._obs()
            self._env_obs_stale = False
        obs, info = super().reset(**kwargs)
        self._no_pending_reset = not self._autoreset_envs.any()
        return self._returned(obs), info

    def _batch_observations(self) -> Any:
        keys = self._box_keys
        if keys is None or not isinstance(self._observations, dict):
            self._observations = concatenate(
                self.single_observation_space, self._env_obs, self._observations
            )
            return deepcopy(self._observations) if self.copy else self._observations
        batch = self._observations
        for key in keys:
            buf = batch[key]
            for i, obs in enumerate(self._env_obs):
                buf[i] = cast(dict, obs)[key]
        if self.copy:
            return {key: batch[key].copy() for key in keys}
        return batch


def make_vector_env(
    num_envs: int = 1,
    *,
    copy: bool = True,
    autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP,
    max_episode_steps: int | None = None,
    env_id: str = "SemanticExplore-v0",
    wrappers: Sequence[Callable[[gym.Env], gym.Env]] = (),
    **env_kwargs: Any,
) -> FastSyncVectorEnv:
    """``gym.make_vec("SemanticExplore-v0", num_envs=4, ...)``: the registered vector entry point.

    ``num_envs`` copies of ``gym.make(env_id, **env_kwargs)`` in a :class:`FastSyncVectorEnv`.
    ``world`` may be a list: env ``i`` gets ``world[i % len(world)]`` (mixed worlds in one
    batch; their maps must have the same shape, as every batch's). A procedural spelling without
    ``seed=`` (``"maze:size_m=6"``) already gives each env its own world, drawn from its reset
    seed. gymnasium's vector options come as keywords here (``make_vec`` refuses
    ``vector_kwargs`` and ``wrappers`` for a vector entry point, before this function runs):
    ``copy`` and ``autoreset_mode``.

    Wrappers per env: ``gym.make_vec(..., vectorization_mode="sync", wrappers=[...])``
    (gymnasium's ``SyncVectorEnv``), or, with this batching, call this function directly::

        make_vector_env(4, wrappers=[lambda e: FixedSizeMap(e, map_size=128)], world="maze2")

    Args:
        wrappers: Applied in order to each env after ``gym.make`` (as ``make_vec``'s
            ``wrappers``); with any, the batch takes the general path, not the direct one.
    """
    if not isinstance(num_envs, int) or isinstance(num_envs, bool) or num_envs < 1:
        raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
    worlds = env_kwargs.pop("world", None)
    if isinstance(worlds, (list, tuple)):
        if not worlds:
            raise ValueError("world: an empty list of worlds")
        per_env = [worlds[i % len(worlds)] for i in range(num_envs)]
    else:
        per_env = [worlds] * num_envs
    if max_episode_steps is not None:
        env_kwargs["max_episode_steps"] = max_episode_steps

    def maker(world: Any) -> Callable[[], gym.Env]:
        kwargs = env_kwargs if world is None else {**env_kwargs, "world": world}

        def make() -> gym.Env:
            env = gym.make(env_id, **kwargs)
            for wrap in wrappers:
                env = wrap(env)
            return env

        return make

    return FastSyncVectorEnv([maker(w) for w in per_env], copy=copy, autoreset_mode=autoreset_mode)
