"""World specs, the fixed mazes, procedural families, start poses and reachable area."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from scipy import ndimage

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds import (
    World,
    distance_to_segments_m,
    fixed_mazes,
    list_world_names,
    parse_world_spec,
    rasterize_free,
    reachable_free_mask,
    sample_start_pose,
    segment_distance_field,
    validate_start_pose,
    world_family_parameters,
    world_from_segments,
)
from semexplore_gym.maps import make_world

ROBOT_RADIUS_M = 0.105
CLEARANCE_M = ROBOT_RADIUS_M + 0.05
FOUR = ndimage.generate_binary_structure(2, 1)


def _box(x0: float, y0: float, x1: float, y1: float) -> list[tuple[float, float, float, float]]:
    return [(x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)]


def _touches_border(mask: np.ndarray) -> bool:
    return bool(mask[0].any() or mask[-1].any() or mask[:, 0].any() or mask[:, -1].any())


# --------------------------------------------------------------------------- specs


def test_list_world_names() -> None:
    assert list_world_names() == ["cave", "forest", "maze", "maze1", "maze2", "noisecave", "office"]


def test_parse_world_spec() -> None:
    assert parse_world_spec("maze1") == ("maze1", {})
    assert parse_world_spec(" maze : seed=3, size_m = 10 ,braid=0.3") == (
        "maze",
        {"seed": "3", "size_m": "10", "braid": "0.3"},
    )
    assert parse_world_spec("office:") == ("office", {})
    with pytest.raises(ValueError, match="'size_m' given twice"):
        parse_world_spec("maze:size_m=3,size_m=4")
    with pytest.raises(ValueError, match="not key=value"):
        parse_world_spec("maze:seed")


def test_unknown_world_lists_available() -> None:
    with pytest.raises(ValueError, match=r"unknown world 'mase1'.*maze1.*maze2.*office"):
        make_world("mase1")


def test_unknown_parameter_lists_valid_ones() -> None:
    with pytest.raises(
        ValueError, match=r"unknown maze parameter 'width'.*corridor_width_m.*braid"
    ):
        make_world("maze:width=3")


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("maze:seed=1.5", "seed='1.5' must be an integer"),
        ("office:size_m=big", "size_m='big' must be a number"),
        ("cave:size_m=nan", "must be finite"),
        ("maze:corridor_width_m=0.3", r"corridor_width_m=0.3 is outside \[0.6"),
        ("maze:braid=1.5", r"braid=1.5 is outside"),
        ("office:seed=-2", "seed=-2 must be a non-negative integer"),
        ("maze1:seed=3", "fixed and takes no parameters"),
    ],
)
def test_bad_parameters(spec: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        make_world(spec)


def test_missing_file_names_path(tmp_path) -> None:
    missing = tmp_path / "nowhere.yaml"
    with pytest.raises(FileNotFoundError, match="nowhere.yaml"):
        make_world(missing)
    with pytest.raises(FileNotFoundError, match="plan.json"):
        make_world(str(tmp_path / "plan.json"))


def test_family_defaults() -> None:
    defaults = world_family_parameters("office")
    assert defaults["size_m"] == 20.0 and "seed" in defaults
    with pytest.raises(ValueError, match="unknown world family"):
        world_family_parameters("castle")


def test_seed_drawn_from_rng_is_reproducible() -> None:
    a = make_world("maze:size_m=5", np.random.default_rng(7))
    b = make_world("maze:size_m=5", np.random.default_rng(7))
    c = make_world("maze:size_m=5", np.random.default_rng(8))
    assert np.array_equal(a.segments_m, b.segments_m)
    assert (
        a.metadata["params"]["seed"] == b.metadata["params"]["seed"] != c.metadata["params"]["seed"]
    )
    # The resolved spec rebuilds the same world.
    again = make_world(a.metadata["spec"])
    assert np.array_equal(again.segments_m, a.segments_m)
    assert a.name == "maze:size_m=5"


def test_world_pickles_with_derived_cache() -> None:
    world = make_world("maze1")
    sample_start_pose(world, np.random.default_rng(0), CLEARANCE_M)
    assert world._derived
    clone = pickle.loads(pickle.dumps(world))
    assert clone._derived == {}
    assert np.array_equal(clone.segments_m, world.segments_m)
    assert np.array_equal(clone.free_mask, world.free_mask)
    assert clone.start_pose == world.start_pose
    pose = sample_start_pose(clone, np.random.default_rng(0), CLEARANCE_M)
    assert pose == sample_start_pose(world, np.random.default_rng(0), CLEARANCE_M)


# --------------------------------------------------------------------------- fixed mazes


def _walls_from_sketch(
    sketch: str, widths_m: tuple[float, ...], heights_m: tuple[float, ...]
) -> set:
    """Unit wall edges drawn in a maze sketch ('+---+' / '|'), top line = largest y."""
    lines = [ln.strip() for ln in sketch.strip("\n").splitlines() if ln.strip()]
    n_rows, n_cols = (len(lines) - 1) // 2, (len(lines[0]) - 1) // 4
    assert (n_rows, n_cols) == (len(heights_m), len(widths_m))
    xs = np.round(np.concatenate([[0.0], np.cumsum(widths_m)]), 6)
    ys = np.round(np.concatenate([[0.0], np.cumsum(heights_m)]), 6)
    edges = set()
    for i, line in enumerate(lines):
        line = line.ljust(4 * n_cols + 1)
        if i % 2 == 0:
            k = n_rows - i // 2
            for c in range(n_cols):
                if line[4 * c + 1 : 4 * c + 4] == "---":
                    edges.add((xs[c], ys[k], xs[c + 1], ys[k]))
        else:
            r = n_rows - 1 - i // 2
            for c in range(n_cols + 1):
                if line[4 * c] == "|":
                    edges.add((xs[c], ys[r], xs[c], ys[r + 1]))
    return edges


def _unit_edges(
    segments: np.ndarray, widths_m: tuple[float, ...], heights_m: tuple[float, ...]
) -> set:
    """Split merged axis-aligned segments back into cell edges of the maze grid."""
    xs = np.round(np.concatenate([[0.0], np.cumsum(widths_m)]), 6)
    ys = np.round(np.concatenate([[0.0], np.cumsum(heights_m)]), 6)
    edges = set()
    for x0, y0, x1, y1 in np.round(segments, 6):
        if y0 == y1:
            lo, hi = sorted((x0, x1))
            inner = xs[(xs >= lo) & (xs <= hi)]
            assert inner[0] == lo and inner[-1] == hi, "segment does not end on grid lines"
            edges |= {(a, y0, b, y0) for a, b in zip(inner[:-1], inner[1:], strict=True)}
        else:
            assert x0 == x1, "maze walls are axis-aligned"
            lo, hi = sorted((y0, y1))
            inner = ys[(ys >= lo) & (ys <= hi)]
            assert inner[0] == lo and inner[-1] == hi
            edges |= {(x0, a, x0, b) for a, b in zip(inner[:-1], inner[1:], strict=True)}
    return edges


def _cell_degrees(
    edges: set, widths_m: tuple[float, ...], heights_m: tuple[float, ...]
) -> np.ndarray:
    xs = np.round(np.concatenate([[0.0], np.cumsum(widths_m)]), 6)
    ys = np.round(np.concatenate([[0.0], np.cumsum(heights_m)]), 6)
    deg = np.zeros((len(heights_m), len(widths_m)), dtype=int)
    for r in range(len(heights_m)):
        for c in range(len(widths_m)):
            sides = [
                (xs[c], ys[r], xs[c + 1], ys[r]),
                (xs[c], ys[r + 1], xs[c + 1], ys[r + 1]),
                (xs[c], ys[r], xs[c], ys[r + 1]),
                (xs[c + 1], ys[r], xs[c + 1], ys[r + 1]),
            ]
            deg[r, c] = sum(s not in edges for s in sides)
    return deg


MAZES = [
    (
        "maze1",
        fixed_mazes.make_maze1,
        fixed_mazes.MAZE1_COLUMN_WIDTHS_M,
        fixed_mazes.MAZE1_ROW_HEIGHTS_M,
    ),
    (
        "maze2",
        fixed_mazes.make_maze2,
        fixed_mazes.MAZE2_COLUMN_WIDTHS_M,
        fixed_mazes.MAZE2_ROW_HEIGHTS_M,
    ),
]


@pytest.mark.parametrize(("name", "maker", "widths", "heights"), MAZES)
def test_fixed_maze_matches_its_sketch_and_has_junctions(name, maker, widths, heights) -> None:
    world = make_world(name)
    sketch = maker.__doc__.split("::", 1)[1]
    drawn = _walls_from_sketch(sketch, widths, heights)
    assert _unit_edges(world.segments_m, widths, heights) == drawn
    deg = _cell_degrees(drawn, widths, heights)
    assert (deg == 4).sum() >= 2
    assert (deg == 3).sum() >= 6
    assert (deg == 1).sum() >= 5  # dead ends
    # Independent loops of the cell graph: edges - nodes + 1 (the maze is connected).
    assert deg.sum() // 2 - deg.size + 1 >= 3


@pytest.mark.parametrize("name", ["maze1", "maze2"])
def test_fixed_maze_size_corridors_and_enclosure(name: str) -> None:
    world = make_world(name)
    assert world.bounds_m == (0.0, 0.0, 7.2, 7.2)
    # Fits the paper's 224 x 224 grid at 0.05 m with a 0.2 m margin.
    env_geometry = GridGeometry.covering(*world.bounds_m, resolution_m=0.05, margin_m=0.2)
    assert env_geometry.shape == (152, 152) and max(env_geometry.shape) <= 224
    validate_start_pose(world, world.start_pose, CLEARANCE_M)

    free = rasterize_free(world, env_geometry)
    assert not _touches_border(free)
    labels, n = ndimage.label(free, structure=FOUR)
    assert n == 1, "all free space is one piece"

    from skimage.morphology import skeletonize

    dist = segment_distance_field(world.segments_m, env_geometry, 2.0)
    # No bottleneck: the centres of 0.58 m disks (0.6 m less rounding) still reach everywhere.
    _, n_wide = ndimage.label(free & (dist >= 0.29), structure=FOUR)
    assert n_wide == 1
    # No open hall: the largest inscribed circle is that of a 4-way junction of 0.9 m corridors.
    assert dist[free].max() <= 0.65
    widths = 2.0 * dist[skeletonize(free)]
    assert 0.6 <= np.median(widths) <= 1.0
    assert np.mean((widths >= 0.6) & (widths <= 1.0)) > 0.8


def test_enclosure_check_detects_a_gap() -> None:
    """The enclosure test above can fail: open one outer wall and free space leaks out."""
    segs = np.array(fixed_mazes.MAZE1_SEGMENTS_M)
    outer_bottom = np.flatnonzero((segs[:, 1] == 0.0) & (segs[:, 3] == 0.0))[0]
    segs[outer_bottom] = (0.0, 0.0, 3.0, 0.0)  # 4.2 m gap
    leaky = world_from_segments("leaky", segs, [(0.45, 0.45)])
    geometry = GridGeometry.covering(*leaky.bounds_m, resolution_m=0.05, margin_m=0.2)
    assert _touches_border(rasterize_free(leaky, geometry))


# --------------------------------------------------------------------------- procedural


@pytest.mark.parametrize(
    "family",
    ["maze:size_m=6,braid=0.5", "office:size_m=16", "cave:size_m=10"],
)
def test_procedural_determinism(family: str) -> None:
    a = make_world(f"{family},seed=3")
    b = make_world(f"{family},seed=3")
    c = make_world(f"{family},seed=4")
    assert np.array_equal(a.segments_m, b.segments_m)
    assert a.start_pose == b.start_pose
    assert a.segments_m.shape != c.segments_m.shape or not np.array_equal(
        a.segments_m, c.segments_m
    )


@pytest.mark.parametrize("family", ["maze:size_m=6", "office:size_m=12", "cave:size_m=8"])
def test_procedural_bounds_do_not_depend_on_seed(family: str) -> None:
    """An env redraws procedural worlds at reset on one map grid, so the box must not move."""
    boxes = {make_world(f"{family},seed={seed}").bounds_m for seed in range(3)}
    assert len(boxes) == 1


def _check_connected_and_enclosed(world: World) -> None:
    geometry = GridGeometry.covering(*world.bounds_m, resolution_m=0.05, margin_m=0.3)
    free = rasterize_free(world, geometry)
    assert not _touches_border(free), f"{world.name}: free space reaches the grid border"
    # Robot-centre space: every part of it must be one piece.
    dist = segment_distance_field(world.segments_m, geometry, 1.0)
    centres = free & (dist >= CLEARANCE_M)
    labels, n = ndimage.label(centres, structure=FOUR)
    sizes = np.bincount(labels.ravel())[1:]
    assert sizes.max() >= 0.995 * sizes.sum(), (
        f"{world.name}: robot space split into {n} parts {sorted(sizes)[-3:]}"
    )
    validate_start_pose(world, world.start_pose, CLEARANCE_M)
    reach = reachable_free_mask(
        world, geometry, world.start_pose[:2], ROBOT_RADIUS_M, CLEARANCE_M, free_mask=free
    )
    assert reach.sum() >= 0.7 * free.sum()


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_maze_family_connected(seed: int) -> None:
    world = make_world(f"maze:seed={seed},size_m=7,corridor_width_m=0.7,braid={seed / 4}")
    _check_connected_and_enclosed(world)
    n = world.metadata["n_cells"]
    assert n == 10 and world.bounds_m == pytest.approx((0.0, 0.0, 7.0, 7.0))


def test_maze_braid_removes_dead_ends() -> None:
    def dead_ends(braid: float) -> int:
        from semexplore_gym.core.worlds.grid_maze import carve_maze

        h, v = carve_maze(12, 12, np.random.default_rng(5), braid)
        opens = (~h[1:]).astype(int) + ~h[:-1] + ~v[:, 1:] + ~v[:, :-1]
        return int((opens == 1).sum())

    assert dead_ends(0.0) > 10
    assert dead_ends(1.0) == 0
    assert dead_ends(0.0) > dead_ends(0.5) > 0


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_office_family_connected(seed: int) -> None:
    world = make_world(f"office:seed={seed},size_m={16 + 4 * seed}")
    _check_connected_and_enclosed(world)
    assert world.metadata["n_corridors"] >= 1


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_cave_family_connected(seed: int) -> None:
    world = make_world(f"cave:seed={seed},size_m=12")
    _check_connected_and_enclosed(world)
    # No straight walls: segment directions are spread over many angles.
    d = world.segments_m[:, 2:] - world.segments_m[:, :2]
    angles = np.round(np.degrees(np.arctan2(d[:, 1], d[:, 0])) % 180).astype(int)
    assert len(np.unique(angles)) > 30


# --------------------------------------------------------------------------- start poses


def _two_rooms(door_width_m: float) -> World:
    """A 3 x 2 m room and a 1 x 1 m closet to its lower right, joined by a door of
    ``door_width_m`` at the bottom of the wall x = 3."""
    segs = [
        (0.0, 0.0, 4.0, 0.0),
        (4.0, 0.0, 4.0, 1.0),
        (4.0, 1.0, 3.0, 1.0),
        (3.0, 1.0, 3.0, 2.0),
        (3.0, 2.0, 0.0, 2.0),
        (0.0, 2.0, 0.0, 0.0),
        (3.0, door_width_m, 3.0, 1.0),
    ]
    return world_from_segments(
        "two_rooms", np.array(segs), [(1.0, 1.0), (3.5, 0.5)], resolution_m=0.025
    )


def test_sample_start_pose_deterministic_with_clearance() -> None:
    world = make_world("office:seed=2,size_m=12")
    poses_a = [sample_start_pose(world, np.random.default_rng(11), CLEARANCE_M) for _ in range(2)]
    assert poses_a[0] == poses_a[1]
    rng = np.random.default_rng(3)
    poses = np.array([sample_start_pose(world, rng, CLEARANCE_M) for _ in range(200)])
    dist = distance_to_segments_m(poses[:, :2], world.segments_m)
    assert dist.min() >= CLEARANCE_M
    assert np.all((poses[:, 2] >= -np.pi) & (poses[:, 2] < np.pi))
    assert len(np.unique(poses[:, :2], axis=0)) > 150
    for pose in poses[:20]:
        validate_start_pose(world, pose, CLEARANCE_M)


def test_sample_start_pose_uses_largest_component() -> None:
    # A 0.2 m door: the closet is cut off for a robot that needs 0.155 m clearance.
    world = _two_rooms(door_width_m=0.2)
    rng = np.random.default_rng(0)
    xs = np.array([sample_start_pose(world, rng, CLEARANCE_M)[0] for _ in range(300)])
    assert xs.max() < 3.0
    with pytest.raises(ValueError, match="no free cell with 1.5 m clearance"):
        sample_start_pose(world, rng, 1.5)


@pytest.mark.parametrize(
    ("pose", "message"),
    [
        ((1.0, 2.0, 0.0), "closer than clearance"),
        ((1.0, 1.9, 0.0), r"\(1, 1.9, 0\) is 0.100 m from a wall"),
        ((5.0, 1.0, 0.0), "outside the world bounds"),
        ((1.0, float("nan"), 0.0), "must be three finite numbers"),
        ((1.0, 1.0), "must be three finite numbers"),
    ],
)
def test_validate_start_pose_errors(pose, message) -> None:
    world = _two_rooms(door_width_m=0.8)
    with pytest.raises(ValueError, match=message):
        validate_start_pose(world, pose, CLEARANCE_M)


def test_validate_start_pose_inside_thick_wall_names_pose() -> None:
    world = make_world("office:seed=0,size_m=12")
    # A cell of the free raster that is not free but lies inside the bounds: inside a wall.
    g = world.free_geometry
    dist = segment_distance_field(world.segments_m, g, 1.0)
    inner = ~world.free_mask & (dist > 0.02)
    inner[[0, -1], :] = False
    inner[:, [0, -1]] = False
    r, c = np.argwhere(inner)[0]
    x, y = g.grid_to_world(r, c)
    with pytest.raises(ValueError, match=rf"start pose \({x:g}, {y:g}, 0\) is not in free space"):
        validate_start_pose(world, (x, y, 0.0), 0.0)


def test_validate_start_pose_returns_floats() -> None:
    world = make_world("maze1")
    assert validate_start_pose(world, np.array([0.45, 0.45, 0.0]), CLEARANCE_M) == (0.45, 0.45, 0.0)


# --------------------------------------------------------------------------- reachable area


def _inner_square(n: int, band: int) -> np.ndarray:
    """An n x n mask True except for a ``band``-cell border and the corner cells of the next ring
    (a disk of 1.1 cells around the robot-centre cells does not reach them diagonally)."""
    out = np.zeros((n, n), dtype=bool)
    out[band:-band, band:-band] = True
    for r in (band, n - 1 - band):
        for c in (band, n - 1 - band):
            out[r, c] = False
    return out


def test_reachable_mask_square_room_leaves_one_cell_band() -> None:
    world = world_from_segments("room", np.array(_box(0.0, 0.0, 2.0, 2.0)), [(1.0, 1.0)])
    geometry = GridGeometry(0.05, 0.0, 0.0, 40, 40)
    free = rasterize_free(world, geometry)
    assert free.all()  # walls on the grid's outer edges
    # Robot centres: cells 2..37 (centre >= 0.105 m from the walls); dilated by 0.055 m.
    reach = reachable_free_mask(world, geometry, (1.0, 1.0), radius_m=0.105, clearance_m=0.105)
    assert np.array_equal(reach, _inner_square(40, 1))
    # With a 0.05 m margin the centres are cells 3..36 and the uncovered band is two cells.
    reach = reachable_free_mask(world, geometry, (1.0, 1.0), radius_m=0.105, clearance_m=0.155)
    assert np.array_equal(reach, _inner_square(40, 2))


def test_reachable_mask_stops_at_narrow_door() -> None:
    geometry = GridGeometry(0.05, -0.1, -0.1, 44, 84)
    narrow = _two_rooms(door_width_m=0.2)
    reach = reachable_free_mask(narrow, geometry, (1.0, 1.0), ROBOT_RADIUS_M, CLEARANCE_M)
    xs, _ = geometry.grid_to_world(0, np.arange(geometry.width))
    assert reach.any() and not reach[:, xs > 3.0].any()
    wide = _two_rooms(door_width_m=0.8)
    reach = reachable_free_mask(wide, geometry, (1.0, 1.0), ROBOT_RADIUS_M, CLEARANCE_M)
    assert reach[:, xs > 3.2].any()
    assert not (reach & ~rasterize_free(wide, geometry)).any()


def test_reachable_mask_bad_start() -> None:
    world = _two_rooms(door_width_m=0.8)
    geometry = GridGeometry(0.05, -0.1, -0.1, 44, 84)
    with pytest.raises(ValueError, match=r"start \(0.05, 1\) has no free cell"):
        reachable_free_mask(world, geometry, (0.05, 1.0), ROBOT_RADIUS_M, CLEARANCE_M)
    with pytest.raises(ValueError, match="radius_m must be a positive"):
        reachable_free_mask(world, geometry, (1.0, 1.0), 0.0, CLEARANCE_M)
