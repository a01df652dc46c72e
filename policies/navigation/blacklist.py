"""The goals a policy gave up on: :class:`GoalBlacklist`.

The frontier baselines' :class:`~semexplore_gym.policies.navigation.navigator.Navigator` and the
semantic expert's goal memory both skip new goals near a blacklisted one (a box or a disc; see
:mod:`semexplore_gym.policies.navigation` for who uses which).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Literal, cast

__all__ = ["GoalBlacklist"]


class GoalBlacklist:
    """Goals given up on; a point near one of them is blacklisted too.

    Args:
        size_m: Radius of the disc (``shape="disc"``) or half-size of the axis-aligned box
            (``shape="box"``, ROS ``frontier_exploration``'s ``blacklist_box_size``) round each
            blacklisted goal.
        shape: ``"disc"`` or ``"box"``; the boundary belongs to the blacklisted region.
    """

    def __init__(self, size_m: float, shape: Literal["disc", "box"] = "disc") -> None:
        if shape not in ("disc", "box"):
            raise ValueError(f"shape must be 'disc' or 'box', got {shape!r}")
        self.size_m = float(size_m)
        self.shape = shape
        self.points_m: list[tuple[float, float]] = []

    def add(self, xy_m: tuple[float, float]) -> None:
        """Blacklist the goal at ``xy_m`` (metres, world frame)."""
        self.points_m.append(xy_m)

    def clear(self) -> None:
        """Forget every blacklisted goal."""
        self.points_m.clear()

    def __contains__(self, xy_m: object) -> bool:
        """Whether ``xy_m`` lies within the disc or box of a blacklisted goal."""
        x, y = cast("tuple[float, float]", xy_m)
        size = self.size_m
        if self.shape == "box":
            return any(abs(x - bx) <= size and abs(y - by) <= size for bx, by in self.points_m)
        return any(math.dist((x, y), b) <= size for b in self.points_m)

    def __len__(self) -> int:
        return len(self.points_m)

    def __iter__(self) -> Iterator[tuple[float, float]]:
        return iter(self.points_m)
