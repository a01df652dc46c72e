"""A team of TurtleBot3s in one pymunk space, and LiDAR scans that see teammates.

:class:`TeamSim` is :class:`~semexplore_gym.sim.robot.RobotSim` for ``n`` robots: the same
walls, bodies, drive joints, substepping, free-space arcs and pickling (both are a
:class:`~semexplore_gym.sim.robot.PymunkSim`), with the robots added to one space so that they
collide with the walls and with each other. With one robot it makes the same Chipmunk calls in
the same order as :class:`RobotSim` (the multi-robot env's one-robot equivalence test relies on
it).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pymunk
from pymunk._chipmunk import ffi as _ffi
from pymunk._chipmunk import lib as _cp

from semexplore_gym.core.mapping.disc_cast import DiscObstacles
from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid
from semexplore_gym.core.mapping.scan_fusion import ScanFootprint
from semexplore_gym.core.worlds.world import World
from semexplore_gym.sim.lidar import Lidar
from semexplore_gym.sim.robot import (
    ROBOT_COLLISION_TYPE,
    WALL_COLLISION_TYPE,
    PhysicsParams,
    PymunkSim,
    RobotParams,
)

#: The full-size discs robots touch each other with (teams of two or more).
BUMPER_COLLISION_TYPE = 3


class TeamSim(PymunkSim):
    """Pymunk space holding one world's walls and ``n_robots`` robots.

    Args:
        world: The walls.
        robot: Robot parameters (all robots alike).
        physics: Stepping parameters.
        n_robots: Team size, at least 1.

    Attributes:
        collisions: Per robot, contact episodes begun (with a wall or a teammate).
        robot_collisions: Robot-robot contact episodes begun (one per touching pair).
    """

    def __init__(
        self, world: World, robot: RobotParams, physics: PhysicsParams, n_robots: int
    ) -> None:
        if n_robots < 1:
            raise ValueError(f"n_robots must be at least 1, got {n_robots!r}")
        self.world = world
        self.robot_params = robot
        self.physics_params = physics
        self.n_robots = int(n_robots)
        self._build()

    def _build(self) -> None:
        space = self._new_space()
        self.bodies: list[pymunk.Body] = []
        self.controls: list[pymunk.Body] = []
        self._index_of: dict[pymunk.Shape, int] = {}
        for i in range(self.n_robots):
            self._add_robot(space, i)
        self._wall_filter = pymunk.ShapeFilter(mask=0b01)
        self._query_info = _ffi.new("cpPointQueryInfo *")
        n = self.n_robots
        self._touching = [0] * n
        self._began = [False] * n
        self._suppress_begin = [False] * n
        self._add_contact_handlers(space)
        self.space = space
        self.collisions = [0] * n
        self.robot_collisions = 0
        self.in_contact = [False] * n

    def _add_robot(self, space: pymunk.Space, i: int) -> None:
        """Add robot ``i``'s body, wall disc, drive joints (and bumper disc in a team)."""
        r = self.robot_params
        body, shape, control = self._add_robot_body(space)
        self.bodies.append(body)
        self.controls.append(control)
        self._index_of[shape] = i
        if self.n_robots > 1:
            # The wall shape is shrunk by the walls' skin; between robots a second, full-size
            # disc touches, so two robots meet at 2 * radius_m (what their LiDARs see).
            shape.filter = pymunk.ShapeFilter(categories=0b10, mask=0b01)
            bumper = pymunk.Circle(body, r.radius_m)
            bumper.friction = 0.0
            bumper.elasticity = 0.0
            bumper.collision_type = BUMPER_COLLISION_TYPE
            bumper.filter = pymunk.ShapeFilter(categories=0b100, mask=0b100)
            space.add(bumper)
            self._index_of[bumper] = i

    def _add_contact_handlers(self, space: pymunk.Space) -> None:
        """Count contact episodes: robot-wall and robot-robot (bumper-bumper) begin/separate."""

        def _contact_begins(i: int) -> None:
            if self._touching[i] == 0 and not self._suppress_begin[i]:
                self._began[i] = True
            self._touching[i] += 1

        def _begin_wall(arbiter: pymunk.Arbiter, space_: pymunk.Space, data: dict) -> None:
            _contact_begins(self._index_of[arbiter.shapes[0]])

        def _separate_wall(arbiter: pymunk.Arbiter, space_: pymunk.Space, data: dict) -> None:
            i = self._index_of[arbiter.shapes[0]]
            self._touching[i] = max(0, self._touching[i] - 1)

        def _begin_robot(arbiter: pymunk.Arbiter, space_: pymunk.Space, data: dict) -> None:
            a, b = (self._index_of[s] for s in arbiter.shapes)
            if not (self._suppress_begin[a] and self._suppress_begin[b]):
                self.robot_collisions += 1
            _contact_begins(a)
            _contact_begins(b)

        def _separate_robot(arbiter: pymunk.Arbiter, space_: pymunk.Space, data: dict) -> None:
            for s in arbiter.shapes:
                i = self._index_of[s]
                self._touching[i] = max(0, self._touching[i] - 1)

        space.on_collision(
            ROBOT_COLLISION_TYPE, WALL_COLLISION_TYPE, begin=_begin_wall, separate=_separate_wall
        )
        space.on_collision(
            BUMPER_COLLISION_TYPE,
            BUMPER_COLLISION_TYPE,
            begin=_begin_robot,
            separate=_separate_robot,
        )

    def reset(self, poses: Sequence[tuple[float, float, float]]) -> None:
        """Place robot ``i`` at rest at ``poses[i]`` = (x_m, y_m, yaw_rad)."""
        if len(poses) != self.n_robots:
            raise ValueError(f"need {self.n_robots} poses, got {len(poses)}")
        for body, control, pose in zip(self.bodies, self.controls, poses, strict=True):
            x, y, yaw = (float(v) for v in pose)
            for b in (body, control):
                b.position = (x, y)
                b.angle = yaw
                b.velocity = (0.0, 0.0)
                b.angular_velocity = 0.0
            self.space.reindex_shapes_for_body(body)
        n = self.n_robots
        self.collisions = [0] * n
        self.robot_collisions = 0
        self.in_contact = [False] * n
        self._began = [False] * n
        self._touching = [0] * n

    def pose(self, i: int) -> tuple[float, float, float]:
        """True pose of robot ``i``."""
        b = self.bodies[i]._body
        p = _cp.cpBodyGetPosition(b)
        return (p.x, p.y, _cp.cpBodyGetAngle(b))

    @property
    def poses(self) -> list[tuple[float, float, float]]:
        return [self.pose(i) for i in range(self.n_robots)]

    def step(self, commands: Sequence[tuple[float, float]], dt_s: float) -> list[bool]:
        """Drive robot ``i`` with body-frame ``commands[i]`` = (v, omega) for ``dt_s``.

        Returns, per robot, whether a new contact (wall or teammate) began. When no robot can
        touch anything this step (no wall within radius + the step's largest travel + 1 cm of
        any robot, no two robots within twice that, no contact going on), each moves along its
        exact arc without the solver, as :meth:`RobotSim.step`; otherwise all robots are
        integrated together in fixed substeps.
        """
        rp = self.robot_params
        n_sub = self._substeps_for(dt_s)
        reach = rp.radius_m + rp.max_linear_speed_mps * dt_s + 0.01
        space_p = self.space._space
        positions = [_cp.cpBodyGetPosition(b._body) for b in self.bodies]
        free = all(t == 0 for t in self._touching)
        if free:
            for p in positions:
                near = _cp.cpSpacePointQueryNearest(
                    space_p, p, reach, self._wall_filter, self._query_info
                )
                if near != _ffi.NULL:
                    free = False
                    break
        if free and self.n_robots > 1:
            xy = np.array([(p.x, p.y) for p in positions])
            d = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
            np.fill_diagonal(d, np.inf)
            free = bool(d.min() > 2.0 * reach)
        if free:
            for i, (v, w) in enumerate(commands):
                self._drive_arc(self.bodies[i], v, w, dt_s)
                self.in_contact[i] = False
            return [False] * self.n_robots
        h = dt_s / n_sub
        n = self.n_robots
        self._began = [False] * n
        for body, control, (_, w) in zip(self.bodies, self.controls, commands, strict=True):
            control_p = control._body
            _cp.cpBodySetPosition(control_p, _cp.cpBodyGetPosition(body._body))
            _cp.cpBodySetAngularVelocity(control_p, w)
        space = self.space
        if space._bodies_to_check:
            space.step(0.0)
        get_angle, set_velocity, cp_step = (
            _cp.cpBodyGetAngle,
            _cp.cpBodySetVelocity,
            _cp.cpSpaceStep,
        )
        pairs = [
            (b._body, c._body, float(v))
            for b, c, (v, _) in zip(self.bodies, self.controls, commands, strict=True)
        ]
        space._locked = True
        try:
            for _ in range(n_sub):
                for body_p, control_p, v in pairs:
                    yaw = get_angle(body_p)
                    set_velocity(control_p, (v * math.cos(yaw), v * math.sin(yaw)))
                cp_step(space_p, h)
        finally:
            space._locked = False
        self._suppress_begin = [False] * n
        new = list(self._began)
        for i in range(n):
            if new[i]:
                self.collisions[i] += 1
            self.in_contact[i] = self._touching[i] > 0
        return new

    # Pymunk objects hold C pointers: pickle the inputs and rebuild.
    def __getstate__(self) -> dict:
        return {
            **self._inputs_state(),
            "n_robots": self.n_robots,
            "poses": self.poses,
            "velocities": [tuple(b.velocity) for b in self.bodies],
            "angular_velocities": [float(b.angular_velocity) for b in self.bodies],
            "collisions": list(self.collisions),
            "robot_collisions": self.robot_collisions,
            "touching": [t > 0 for t in self._touching],
        }

    def __setstate__(self, state: dict) -> None:
        self._restore_inputs(state)
        self.n_robots = state["n_robots"]
        self._build()
        self.reset(state["poses"])
        for b, v, w in zip(
            self.bodies, state["velocities"], state["angular_velocities"], strict=True
        ):
            b.velocity = v
            b.angular_velocity = w
        self.collisions = list(state["collisions"])
        self.robot_collisions = state["robot_collisions"]
        # The rebuilt space re-detects contacts already counted: do not count them again.
        self._suppress_begin = list(state["touching"])


def sense_with_teammates(
    lidar: Lidar,
    true_pose: tuple[float, float, float],
    map_pose: tuple[float, float, float] | np.ndarray,
    grids: Sequence[OccupancyGrid],
    rng: np.random.Generator,
    teammates: DiscObstacles | None,
    footprint: ScanFootprint | None = None,
) -> np.ndarray:
    """A scan at ``true_pose`` that sees walls and teammates, fused into each of ``grids``.

    One :meth:`Lidar.sense_and_map` call (the same random draws: range noise, then dropouts)
    casts the walls and the teammates within range and fuses the scan into ``grids[0]``; the
    other grids get the same map ranges.

    Args:
        lidar: The robot's LiDAR.
        true_pose: Where the scan is taken.
        map_pose: The pose the map is built with (the odometry estimate).
        grids: The grids to fuse the scan into (the team map, or a robot's own and the team's).
        rng: The env's random source.
        teammates: The other robots as discs at their true positions (those within
            ``max_range_m`` + their radius of the sensor are cast); their ``map_hits``
            false (the default of a team): beams that end on a teammate are left out of the
            map (the team knows where its robots are), while the returned scan still holds
            them. None: no teammates.
        footprint: Where to record the cells the scan updated (in ``grids[0]``; the same
            cells in every grid).

    Returns:
        The ``(n,)`` float32 scan: 0 = invalid, ``max_range_m`` = no return.
    """
    p = lidar.params
    scan = lidar.sense_and_map(true_pose, map_pose, grids[0], rng, teammates, footprint)
    if len(grids) > 1:
        mx, my, myaw = lidar.sensor_pose(*(float(v) for v in map_pose))
        ranges = lidar.last_map_ranges.copy()
        for grid in grids[1:]:
            grid.integrate_scan(mx, my, myaw, lidar.beam_angles_rad, ranges, p.max_range_m)
    return scan
