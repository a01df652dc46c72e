"""Drawing an env state for people: a read-only snapshot in, an RGB array out.

The renderer never touches simulator state: the env hands it a :class:`RenderSnapshot`.
Layers, bottom to top: the occupancy map (white free, grey unknown, black occupied), the
ground-truth walls (faint blue), a policy overlay, LiDAR rays, the trajectory and the robot.

Overlay keys (all optional), set with ``env.unwrapped.set_overlay(policy.overlay())``:

=================  =========================================================
``area_types``     (H, W) int raster of ``AreaType`` values, -1 where none
``paths_m``        list of (K, 2) polylines in world metres (the chosen path)
``goal_m``         (x, y) the chosen goal
``frontiers_m``    list of (x, y) frontier targets
``points_m``       list of (x, y) extra markers
``text``           a line of text drawn under the status line
=================  =========================================================
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

#: Colours of semantic area types (GRID-FAST codes 0/10/20/30).
AREA_COLOURS: dict[int, tuple[int, int, int]] = {
    0: (230, 85, 60),  # intersection: red
    10: (90, 160, 230),  # pathway: blue
    20: (150, 150, 150),  # dead end: grey
    30: (70, 190, 90),  # frontier pathway: green
}


_GRID_LUT = np.zeros((256, 3), dtype=np.uint8)
_GRID_LUT[FREE] = (255, 255, 255)
_GRID_LUT[UNKNOWN] = (200, 200, 200)
_GRID_LUT[OCCUPIED] = (20, 20, 20)
_GRID_LUT.setflags(write=False)


@dataclass(frozen=True)
class RenderSnapshot:
    """Everything one frame shows, copied out of the env."""

    map: np.ndarray
    geometry: GridGeometry
    segments_m: np.ndarray
    pose: tuple[float, float, float]
    radius_m: float
    scan: np.ndarray | None = None
    beam_angles_rad: np.ndarray | None = None
    sensor_pose: tuple[float, float, float] | None = None
    max_range_m: float = 3.5
    trajectory_m: np.ndarray | None = None
    overlay: dict[str, Any] = field(default_factory=dict)
    text: str = ""


class Renderer:
    """Turns snapshots into RGB frames (and shows them in a window for ``human`` mode).

    Args:
        geometry: Frame of the maps that will be drawn.
        max_size_px: Longest side of the frame; the map is scaled to fit.
    """

    def __init__(self, geometry: GridGeometry, max_size_px: int = 720) -> None:
        self.geometry = geometry
        h, w = geometry.shape
        self.px_per_cell = (
            max(1.0, min(8.0, max_size_px / max(h, w)))
            if max(h, w) <= max_size_px
            else max_size_px / max(h, w)
        )
        self.size_px = (
            max(1, int(round(w * self.px_per_cell))),
            max(1, int(round(h * self.px_per_cell))),
        )
        self._window: Any = None
        self._clock: Any = None

    def world_to_px(self, xy_m: np.ndarray) -> np.ndarray:
        """World metres -> image pixel (u right, v down) for (N, 2) points."""
        g = self.geometry
        xy = np.asarray(xy_m, dtype=np.float64).reshape(-1, 2)
        u = (xy[:, 0] - g.origin_x_m) / g.resolution_m * self.px_per_cell
        v = self.size_px[1] - (xy[:, 1] - g.origin_y_m) / g.resolution_m * self.px_per_cell
        return np.stack([u, v], axis=1)

    def _base_image(self, grid: np.ndarray, area_types: np.ndarray | None) -> Any:
        """The map as a PIL image at frame size (colour lookup at grid size, then a NEAREST resize)."""
        from PIL import Image

        rgb = _GRID_LUT[grid]
        if area_types is not None and area_types.shape == grid.shape:
            for code, colour in AREA_COLOURS.items():
                m = area_types == code
                if m.any():
                    rgb[m] = (0.45 * rgb[m] + 0.55 * np.array(colour)).astype(np.uint8)
        # Row 0 is the lowest y: flip so that y points up.
        small = Image.fromarray(np.ascontiguousarray(rgb[::-1]))
        return small.resize(self.size_px, Image.Resampling.NEAREST)

    def draw(self, snap: RenderSnapshot) -> np.ndarray:
        """Return an (H_px, W_px, 3) uint8 frame."""
        from PIL import ImageDraw

        ov = snap.overlay or {}
        img = self._base_image(snap.map, ov.get("area_types"))
        draw = ImageDraw.Draw(img, "RGBA")
        lw = max(1, int(round(self.px_per_cell * 0.4)))
        if len(snap.segments_m):
            a = self.world_to_px(snap.segments_m[:, 0:2])
            b = self.world_to_px(snap.segments_m[:, 2:4])
            for (u0, v0), (u1, v1) in zip(a, b, strict=True):
                draw.line([(u0, v0), (u1, v1)], fill=(60, 90, 220, 90), width=lw)
        hits_px = None
        if (
            snap.scan is not None
            and snap.beam_angles_rad is not None
            and snap.sensor_pose is not None
        ):
            sx, sy, syaw = snap.sensor_pose
            ok = snap.scan > 0
            r = snap.scan[ok].astype(np.float64)
            ang = syaw + snap.beam_angles_rad[ok]
            ends = self.world_to_px(np.stack([sx + r * np.cos(ang), sy + r * np.sin(ang)], axis=1))
            if len(ends) >= 3:
                # The scanned area as one translucent polygon: one draw call, not a line per beam.
                draw.polygon([tuple(q) for q in ends], fill=(255, 140, 0, 45))
            hits_px = ends[r < snap.max_range_m]
        for path in ov.get("paths_m", []) or []:
            p = np.asarray(path, dtype=np.float64)
            if p.ndim == 2 and len(p) >= 2:
                draw.line(
                    [tuple(q) for q in self.world_to_px(p)],
                    fill=(160, 40, 200, 230),
                    width=max(2, lw + 1),
                )
        marker = max(3.0, self.px_per_cell * 1.5)
        for pt in ov.get("frontiers_m", []) or []:
            u, v = self.world_to_px(np.asarray(pt, dtype=np.float64)[:2])[0]
            draw.ellipse(
                [u - marker, v - marker, u + marker, v + marker], outline=(0, 140, 60, 255), width=2
            )
        for pt in ov.get("points_m", []) or []:
            u, v = self.world_to_px(np.asarray(pt, dtype=np.float64)[:2])[0]
            draw.rectangle(
                [u - marker / 2, v - marker / 2, u + marker / 2, v + marker / 2],
                fill=(40, 40, 200, 200),
            )
        if ov.get("goal_m") is not None:
            u, v = self.world_to_px(np.asarray(ov["goal_m"], dtype=np.float64)[:2])[0]
            m = marker * 1.5
            draw.line([(u - m, v - m), (u + m, v + m)], fill=(200, 0, 160, 255), width=3)
            draw.line([(u - m, v + m), (u + m, v - m)], fill=(200, 0, 160, 255), width=3)
        if snap.trajectory_m is not None and len(snap.trajectory_m) >= 2:
            draw.line(
                [tuple(q) for q in self.world_to_px(snap.trajectory_m)],
                fill=(0, 120, 255, 200),
                width=max(1, lw),
            )
        if hits_px is not None and len(hits_px):
            draw.point([tuple(q) for q in hits_px], fill=(230, 60, 0, 255))
        x, y, yaw = snap.pose
        ((u, v),) = self.world_to_px(np.array([[x, y]]))
        rpx = snap.radius_m / self.geometry.resolution_m * self.px_per_cell
        draw.ellipse(
            [u - rpx, v - rpx, u + rpx, v + rpx], fill=(0, 90, 200, 220), outline=(0, 0, 0, 255)
        )
        draw.line(
            [(u, v), (u + rpx * 1.6 * math.cos(yaw), v - rpx * 1.6 * math.sin(yaw))],
            fill=(255, 255, 255, 255),
            width=2,
        )
        lines = [t for t in (snap.text, ov.get("text", "")) if t]
        for i, t in enumerate(lines):
            draw.text((4, 4 + 12 * i), t, fill=(0, 0, 0, 255))
        return np.asarray(img, dtype=np.uint8)

    def show(self, frame: np.ndarray, fps: float) -> None:
        """Show a frame in a pygame window (``human`` render mode)."""
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        try:
            import pygame
        except ImportError as e:  # pragma: no cover - depends on the optional extra
            from gymnasium.error import DependencyNotInstalled

            raise DependencyNotInstalled(
                'render_mode="human" needs pygame: pip install "semexplore-gym[render]"'
            ) from e
        if self._window is None:
            # The display alone (pygame.init() would open the audio device too: ALSA errors on
            # a machine without sound). Without X11 or Wayland there is nothing to show the
            # window on: SDL's dummy driver draws it quietly (its fall-backs print XDG errors).
            if sys.platform.startswith("linux") and not (
                os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
            ):
                os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
            pygame.display.init()
            self._window = pygame.display.set_mode((frame.shape[1], frame.shape[0]))
            pygame.display.set_caption("SemanticExplore")
            self._clock = pygame.time.Clock()
        surf = pygame.surfarray.make_surface(np.transpose(frame, (1, 0, 2)))
        self._window.blit(surf, (0, 0))
        pygame.event.pump()
        pygame.display.flip()
        self._clock.tick(fps)

    def close(self) -> None:
        if self._window is not None:
            import pygame

            pygame.display.quit()
            pygame.quit()
            self._window = None
