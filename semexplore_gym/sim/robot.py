"""The TurtleBot3 Burger in pymunk: a disc driven as a differential-drive robot.

The robot body is dynamic; a kinematic *control body* carries the commanded velocity and pulls
the robot with a :class:`pymunk.PivotJoint` (no positional bias, bounded force) and a
:class:`pymunk.GearJoint` (heading). Walls therefore stop the robot physically: a command into a
wall saturates the joint force instead of teleporting the robot into the wall, as overwriting
``body.velocity`` would (measured 4 cm penetration at 20 Hz, stack-measurements.md §2e).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pymunk
from pymunk._chipmunk import ffi as _ffi
from pymunk._chipmunk import lib as _cp

from semexplore_gym.core.validation import require_finite
from semexplore_gym.core.worlds.world import World

WALL_COLLISION_TYPE = 1
ROBOT_COLLISION_TYPE = 2
WALL_SKIN_M = 0.01


@dataclass(frozen=True)
class RobotParams:
    """TurtleBot3 Burger geometry and limits (defaults from the ROBOTIS e-manual).

    Attributes:
        radius_m: Radius of the disc that collides with walls.
        mass_kg: Mass of the robot body.
        max_linear_speed_mps: Speed at action ``a[0] = 1``.
        max_angular_speed_radps: Turn rate at action ``a[1] = 1``.
        allow_reverse: If False, negative linear actions are clipped to 0.
        max_drive_force_n: Force the drive can exert to reach the commanded velocity.
        max_turn_torque_nm: Torque the drive can exert to reach the commanded turn rate.
    """

    radius_m: float = 0.105
    mass_kg: float = 1.0
    max_linear_speed_mps: float = 0.22
    max_angular_speed_radps: float = 2.84
    allow_reverse: bool = True
    max_drive_force_n: float = 50.0
    max_turn_torque_nm: float = 20.0

    def __post_init__(self) -> None:
        require_finite(
            self,
            (
                "radius_m",
                "mass_kg",
                "max_linear_speed_mps",
                "max_angular_speed_radps",
                "max_drive_force_n",
                "max_turn_torque_nm",
            ),
            positive=True,
            prefix="robot.",
        )
        # Below twice the wall skin the disc slips between wall shapes; extreme mass or drive
        # force make the drive constraint overpower the contact solver.
        for name, lo, hi in (
            ("radius_m", 2.0 * WALL_SKIN_M, 2.0),
            ("mass_kg", 0.1, 1000.0),
            ("max_angular_speed_radps", 0.0, 100.0),
            ("max_drive_force_n", 0.0, 1e5),
            ("max_turn_torque_nm", 0.0, 1e4),
        ):
            v = getattr(self, name)
            if not (lo <= v <= hi):
                raise ValueError(f"robot.{name} must be in [{lo:g}, {hi:g}], got {v!r}")
        if self.max_drive_force_n / self.mass_kg > 200.0:
            raise ValueError(
                f"robot.max_drive_force_n / robot.mass_kg = "
                f"{self.max_drive_force_n / self.mass_kg:.3g} m/s^2 is beyond the 200 the "
                "contact solver holds against"
            )
        if self.max_linear_speed_mps > 5.0:
            raise ValueError(
                f"robot.max_linear_speed_mps={self.max_linear_speed_mps} is beyond what the physics is tuned for (<= 5 m/s)"
            )


@dataclass(frozen=True)
class PhysicsParams:
    """Simulation stepping.

    Contacts are discrete, so the robot can sink into a wall by up to the distance it travels
    in one substep. A control step far from every wall (no wall within radius + largest travel
    + 1 cm: one pymunk nearest-point query) is one exact arc without the solver; near a wall it
    is integrated in fixed substeps that travel at most ``max_substep_travel_m`` at full speed.

    Attributes:
        max_substep_travel_m: Largest distance the robot may travel in one substep near walls
            (the bound on wall penetration).
        max_substeps: Upper bound on substeps per control step.
        collision_slop_m: Allowed overlap before pymunk corrects it. Pymunk's default (0.1) is
            10 cm in our metre units, so it is set to 1 mm.
        solver_iterations: Pymunk solver iterations per substep.
    """

    max_substep_travel_m: float = 0.004
    max_substeps: int = 40
    collision_slop_m: float = 0.001
    solver_iterations: int = 10

    def __post_init__(self) -> None:
        if not (0 < self.max_substep_travel_m <= 0.05):
            raise ValueError(
                f"physics.max_substep_travel_m must be in (0, 0.05] m, got {self.max_substep_travel_m!r}"
            )
        if not (1 <= self.max_substeps <= 10_000):
            raise ValueError(f"physics.max_substeps must be in 1..10000, got {self.max_substeps!r}")
        if not (0 <= self.collision_slop_m <= 0.005):
            raise ValueError(
                f"physics.collision_slop_m must be in [0, 0.005] m, got {self.collision_slop_m!r}"
            )
        if not (5 <= self.solver_iterations <= 1000):
            raise ValueError(
                f"physics.solver_iterations must be in 5..1000, got {self.solver_iterations!r}"
            )


class PymunkSim:
    """What :class:`RobotSim` and :class:`~semexplore_gym.sim.team.TeamSim` share: the world's
    walls in a pymunk space, robots driven through a kinematic control body, the fixed substep
    count near walls, the exact arc far from them, and pickling by the inputs (pymunk objects
    hold C pointers: a copy rebuilds its space)."""

    world: World
    robot_params: RobotParams
    physics_params: PhysicsParams
    _substep_dt_key: float
    _substeps: int
    space: pymunk.Space

    def _new_space(self) -> pymunk.Space:
        """A space with the physics settings and the world's walls (static, skinned segments)."""
        space = pymunk.Space()
        space.gravity = (0.0, 0.0)
        space.collision_slop = self.physics_params.collision_slop_m
        space.iterations = self.physics_params.solver_iterations
        static = space.static_body
        shapes = []
        for x0, y0, x1, y1 in self.world.segments_m:
            s = pymunk.Segment(static, (float(x0), float(y0)), (float(x1), float(y1)), WALL_SKIN_M)
            s.friction = 0.0
            s.elasticity = 0.0
            s.collision_type = WALL_COLLISION_TYPE
            s.filter = pymunk.ShapeFilter(categories=0b01)
            shapes.append(s)
        space.add(*shapes)
        self._substep_dt_key = -1.0
        self._substeps = 1
        return space

    def _add_robot_body(
        self, space: pymunk.Space
    ) -> tuple[pymunk.Body, pymunk.Circle, pymunk.Body]:
        """Add a robot to ``space``: its body, wall disc, control body and drive joints;
        returns ``(body, disc, control)``."""
        r = self.robot_params
        moment = pymunk.moment_for_circle(r.mass_kg, 0.0, r.radius_m)
        body = pymunk.Body(r.mass_kg, moment)
        # Walls get a skin and the disc shrinks by the same amount: the contact geometry is
        # unchanged, but rounded wall ends give clean contact normals at corners.
        shape = pymunk.Circle(body, r.radius_m - WALL_SKIN_M)
        shape.friction = 0.0
        shape.elasticity = 0.0
        shape.collision_type = ROBOT_COLLISION_TYPE
        shape.filter = pymunk.ShapeFilter(categories=0b10)
        control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        pivot = pymunk.PivotJoint(control, body, (0.0, 0.0), (0.0, 0.0))
        pivot.max_bias = 0.0
        pivot.max_force = r.max_drive_force_n
        gear = pymunk.GearJoint(control, body, 0.0, 1.0)
        gear.error_bias = 0.0
        gear.max_bias = 0.0
        gear.max_force = r.max_turn_torque_nm
        space.add(body, shape, control, pivot, gear)
        return body, shape, control

    def _substeps_for(self, dt_s: float) -> int:
        if dt_s != self._substep_dt_key:
            travel = self.robot_params.max_linear_speed_mps * dt_s
            pp = self.physics_params
            self._substeps = min(
                pp.max_substeps, max(1, math.ceil(travel / pp.max_substep_travel_m))
            )
            self._substep_dt_key = dt_s
        return self._substeps

    def _drive_arc(self, body: pymunk.Body, v: float, w: float, dt_s: float) -> None:
        """Move ``body`` along the exact differential-drive arc of ``(v, w)`` for ``dt_s``."""
        # The C calls behind body.position, body.angle, ... = and reindex_shapes_for_body.
        b = body._body
        p = _cp.cpBodyGetPosition(b)
        x, y = p.x, p.y
        yaw = _cp.cpBodyGetAngle(b)
        if abs(w) > 1e-9:
            yaw2 = yaw + w * dt_s
            x += v / w * (math.sin(yaw2) - math.sin(yaw))
            y -= v / w * (math.cos(yaw2) - math.cos(yaw))
        else:
            yaw2 = yaw
            x += v * dt_s * math.cos(yaw)
            y += v * dt_s * math.sin(yaw)
        _cp.cpBodySetPosition(b, (x, y))
        _cp.cpBodySetAngle(b, yaw2)
        _cp.cpBodySetVelocity(b, (v * math.cos(yaw2), v * math.sin(yaw2)))
        _cp.cpBodySetAngularVelocity(b, w)
        _cp.cpSpaceReindexShapesForBody(self.space._space, b)

    def _inputs_state(self) -> dict:
        """The inputs a copy rebuilds its space from (the start of ``__getstate__``)."""
        return {
            "world": self.world,
            "robot_params": self.robot_params,
            "physics_params": self.physics_params,
        }

    def _restore_inputs(self, state: dict) -> None:
        self.world = state["world"]
        self.robot_params = state["robot_params"]
        self.physics_params = state["physics_params"]


class RobotSim(PymunkSim):
    """Pymunk space holding one world's walls and the robot.

    Args:
        world: The walls.
        robot: Robot parameters.
        physics: Stepping parameters.
    """

    def __init__(self, world: World, robot: RobotParams, physics: PhysicsParams) -> None:
        self.world = world
        self.robot_params = robot
        self.physics_params = physics
        self._build()

    def _build(self) -> None:
        space = self._new_space()
        body, _, control = self._add_robot_body(space)
        self._wall_filter = pymunk.ShapeFilter(mask=0b01)
        self._query_info = _ffi.new("cpPointQueryInfo *")  # scratch for the near-wall query
        self._touching = 0
        self._began = False
        self._suppress_begin = False

        # begin/separate fire only when a contact starts or ends, so they cost nothing while the
        # robot drives in free space; a pre-solve callback would run every substep.
        def _begin(arbiter: pymunk.Arbiter, space_: pymunk.Space, data: dict) -> None:
            if self._touching == 0 and not self._suppress_begin:
                self._began = True
            self._touching += 1

        def _separate(arbiter: pymunk.Arbiter, space_: pymunk.Space, data: dict) -> None:
            self._touching = max(0, self._touching - 1)

        space.on_collision(
            ROBOT_COLLISION_TYPE, WALL_COLLISION_TYPE, begin=_begin, separate=_separate
        )
        self.space = space
        self.body = body
        self.control = control
        self.collisions = 0
        self.in_contact = False

    def reset(self, pose: tuple[float, float, float]) -> None:
        """Place the robot at rest at ``pose`` = (x_m, y_m, yaw_rad)."""
        x, y, yaw = (float(v) for v in pose)
        for b in (self.body, self.control):
            b.position = (x, y)
            b.angle = yaw
            b.velocity = (0.0, 0.0)
            b.angular_velocity = 0.0
        self.space.reindex_shapes_for_body(self.body)
        self.collisions = 0
        self.in_contact = False
        self._began = False
        self._touching = 0

    @property
    def pose(self) -> tuple[float, float, float]:
        b = self.body._body
        p = _cp.cpBodyGetPosition(b)
        return (p.x, p.y, _cp.cpBodyGetAngle(b))

    def step(self, linear_mps: float, angular_radps: float, dt_s: float) -> bool:
        """Drive with body-frame (v, omega) for ``dt_s``; return True if a new collision began.

        Far from every wall (none within radius + the largest travel of the step + 1 cm) the
        robot cannot touch anything, so it moves along the exact differential-drive arc without
        calling the solver. Near walls pymunk integrates with a *fixed* substep (Chipmunk's
        cached contact impulses assume a constant timestep; varying it makes the solver eject
        the robot through walls). A collision is counted once per contact episode.
        """
        rp = self.robot_params
        n = self._substeps_for(dt_s)
        reach = rp.radius_m + rp.max_linear_speed_mps * dt_s + 0.01
        # Space.point_query_nearest without its Python result objects: any wall within reach?
        body_p = self.body._body
        near = _cp.cpSpacePointQueryNearest(
            self.space._space,
            _cp.cpBodyGetPosition(body_p),
            reach,
            self._wall_filter,
            self._query_info,
        )
        if near == _ffi.NULL and self._touching == 0:
            self._drive_arc(self.body, linear_mps, angular_radps, dt_s)
            self.in_contact = False
            return False
        h = dt_s / n
        self._began = False
        # The pivot and gear joints have no positional bias: only the control body's velocities
        # matter; keeping it on the robot avoids a large lever arm in the pivot constraint.
        control_p = self.control._body
        _cp.cpBodySetPosition(control_p, _cp.cpBodyGetPosition(body_p))  # control.position = ...
        _cp.cpBodySetAngularVelocity(control_p, angular_radps)
        space = self.space
        if space._bodies_to_check:  # pymunk checks new bodies' masses once, in Space.step
            space.step(0.0)
        # The substeps call Chipmunk through pymunk's own binding: the same C calls as
        # ``body.angle``, ``control.velocity = ...`` and ``space.step(h)``, without their Python
        # wrappers (nothing is added or removed and no post-step callback is registered here).
        space_p = space._space
        get_angle, set_velocity, cp_step = (
            _cp.cpBodyGetAngle,
            _cp.cpBodySetVelocity,
            _cp.cpSpaceStep,
        )
        space._locked = True
        try:
            for _ in range(n):
                yaw = get_angle(body_p)
                set_velocity(control_p, (linear_mps * math.cos(yaw), linear_mps * math.sin(yaw)))
                cp_step(space_p, h)
        finally:
            space._locked = False
        self._suppress_begin = False
        new_collision = self._began
        if new_collision:
            self.collisions += 1
        self.in_contact = self._touching > 0
        return new_collision

    # Pymunk objects hold C pointers: pickle the inputs and rebuild.
    def __getstate__(self) -> dict:
        return {
            **self._inputs_state(),
            "pose": self.pose,
            "velocity": tuple(self.body.velocity),
            "angular_velocity": float(self.body.angular_velocity),
            "collisions": self.collisions,
            "touching": self._touching > 0,
        }

    def __setstate__(self, state: dict) -> None:
        self._restore_inputs(state)
        self._build()
        self.reset(state["pose"])
        self.body.velocity = state["velocity"]
        self.body.angular_velocity = state["angular_velocity"]
        self.collisions = state["collisions"]
        # The rebuilt space re-detects a contact that was already counted: do not count it again.
        self._suppress_begin = bool(state["touching"])


def nearest_wall_distance_m(segments_m: np.ndarray, x_m: float, y_m: float) -> float:
    """Distance from a point to the nearest wall segment (used by tests and diagnostics)."""
    seg = np.asarray(segments_m, dtype=np.float64)
    a = seg[:, 0:2]
    b = seg[:, 2:4]
    ab = b - a
    p = np.array([x_m, y_m])
    denom = np.einsum("ij,ij->i", ab, ab)
    t = np.where(denom > 0, np.einsum("ij,ij->i", p - a, ab) / np.where(denom > 0, denom, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    closest = a + ab * t[:, None]
    return float(np.min(np.hypot(*(closest - p).T))) if len(seg) else math.inf
