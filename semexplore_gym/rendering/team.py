"""Drawing a team: the shared map, then one colour per robot (trajectory, path, goal, body)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from semexplore_gym.core.grid import GridGeometry

#: One colour per robot (up to 8), distinguishable on the grey map.
ROBOT_COLOURS: tuple[tuple[int, int, int], ...] = (
    (0, 120, 255),
    (230, 60, 0),
    (0, 160, 70),
    (170, 40, 200),
    (220, 170, 0),
    (0, 170, 190),
    (200, 0, 100),
    (110, 80, 40),
)


@dataclass(frozen=True)
class TeamSnapshot:
    """Everything one team frame shows, copied out of the env."""

    map: np.ndarray
    geometry: GridGeometry
    segments_m: np.ndarray
    poses: list[tuple[float, float, float]]
    radius_m: float
    trajectories_m: list[np.ndarray]
    goals_m: list[Any]
    paths_m: list[Any]
    text: str = ""


def draw_team(renderer: Any, snap: TeamSnapshot) -> np.ndarray:
    """An ``(H_px, W_px, 3)`` uint8 frame of ``snap`` drawn with a
    :class:`~semexplore_gym.rendering.renderer.Renderer` (its map and wall layers)."""
    from PIL import Image, ImageDraw

    from semexplore_gym.rendering.renderer import RenderSnapshot

    x0, y0, yaw0 = snap.poses[0]
    # The map, walls and status text as the single-robot frame draws them, robot drawn over.
    base = renderer.draw(
        RenderSnapshot(
            map=snap.map,
            geometry=snap.geometry,
            segments_m=snap.segments_m,
            pose=(x0, y0, yaw0),
            radius_m=snap.radius_m,
            text=snap.text,
        )
    )
    img = Image.fromarray(base)
    draw = ImageDraw.Draw(img, "RGBA")
    w = max(2, int(round(renderer.px_per_cell * 0.6)))
    rpx = snap.radius_m / snap.geometry.resolution_m * renderer.px_per_cell
    for i, pose in enumerate(snap.poses):
        colour = ROBOT_COLOURS[i % len(ROBOT_COLOURS)]
        traj = snap.trajectories_m[i]
        if traj is not None and len(traj) >= 2:
            draw.line([tuple(q) for q in renderer.world_to_px(traj)], fill=(*colour, 170), width=w)
        path = snap.paths_m[i] if i < len(snap.paths_m) else None
        if path is not None and len(path) >= 2:
            pts = renderer.world_to_px(np.asarray(path, dtype=np.float64))
            draw.line([tuple(q) for q in pts], fill=(*colour, 255), width=1)
        goal = snap.goals_m[i] if i < len(snap.goals_m) else None
        if goal is not None:
            ((u, v),) = renderer.world_to_px(np.asarray(goal, dtype=np.float64)[:2])
            m = max(4.0, rpx)
            draw.line([(u - m, v - m), (u + m, v + m)], fill=(*colour, 255), width=3)
            draw.line([(u - m, v + m), (u + m, v - m)], fill=(*colour, 255), width=3)
        x, y, yaw = pose
        ((u, v),) = renderer.world_to_px(np.array([[x, y]]))
        r = max(3.0, rpx)
        draw.ellipse([u - r, v - r, u + r, v + r], fill=(*colour, 255), outline=(0, 0, 0, 255))
        draw.line(
            [(u, v), (u + r * np.cos(yaw), v - r * np.sin(yaw))], fill=(255, 255, 255, 255), width=2
        )
    return np.asarray(img, dtype=np.uint8)
