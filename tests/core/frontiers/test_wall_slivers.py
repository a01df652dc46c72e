"""Wall slivers: thin UNKNOWN strips along walls read as wall; wide unknown space stays."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from semexplore_gym.core.frontiers.reachable import frontier_groups
from semexplore_gym.core.frontiers.wall_slivers import (
    fill_wall_slivers,
    wall_sliver_mask,
    wall_sliver_mask_box,
)
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN

_CODE = {"#": OCCUPIED, ".": FREE, "?": UNKNOWN}

#: A corner of a SLAM map (an expert mission on a development office, 25 m, seed 7708, after
#: 99 % coverage): the outside of the building above, an inner wall meeting the outer wall
#: below. The SLAM map drew the inner wall's faces one cell thin with its inside UNKNOWN, and
#: the junction open: free cells beside a wedge of UNKNOWN that reaches the outside, a frontier
#: with deep unknown space behind it, where the map of the same scans at the true poses has
#: none worth a drive. The expert drove there after the floor was done.
JUNCTION = ["?" * 32] * 10 + [
    "##########???????.?#############",
    "..........?????.................",
    ".........#????..................",
    "..........??....................",
] + [".........#?#...................."] * 16


def _grid(rows: list[str]) -> np.ndarray:
    return np.array([[_CODE[ch] for ch in r] for r in rows], dtype=np.uint8)


def _reference(grid: np.ndarray, width_cells: float, gap_cells: int) -> np.ndarray:
    """The definition with scipy's binary morphology on a generously padded grid."""
    r = width_cells / 2.0
    k = int(np.ceil(r))
    y, x = np.mgrid[-k : k + 1, -k : k + 1]
    disc = x * x + y * y <= r * r + 1e-9
    pad = 2 * k + 2
    unknown = np.pad(grid == UNKNOWN, pad, constant_values=True)
    opened = ndimage.binary_opening(unknown, structure=disc)[pad:-pad, pad:-pad]
    near = ndimage.binary_dilation(
        grid == OCCUPIED, structure=np.ones((2 * gap_cells + 1,) * 2, dtype=bool)
    )
    return (grid == UNKNOWN) & ~opened & near


def test_the_mask_is_the_opening_definition_on_random_grids() -> None:
    rng = np.random.default_rng(3)
    values = np.array([OCCUPIED, UNKNOWN, FREE], dtype=np.uint8)
    for _ in range(150):
        shape = (int(rng.integers(3, 40)), int(rng.integers(3, 40)))
        g = rng.choice(values, size=shape, p=[0.2, 0.5, 0.3])
        width = float(rng.choice([1.0, 2.0, 3.3, 5.0, 6.0, 7.5]))
        gap = int(rng.integers(0, 4))
        assert np.array_equal(wall_sliver_mask(g, width, gap), _reference(g, width, gap))


def test_a_box_of_the_mask_needs_only_the_box_and_its_context() -> None:
    rng = np.random.default_rng(5)
    values = np.array([OCCUPIED, UNKNOWN, FREE], dtype=np.uint8)
    for _ in range(150):
        g = rng.choice(values, size=(int(rng.integers(5, 60)), int(rng.integers(5, 60))))
        width, gap = float(rng.choice([2.0, 3.3, 5.0, 6.0])), int(rng.integers(0, 3))
        r0 = int(rng.integers(0, g.shape[0]))
        r1 = int(rng.integers(r0, g.shape[0] + 1))
        c0 = int(rng.integers(0, g.shape[1]))
        c1 = int(rng.integers(c0, g.shape[1] + 1))
        box = wall_sliver_mask_box(g, (r0, r1), (c0, c1), width, gap)
        assert np.array_equal(box, wall_sliver_mask(g, width, gap)[r0:r1, c0:c1])
    with pytest.raises(ValueError, match=r"box rows \(0, 99\).*outside"):
        wall_sliver_mask_box(g, (0, 99), (0, 1), 5.0)


def test_a_slam_junction_loses_its_frontier_and_the_wall_inside_becomes_wall() -> None:
    g = _grid(JUNCTION)
    filled = fill_wall_slivers(g, 0.25, 0.05)
    # the inside of the inner wall (one cell between its two faces) now reads as wall
    assert (filled[14:, 10] == OCCUPIED).all() and (g[14:, 10] == UNKNOWN).all()
    # the outside of the building stays unknown, every known cell stays as it was
    assert (filled[:10] == UNKNOWN).all()
    assert np.array_equal(filled[g != UNKNOWN], g[g != UNKNOWN])
    # The expert's grid fallback (groups of 7 cells, 4 cells of unknown depth) finds the
    # junction's frontier on the map as observed, and none once the slivers are wall.
    assert frontier_groups(g, 7, 4.0)[1] == 1
    assert frontier_groups(filled, 7, 4.0)[1] == 0


def test_wide_unknown_space_and_strips_away_from_walls_stay_unknown() -> None:
    # A room whose right wall has a 0.8 m door into an unseen room, and two LiDAR rays that
    # crossed unknown space in the open, a one-cell strip of UNKNOWN between them.
    g = np.full((40, 60), UNKNOWN, dtype=np.uint8)
    g[5:35, 5:30] = FREE
    g[4, 4:31] = g[35, 4:31] = OCCUPIED
    g[4:36, 4] = g[4:36, 30] = OCCUPIED
    g[16:32, 30] = FREE  # the door, 16 cells
    g[18, 31:55] = g[20, 31:55] = FREE  # rays through it, a strip between them
    filled = fill_wall_slivers(g, 0.25, 0.05)
    assert filled[19, 40] == UNKNOWN  # the strip between the rays, far from walls
    assert (filled[25:30, 35:55] == UNKNOWN).all()  # the room behind the door
    before, after = frontier_groups(g, 7, 4.0), frontier_groups(filled, 7, 4.0)
    assert after[1] == before[1] >= 1


def test_a_grid_without_slivers_comes_back_as_itself() -> None:
    g = np.full((20, 20), FREE, dtype=np.uint8)
    g[0, :] = OCCUPIED
    assert fill_wall_slivers(g, 0.25, 0.05) is g
    unknown = np.full((20, 20), UNKNOWN, dtype=np.uint8)
    assert not wall_sliver_mask(unknown, 5.0).any()


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda g: wall_sliver_mask(g, 0.0), "max_width_cells.*0.0"),
        (lambda g: wall_sliver_mask(g, float("nan")), "max_width_cells.*nan"),
        (lambda g: wall_sliver_mask(g, 5.0, -1), "wall_gap_cells.*-1"),
        (lambda g: wall_sliver_mask(g, 5.0, 1.5), "wall_gap_cells.*1.5"),
        (lambda g: fill_wall_slivers(g, 0.25, 0.0), "resolution_m.*0.0"),
        (lambda g: fill_wall_slivers(np.where(g == FREE, np.uint8(7), g), 0.25, 0.05), "grid"),
    ],
)
def test_bad_input_is_a_clear_error(call, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        call(_grid(JUNCTION))
