"""``SemanticExplore-v0``: explore an unknown building with a simulated TurtleBot3 and LiDAR."""

from __future__ import annotations

import math
import os
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from semexplore_gym.core.coverage_tour.problem import PRIVILEGED_INFO_KEY
from semexplore_gym.core.features.map_window import map_window, window_origin
from semexplore_gym.core.grid import GridGeometry, wrap_angle_rad
from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid
from semexplore_gym.core.mapping.odometry import OdometryDrift
from semexplore_gym.core.mapping.raycast import SegmentIndex
from semexplore_gym.core.validation import short_repr
from semexplore_gym.core.worlds.start import sample_start_pose, validate_start_pose
from semexplore_gym.core.worlds.world import World
from semexplore_gym.envs.coverage_mask import coverage_mask
from semexplore_gym.envs.env_config import EnvConfig, load_env_config
from semexplore_gym.envs.observation_options import MAP_OBSERVATIONS as MAP_OBSERVATIONS
from semexplore_gym.envs.observation_options import STATIC_INFO_MODES as STATIC_INFO_MODES
from semexplore_gym.envs.observation_options import ObservationOptions
from semexplore_gym.envs.slam_mode import SlamMode, draw_beside_truth, kidnap_start, slam_reset
from semexplore_gym.envs.static_info import FrozenInfo as FrozenInfo
from semexplore_gym.envs.static_info import static_info_of
from semexplore_gym.maps import make_world
from semexplore_gym.sim.lidar import Lidar
from semexplore_gym.sim.robot import RobotSim

PROCEDURAL_FAMILIES = ("maze", "office", "cave", "noisecave")
#: The per-step numbers of ``info`` besides ``reward_terms`` (see :meth:`info_numbers`).
INFO_NUMBERS = ("coverage", "explored_area_m2", "collisions", "sim_time_s", "path_length_m")


def is_unseeded_procedural(spec: Any) -> bool:
    """Whether ``spec`` names a procedural family without ``seed=`` (a new world per reset)."""
    if not isinstance(spec, str):
        return False
    family, _, params = spec.partition(":")
    return family in PROCEDURAL_FAMILIES and "seed=" not in params


class SemanticExploreEnv(gym.Env):
    """Explore an unknown building with a TurtleBot3 Burger and a 2D LiDAR.

    ## Description
    A disc robot (TurtleBot3 Burger, radius 0.105 m) drives in a 2D world of walls simulated
    with pymunk. Each control step (0.2 s) a 360-beam LiDAR scans the walls and the scan is
    fused into a log-odds occupancy grid. The task is to map the reachable free space; the
    scripted expert (``semexplore_gym.policies.expert.expert``) does it with the semantic topometric method
    of Fredriksson, Saradagi and Nikolakopoulos.

    ## Action Space
    ``Box(-1, 1, (2,), float32)``: ``[v, omega]`` scaled by ``robot.max_linear_speed_mps``
    (0.22 m/s) and ``robot.max_angular_speed_radps`` (2.84 rad/s). Values outside [-1, 1] are
    clipped; NaN or inf raise ``ValueError``.

    ## Observation Space
    ``Dict``:

    =======  ==============  =======  =================  ===================================
    key      shape           dtype    range              unit / meaning
    =======  ==============  =======  =================  ===================================
    map      (H, W)          uint8    {0, 128, 255}      OCCUPIED=0, UNKNOWN=128, FREE=255;
                                                         row 0 = lowest y (see ``core``)
    pose     (3,)            float32  x, y, yaw          metres, metres, radians (map frame)
    scan     (n_beams,)      float32  [0, max_range_m]   metres; 0 = invalid, max = no return
    =======  ==============  =======  =================  ===================================

    The map frame is the world frame; ``info["map_geometry"]`` (and ``self.map_geometry``)
    give the grid's resolution, origin and shape. ``pose`` is the pose the map was built with:
    ground truth, or the odometry estimate when ``odometry`` noise is configured. Beam ``i`` of
    ``scan`` points ``i * 2*pi/n_beams`` counter-clockwise from the heading.

    ## Rewards
    ``reward = sum(weight * term)`` over named terms (weights in ``RewardParams``):
    ``free_area_change`` (the net change of the map's free area this step in m^2, weight 1: cells
    newly mapped free minus free cells re-marked occupied, so a step that re-observes a wall's
    edge can score below zero), ``time`` (the control period in s, weight -0.01) and
    ``collision`` (1 when a wall contact begins, weight -1). ``info["reward_terms"]`` holds each
    weighted term.

    ## Starting State
    The world's start pose, ``episode.start_pose``, ``reset(options={"start_pose": ...})``, or
    (``episode.random_start`` or none given) a pose sampled uniformly in free space at least
    ``radius + start_clearance_margin_m`` from walls, yaw uniform, from the env's RNG. The first
    scan is fused before the first observation.

    ## Episode End
    Terminated when ``coverage >= episode.coverage_goal`` (0.99). Truncated when the simulated
    time reaches ``episode.max_time_s`` (1200 s). ``coverage`` = mapped free cells inside the
    reachable mask / cells of the reachable mask, where the reachable mask is the free area the
    robot's body can sweep from the start (``self.start_pose``) with its centre at least
    ``radius + episode.coverage_clearance_margin_m`` (0.01 m) from walls, less a one-cell band
    along walls (:func:`~semexplore_gym.envs.coverage_mask.coverage_mask`).

    ## Arguments
    - ``world``: ``"maze1"``, ``"maze2"``, ``"maze:seed=3,size_m=10"``, ``"office:..."``,
      ``"cave:..."``, ``"noisecave:..."``, a ROS map ``.yaml`` or a HouseExpo ``.json``. A
      procedural spelling without ``seed`` draws a new world from the env's RNG at every reset
      (same grid shape).
    - ``config``: None, a preset name (``"default"``, ``"paper"``), a YAML path, a dict or an
      :class:`EnvConfig`.
    - ``overrides``: list of ``"section.key=value"`` strings applied on top of ``config``.
    - ``render_mode``: None, ``"rgb_array"`` or ``"human"``.
    - ``observation_options``: an :class:`~semexplore_gym.envs.observation_options.ObservationOptions`
      (None: the defaults) with the three speed options below; ``gym.make`` also takes them
      one by one as keywords (``map_observation="shared"``), which replace its fields.
    - ``map_observation``: ``"copy"`` (default) gives a fresh copy of the whole map each step
      (1.3 MB per step on Willow Garage). ``"window"`` gives a fresh ``(map_window_cells,
      map_window_cells)`` window of it centred on the cell of ``obs["pose"]`` (north-up, cells
      beyond the map read UNKNOWN) and adds ``obs["map_offset_cells"]``, int32 ``(row, col)``
      of the window's first cell in the full map: ``obs["map"][r, c] == full_map[r + row,
      c + col]`` where that cell exists (the same window as ``FixedSizeMap(env,
      map_window_cells, anchor="robot")``, without copying the whole map first).
      ``"shared"`` gives a read-only live view of the env's own map instead of a copy: no copy
      at all, but the array changes in place at every step of the episode (a new episode maps
      into a new array, so the last episode's view keeps its final map). For code that reads
      the map within the step it gets it, as the scripted policies do (the semantic expert's
      missions are bit-identical either way, tested); ``np.array(obs["map"])`` keeps a
      snapshot. Writing into it raises ``ValueError``.
    - ``map_window_cells``: side of the ``"window"`` map in cells (8 to 4096; default 160, 8 m
      at 0.05 m per cell, which holds a 3.5 m LiDAR's reach).
    - ``static_info``: ``"every_step"`` (default) puts the static entries (``map_geometry``,
      ``robot``, ``lidar``, ``dt_s``) in every ``info``; ``"reset"`` puts them only in the
      ``info`` of ``reset``, so each step's ``info`` holds only what changes (cheaper to merge
      in gymnasium's vector envs, which batch every ``info`` key per step).
    - ``privileged``: False (default). True adds the ground truth to the ``info`` of ``reset``
      (only there): ``info["privileged_world"]``, a
      :class:`~semexplore_gym.core.coverage_tour.problem.PrivilegedWorld` (true world, start
      pose, reachable mask, LiDAR model). The one channel through which privileged policies (the
      oracle explorer) read the true world; observations are unchanged. Learning code never
      sets it.

    ## Info
    ``map_geometry``, ``robot``, ``lidar``, ``dt_s``, ``coverage``, ``explored_area_m2`` (free
    area in the map), ``collisions`` (count so far), ``sim_time_s``, ``path_length_m``,
    ``reward_terms``; ``true_pose`` is *not* given (policies must not see ground truth). With
    ``slam.enabled`` (preset ``"slam"``) map and pose are SLAM's, ``info`` adds its figures and
    ``reset(options={"kidnap_to": pose})`` kidnaps the robot (:mod:`~semexplore_gym.envs.slam_mode`);
    ``render()`` then draws the SLAM map beside the map at the true poses.

    ## Notes
    Rendering overlays: ``env.unwrapped.set_overlay(dict)`` draws a policy's semantic areas,
    paths and goal on the next frames (keys in :mod:`semexplore_gym.rendering.renderer`).

    ## Version History
    - v0: initial version. (The ``new_area`` reward term was renamed ``free_area_change``, and
      its weight ``reward.free_area_change_weight``, to say what it is; values unchanged.)
    - v0, 0.1 (no change to observations, rewards or dynamics): ``info["map_geometry"]``,
      ``info["robot"]`` and ``info["lidar"]`` are read-only mappings (:class:`FrozenInfo`)
      built once per env and shared by every step, instead of fresh dicts each step. Same
      keys and values; mutating them raises ``TypeError`` (take ``dict(...)`` for a copy).
      In gymnasium vector envs each is collected as an object array of mappings rather than
      a dict of per-field arrays.
    - v0, 0.1: the ``map_observation`` (``"window"``, ``"shared"``) and ``static_info``
      (``"reset"``) options, off by default (the default observations and ``info`` are unchanged).
    - v0, 0.2 (no change to observations, rewards or dynamics): the speed options are
      one :class:`ObservationOptions` (``observation_options=``); the fast path the vector env
      uses is public (:meth:`advance`, :meth:`write_obs_into`, :meth:`info_numbers`).
    - v0, 0.2: the ``privileged`` option (off by default; nothing changes without it).

    ## Speed
    ``scripts/bench_env.py`` times the step by stage, ``scripts/bench_vector_env.py`` vector envs
    against a plain loop. ``map_observation="window"`` copies only the window around the robot,
    ``"shared"`` nothing (Willow Garage: about 2x the steps/s of ``"copy"``). gymnasium's
    ``SyncVectorEnv`` merges every ``info`` key at each step (maze1: about 0.7x a plain loop);
    :class:`~semexplore_gym.envs.vector.FastSyncVectorEnv` gives the same results stepping these
    envs straight into its batch (0.93-0.98x with 4 envs, the higher with ``copy=False`` and
    ``static_info="reset"``). ``AsyncVectorEnv`` pays off only with a free core per worker
    (0.3-0.45x on a busy 2-core machine).
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 5}

    def __init__(
        self,
        world: str | os.PathLike | World = "maze1",
        config: EnvConfig | str | os.PathLike | dict | None = None,
        overrides: list[str] | None = None,
        render_mode: str | None = None,
        observation_options: ObservationOptions | None = None,
        privileged: bool = False,
        **option_fields: Any,
    ) -> None:
        super().__init__()
        self.privileged = bool(privileged)
        opts = ObservationOptions.from_flags(
            observation_options, option_fields, type(self).__init__
        )
        self.observation_options = opts
        # Read by wrappers and tools; the options object is the one source.
        self.map_observation = opts.map_observation
        self.map_window_cells = opts.map_window_cells
        self.static_info = opts.static_info
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode {render_mode!r} is not one of {self.metadata['render_modes']}"
            )
        self.render_mode = render_mode
        self.config: EnvConfig = load_env_config(config, overrides)
        cfg = self.config
        self.world_spec = world
        self._randomise_world = is_unseeded_procedural(world)
        self.world: World = (
            world if isinstance(world, World) else make_world(world, rng=np.random.default_rng(0))
        )
        self.map_geometry: GridGeometry = GridGeometry.covering(
            *self.world.bounds_m, cfg.mapping.resolution_m, cfg.mapping.margin_m
        )
        n_cells = self.map_geometry.height * self.map_geometry.width
        if n_cells > 40_000_000:
            raise ValueError(
                f"world {self.world.name!r} needs a {self.map_geometry.height}x{self.map_geometry.width} map at "
                f"mapping.resolution_m={cfg.mapping.resolution_m}; raise mapping.resolution_m"
            )
        self._build_world_state()
        self.observation_space = self._observation_space()
        self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
        self._static_info = static_info_of(self.config, self.map_geometry)
        self._area_per_cell_m2 = cfg.mapping.resolution_m**2
        self._static_every_step = self.static_info == "every_step"
        self._overlay: dict[str, Any] = {}
        self._renderer: Any = None
        self._started = False
        self.start_pose: tuple[float, float, float] | None = None  # set by reset

    # ----------------------------------------------------------------- set-up
    def _observation_space(self) -> spaces.Dict:
        cfg = self.config
        h, w = self.map_geometry.shape
        if self.map_observation == "window":
            h = w = self.map_window_cells
        big = np.float32(1e6)
        space = spaces.Dict(
            {
                "map": spaces.Box(0, 255, shape=(h, w), dtype=np.uint8),
                "pose": spaces.Box(
                    np.array([-big, -big, -np.pi], dtype=np.float32),
                    np.array([big, big, np.pi], dtype=np.float32),
                    dtype=np.float32,
                ),
                "scan": spaces.Box(
                    0.0, cfg.lidar.max_range_m, shape=(cfg.lidar.n_beams,), dtype=np.float32
                ),
            }
        )
        if self.map_observation == "window":
            lim = 2**30
            space.spaces["map_offset_cells"] = spaces.Box(-lim, lim, shape=(2,), dtype=np.int32)
        return space

    def _build_world_state(self) -> None:
        cfg = self.config
        self.sim = RobotSim(self.world, cfg.robot, cfg.physics)
        self.lidar = Lidar(cfg.lidar, SegmentIndex(self.world.segments_m))
        self.grid = OccupancyGrid(self.map_geometry, cfg.mapping)
        self.odometry = OdometryDrift(cfg.odometry)
        self._odometry_noisy = not cfg.odometry.is_perfect
        self.slam = SlamMode.create(cfg, self.map_geometry, self.lidar.beam_angles_rad)

    def choose_start(self, options: dict[str, Any] | None) -> tuple[float, float, float]:
        """The start pose for a reset: ``options["start_pose"]``, else ``episode.start_pose``,
        else the world's start (unless ``episode.random_start``), else a random free pose drawn
        from :attr:`np_random`. Raises ``ValueError`` for a malformed or blocked pose."""
        cfg = self.config
        clearance = cfg.robot.radius_m + cfg.episode.start_clearance_margin_m
        pose = None
        if options and options.get("start_pose") is not None:
            pose = options["start_pose"]
        elif cfg.episode.start_pose is not None:
            pose = cfg.episode.start_pose
        elif self.world.start_pose is not None and not cfg.episode.random_start:
            pose = self.world.start_pose
        if pose is None:
            return tuple(float(v) for v in sample_start_pose(self.world, self.np_random, clearance))  # type: ignore[return-value]
        try:
            pose_t = tuple(float(v) for v in pose)
        except (TypeError, ValueError) as e:
            raise ValueError(f"start_pose must be (x_m, y_m, yaw_rad), got {pose!r}") from e
        if len(pose_t) != 3:
            raise ValueError(f"start_pose must be (x_m, y_m, yaw_rad), got {pose!r}")
        validate_start_pose(self.world, pose_t, cfg.robot.radius_m)
        return pose_t  # type: ignore[return-value]

    # ------------------------------------------------------------------- API
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        if self._randomise_world and (self._started or seed is not None):
            world_seed = int(self.np_random.integers(0, 2**31 - 1))
            family, _, params = str(self.world_spec).partition(":")
            params = f"{params},seed={world_seed}" if params.strip() else f"seed={world_seed}"
            self.world = make_world(f"{family}:{params}")
            self._build_world_state()
        self._started = True
        pose = self.choose_start(kidnap_start(options, self.slam))
        cfg = self.config
        self.sim.reset(pose)
        self.start_pose = pose
        reach = coverage_mask(self.world, self.map_geometry, pose[:2], cfg)
        self._n_reachable = max(1, int(reach.sum()))
        self.grid = OccupancyGrid(self.map_geometry, cfg.mapping, count_mask=reach)
        self.odometry.reset(pose)
        self._est_pose: tuple[float, float, float] | np.ndarray = pose
        self.sim_time_s = 0.0
        self._n_steps = 0
        self.path_length_m = 0.0
        self._trajectory: list[tuple[float, float]] = [(pose[0], pose[1])]
        self._overlay = {}
        self._true_pose = self.sim.pose
        self._scan = self._sense_and_map(self._true_pose)
        self._map_grid, self._est_pose = slam_reset(self.slam, self.grid, pose, self._scan, options)
        info = self._info({"free_area_change": 0.0, "time": 0.0, "collision": 0.0}, True)
        if self.privileged:
            info[PRIVILEGED_INFO_KEY] = self._privileged_world(pose, reach)
        if self.render_mode == "human":
            self.render()
        return self._obs(), info

    def _privileged_world(self, pose: tuple[float, float, float], reach: np.ndarray) -> Any:
        from semexplore_gym.core.coverage_tour.problem import PrivilegedWorld, SensorModel

        cfg = self.config
        reach = reach.copy()
        reach.flags.writeable = False
        return PrivilegedWorld(
            world=self.world,
            geometry=self.map_geometry,
            start_pose=pose,
            radius_m=cfg.robot.radius_m,
            clearance_m=cfg.robot.radius_m + cfg.episode.coverage_clearance_margin_m,
            reachable_mask=reach,
            sensor=SensorModel(cfg.lidar.n_beams, cfg.lidar.max_range_m, cfg.lidar.min_range_m),
            max_linear_speed_mps=cfg.robot.max_linear_speed_mps,
            coverage_goal=cfg.episode.coverage_goal,
        )

    def step(
        self, action: np.ndarray
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        reward, terminated, truncated, terms = self.advance(action)
        info = self.step_info(terms)
        if self.render_mode == "human":
            self.render()
        return self._obs(), reward, terminated, truncated, info

    # ------------------------------------------------- the vector env's fast path
    # step() is advance() + _obs() + step_info(); FastSyncVectorEnv calls the public pieces
    # itself (advance, write_obs_into, info_numbers, static_info_entries, step_info) to step
    # straight into its batch. They must stay in step with step(): a change to what step()
    # returns changes them too (tests/envs/test_vector.py compares with SyncVectorEnv).
    def advance(self, action: Any) -> tuple[float, bool, bool, dict[str, float]]:
        """One control step of the world, robot, LiDAR and map, without building the
        observation or ``info``: ``(reward, terminated, truncated, reward_terms)``.

        :meth:`step` is this, then the observation and :meth:`step_info`; a caller that
        advances must read the observation with :meth:`write_obs_into` and the ``info``
        numbers with :meth:`info_numbers` before the next call.
        """
        v_mps, w_radps = self.scale_action(action)
        cfg = self.config
        before = self._true_pose
        new_collision = self.sim.step(v_mps, w_radps, cfg.episode.dt_s)
        after = self._true_pose = self.sim.pose
        self._n_steps += 1
        # From the step count, not a running sum, so 600 steps of 0.2 s are exactly 120 s.
        self.sim_time_s = round(self._n_steps * cfg.episode.dt_s, 9)
        self.path_length_m += math.hypot(after[0] - before[0], after[1] - before[1])
        self._trajectory.append((after[0], after[1]))
        self._est_pose = (
            self.odometry.update(before, after, self.np_random) if self._odometry_noisy else after
        )
        n_free_before = self.grid.n_free_cells
        self._scan = self._sense_and_map(after)
        if self.slam is not None:
            self._est_pose = self.slam.update(self._est_pose, self._scan, after)
        free_area_change_m2 = (self.grid.n_free_cells - n_free_before) * cfg.mapping.resolution_m**2
        rw = cfg.reward
        terms = {
            "free_area_change": rw.free_area_change_weight * free_area_change_m2,
            "time": rw.time_weight * cfg.episode.dt_s,
            "collision": rw.collision_weight * float(new_collision),
        }
        reward = float(sum(terms.values()))
        terminated = bool(self.grid.n_free_in_mask / self._n_reachable >= cfg.episode.coverage_goal)
        truncated = bool(self.sim_time_s >= cfg.episode.max_time_s - 1e-9)
        return reward, terminated, truncated, terms

    def scale_action(self, action: Any) -> tuple[float, float]:
        """``action`` = [v, omega] in [-1, 1] as (linear m/s, angular rad/s) of the robot's
        limits (clipped). Raises ``ValueError`` for anything but 2 real numbers."""
        if isinstance(action, np.ndarray) and action.shape == (2,) and action.dtype.kind in "fiub":
            a0, a1 = float(action[0]), float(action[1])
        else:
            try:
                raw = np.asarray(action)
                # float() would drop an imaginary part or parse a string: only real numbers.
                if raw.dtype.kind not in "fiubO" or np.iscomplexobj(action):
                    raise TypeError(f"dtype {raw.dtype}")
                a = raw.astype(np.float64).reshape(-1)
            except (TypeError, ValueError, OverflowError) as e:  # Overflow: a huge Python int
                raise ValueError(
                    f"action must be 2 numbers [v, omega] in [-1, 1], got {short_repr(action)}"
                ) from e
            if a.shape != (2,):
                raise ValueError(f"action must have shape (2,), got {short_repr(action)}")
            a0, a1 = float(a[0]), float(a[1])
        if not (math.isfinite(a0) and math.isfinite(a1)):
            raise ValueError(f"action contains NaN or inf: {short_repr(action)}")
        rp = self.config.robot
        v = min(1.0, max(-1.0, a0)) * rp.max_linear_speed_mps
        if not rp.allow_reverse:
            v = max(v, 0.0)
        return v, min(1.0, max(-1.0, a1)) * rp.max_angular_speed_radps

    def _sense_and_map(self, true_pose: tuple[float, float, float]) -> np.ndarray:
        map_pose = self._est_pose if self.slam is None else true_pose  # SLAM maps on its own
        return self.lidar.sense_and_map(true_pose, map_pose, self.grid, self.np_random)

    def _obs(self) -> dict[str, np.ndarray]:
        pose = np.array(self._pose_values(), dtype=np.float32)
        if self.map_observation == "window":
            return self._window_obs(pose)
        return {
            "map": self._map_grid.encoded
            if self.map_observation == "shared"
            else self._map_grid.encoded_copy(),
            "pose": pose,
            "scan": self._scan,
        }

    def _pose_values(self) -> tuple[float, float, float]:
        return self._est_pose[0], self._est_pose[1], wrap_angle_rad(self._est_pose[2])

    def write_obs_into(self, batch: dict[str, np.ndarray], i: int, map_row: np.ndarray) -> None:
        """Put the observation :meth:`step` would return into row ``i`` of ``batch`` (the same
        values; for ``map_observation`` ``"copy"`` and ``"shared"`` only): the vector env's
        batch, no fresh arrays. ``map_row`` is ``batch["map"][i]`` (the same view object every
        step): the map is not copied there each step, the grid keeps its cells in it from the
        first call on (:meth:`OccupancyGrid.keep_encoded_in`)."""
        self._map_grid.keep_encoded_in(map_row)
        batch["pose"][i] = self._pose_values()
        batch["scan"][i] = self._scan

    def _info(self, terms: dict[str, float], static: bool) -> dict[str, Any]:
        # The static entries are shared read-only mappings; the top level is a fresh dict.
        info = self._static_info.copy() if static else {}
        # The keys of INFO_NUMBERS, in its order (a test checks they match).
        (
            info["coverage"],
            info["explored_area_m2"],
            info["collisions"],
            info["sim_time_s"],
            info["path_length_m"],
        ) = self.info_numbers()
        info["reward_terms"] = terms
        info.update(self.slam.info(self._true_pose) if self.slam else {})
        return info

    def _window_obs(self, pose: np.ndarray) -> dict[str, np.ndarray]:
        g = self.map_geometry
        # The cell of the observed (float32) pose, as GridGeometry.world_to_grid computes it.
        row = math.floor((float(pose[1]) - g.origin_y_m) / g.resolution_m)
        col = math.floor((float(pose[0]) - g.origin_x_m) / g.resolution_m)
        origin = window_origin(g.shape, self.map_window_cells, "robot", (row, col))
        return {
            "map": map_window(self._map_grid._encoded, origin, self.map_window_cells),
            "pose": pose,
            "scan": self._scan,
            "map_offset_cells": np.array(origin, dtype=np.int32),
        }

    def step_info(self, terms: dict[str, float]) -> dict[str, Any]:
        """The ``info`` :meth:`step` returns after :meth:`advance` gave ``terms``."""
        return self._info(terms, self._static_every_step)

    def static_info_entries(self) -> dict[str, Any]:
        """The static ``info`` entries (``map_geometry``, ``robot``, ``lidar``, ``dt_s``):
        the same read-only mappings every step (with ``static_info="every_step"``) holds."""
        return self._static_info

    def info_numbers(self) -> tuple[float, float, int, float, float]:
        """The per-step numbers of ``info`` under :data:`INFO_NUMBERS`, in that order."""
        grid = self.grid
        return (
            grid.n_free_in_mask / self._n_reachable,
            grid.n_free_cells * self._area_per_cell_m2,
            self.sim.collisions,
            self.sim_time_s,
            self.path_length_m,
        )

    # ------------------------------------------------------------- rendering
    def set_overlay(self, overlay: dict[str, Any] | None) -> None:
        """Draw a policy's overlay (semantic areas, paths, goal) on subsequent frames."""
        self._overlay = dict(overlay or {})

    def render_snapshot(self) -> Any:
        from semexplore_gym.rendering.renderer import RenderSnapshot

        x, y, yaw = self.sim.pose
        return RenderSnapshot(
            map=self._map_grid.encoded.copy(),
            geometry=self.map_geometry,
            segments_m=self.world.segments_m,
            pose=(x, y, yaw),
            radius_m=self.config.robot.radius_m,
            scan=self._scan.copy(),
            beam_angles_rad=self.lidar.beam_angles_rad,
            sensor_pose=self.lidar.sensor_pose(x, y, yaw),
            max_range_m=self.config.lidar.max_range_m,
            trajectory_m=np.asarray(self._trajectory, dtype=np.float64),
            overlay=self._overlay,
            text=f"t={self.sim_time_s:6.1f} s  coverage={self.grid.n_free_in_mask / self._n_reachable:5.1%}",
        )

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gym.logger.warn(
                "render() called without a render_mode; pass render_mode='rgb_array' or 'human' to gym.make"
            )
            return None
        from semexplore_gym.rendering.renderer import Renderer

        if self._renderer is None:
            self._renderer = Renderer(self.map_geometry)
        if self.slam is not None:  # the SLAM map beside the truth
            frame = draw_beside_truth(self._renderer, self.render_snapshot(), self.grid, self.slam)
        else:
            frame = self._renderer.draw(self.render_snapshot())
        if self.render_mode == "rgb_array":
            return frame
        self._renderer.show(frame, fps=self.metadata["render_fps"])
        return None

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_renderer"] = None
        return state
