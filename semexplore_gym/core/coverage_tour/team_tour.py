"""A team coverage tour: the one-robot tour's viewpoints split into k routes of least makespan.

:func:`split_routes` solves a min-makespan vehicle routing problem on a distance matrix whose
node 0 is the common start: k open routes (each ends where its last viewpoint is) that together
visit every other node once, the longest as short as possible. It goes in two steps:

1. **A split of the one-robot order** (:func:`split_order`): the open tour's viewpoints cut into
   k consecutive chunks, each driven from the start, the cut points chosen exactly (a dynamic
   programme over the cuts) for the least longest route. This is the initial solution, and the
   answer when OR-Tools is missing or k = 1 (then it is the one-robot tour itself).
2. **OR-Tools routing** from that split: arc costs the same geodesic distances the one-robot
   tour uses (integer millimetres), a global span cost on the distance dimension (the makespan)
   over the total as tie-break, guided local search (OR-Tools' routing search runs in one
   thread), stopped after a fixed number of solutions (deterministic) or a wall-clock cap (a guard on big maps), whichever comes
   first. The better of the two is kept, so the result is never worse than step 1.

With ``own_starts_m`` each route runs from its robot's own start instead (the split's pieces
go to the robots nearest them, and OR-Tools gets one depot per robot).

:func:`plan_team_tour` applies it to a :class:`~.tour.CoverageTour`. The routes see what the
one-robot tour's viewpoints see; the scans along the new legs differ from the old legs' (the
team oracle makes up any shortfall from its live map, as the one-robot oracle does).

:func:`team_lower_bound` turns the one-robot bound into a bound on the team's makespan.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semexplore_gym.core.coverage_tour.tour import CoverageTour
from semexplore_gym.core.coverage_tour.viewpoints import nearest_allowed_cell
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.planning.grid_search import distance_field

#: What to install when the routing solver is missing.
ROUTING_HINT = (
    "the team oracle's routing solver needs OR-Tools: pip install 'semexplore-gym[oracle]' "
    "or pip install ortools"
)


@dataclass(frozen=True)
class TeamTourParams:
    """Settings of :func:`split_routes`.

    Attributes:
        solution_limit: OR-Tools stops after this many solutions (deterministic).
        time_limit_s: ... or after this much wall time (a guard on big problems).
        span_cost: Weight of the longest route against the total length (the total breaks
            ties between splits of the same makespan).
        use_solver: False keeps the split of the one-robot order (no OR-Tools).
    """

    solution_limit: int = 300
    time_limit_s: float = 10.0
    span_cost: int = 100
    use_solver: bool = True

    def __post_init__(self) -> None:
        if not (isinstance(self.solution_limit, int) and self.solution_limit >= 1):
            raise ValueError(
                f"TeamTourParams.solution_limit must be an integer >= 1, got {self.solution_limit!r}"
            )
        if not (math.isfinite(self.time_limit_s) and self.time_limit_s > 0):
            raise ValueError(
                f"TeamTourParams.time_limit_s must be positive, got {self.time_limit_s!r}"
            )
        if not (isinstance(self.span_cost, int) and self.span_cost >= 1):
            raise ValueError(
                f"TeamTourParams.span_cost must be an integer >= 1, got {self.span_cost!r}"
            )


@dataclass(frozen=True)
class TeamRoutes:
    """k open routes from node 0 (see :func:`split_routes`).

    Attributes:
        routes: Per route, its nodes in visiting order (node 0, the start, left out; a route
            may be empty).
        lengths_m: Each route's length from the start.
        makespan_m: The longest route.
        total_m: All routes together.
        solver: ``"split"`` (the cut one-robot order) or ``"ortools"`` (improved by routing).
    """

    routes: tuple[tuple[int, ...], ...]
    lengths_m: tuple[float, ...]
    makespan_m: float
    total_m: float
    solver: str


def route_length_m(distances_m: np.ndarray, route: tuple[int, ...] | list[int]) -> float:
    """Length of the open route from node 0 through ``route``."""
    nodes = [0, *route]
    return float(sum(distances_m[a, b] for a, b in zip(nodes[:-1], nodes[1:], strict=True)))


def _check_problem(distances_m: np.ndarray, n_routes: int) -> np.ndarray:
    d = np.asarray(distances_m, dtype=np.float64)
    if d.ndim != 2 or d.shape[0] != d.shape[1] or d.shape[0] < 2:
        raise ValueError(
            f"a team tour needs a square distance matrix with the start and at least one "
            f"viewpoint, got shape {d.shape}"
        )
    if not (isinstance(n_routes, (int, np.integer)) and n_routes >= 1):
        raise ValueError(f"the number of robots must be an integer >= 1, got {n_routes!r}")
    n_viewpoints = d.shape[0] - 1
    if n_routes > n_viewpoints:
        raise ValueError(
            f"{n_routes} robots but only {n_viewpoints} viewpoint(s) to share: use at most "
            f"{n_viewpoints} robots on this world"
        )
    if not np.isfinite(d[0, 1:]).all():
        raise ValueError("a viewpoint cannot be reached from the start")
    return d


def split_order(distances_m: np.ndarray, order: list[int], n_routes: int) -> TeamRoutes:
    """``order`` (nodes, the start left out) cut into ``n_routes`` consecutive chunks, each
    driven from node 0, with the least longest chunk (exact over the cut points)."""
    d = _check_problem(distances_m, n_routes)
    n = len(order)
    seq = np.asarray(order, dtype=np.int64)
    # within[i, j]: the chunk seq[i..j-1] driven from the start (inf for i >= j: no empty chunk
    # unless n < k, which _check_problem refuses).
    steps = np.concatenate([[0.0], np.cumsum(d[seq[:-1], seq[1:]])]) if n else np.zeros(1)
    best = np.full((n_routes + 1, n + 1), np.inf)
    cut = np.zeros((n_routes + 1, n + 1), dtype=np.int64)
    best[0, 0] = 0.0
    for r in range(1, n_routes + 1):
        for j in range(r, n + 1):
            i = np.arange(r - 1, j)
            chunk = d[0, seq[i]] + steps[j - 1] - steps[i]
            val = np.maximum(best[r - 1, i], chunk)
            m = int(np.argmin(val))
            best[r, j], cut[r, j] = float(val[m]), int(i[m])
    routes: list[tuple[int, ...]] = []
    j = n
    for r in range(n_routes, 0, -1):
        lo = int(cut[r, j])
        routes.append(tuple(int(v) for v in seq[lo:j]))
        j = lo
    return _routes(d, routes[::-1], "split")


def _routes(
    d: np.ndarray, routes: list[tuple[int, ...]], solver: str, own: np.ndarray | None = None
) -> TeamRoutes:
    """The routes with their lengths; ``own[i]``: robot ``i``'s start's distances to the nodes
    (None: every robot starts at node 0)."""
    lengths = tuple(
        float(route_length_m(d, r))
        if own is None or not r
        else float(own[i, r[0]] + route_length_m(d, r) - d[0, r[0]])
        for i, r in enumerate(routes)
    )
    return TeamRoutes(
        routes=tuple(routes),
        lengths_m=lengths,
        makespan_m=max(lengths),
        total_m=float(sum(lengths)),
        solver=solver,
    )


def _ortools() -> tuple[object, object]:
    try:
        from ortools.constraint_solver import pywrapcp, routing_enums_pb2
    except ImportError:
        raise ImportError(ROUTING_HINT) from None
    return pywrapcp, routing_enums_pb2


def require_routing_solver() -> None:
    """Raise ImportError (saying how to install it) when OR-Tools is missing."""
    _ortools()


def split_routes(
    distances_m: np.ndarray,
    n_routes: int,
    order: list[int] | None = None,
    params: TeamTourParams | None = None,
    own_starts_m: np.ndarray | None = None,
) -> TeamRoutes:
    """k open routes from node 0 through every other node of ``distances_m``, least makespan
    (module docstring). ``order``: a one-robot visiting order (the start left out) to start
    from; default ``1, 2, ...``. With ``n_routes == 1`` the answer is ``order`` itself.
    ``own_starts_m``: ``(k, N)`` distances from each robot's own start to every node (column
    0 unused): route ``i`` then runs from robot ``i``'s start (teammates that start apart, on
    either side of a wall, say); the split of the order goes to the robots by
    :func:`scipy.optimize.linear_sum_assignment` on the way to each piece's first node.

    Raises:
        ValueError: ``n_routes`` < 1 or above the number of viewpoints, a bad matrix, a
            viewpoint the start cannot reach.
        ImportError: OR-Tools is missing (and ``params.use_solver``, ``n_routes`` > 1).
    """
    prm = params or TeamTourParams()
    d = _check_problem(distances_m, n_routes)
    seq = list(range(1, d.shape[0])) if order is None else [int(v) for v in order]
    if sorted(seq) != list(range(1, d.shape[0])):
        raise ValueError("order must list every node but the start (0) once")
    first = split_order(d, seq, n_routes)
    own = None
    if own_starts_m is not None:
        own = np.asarray(own_starts_m, dtype=np.float64)
        if own.shape != (n_routes, d.shape[0]) or not np.isfinite(own[:, 1:]).all():
            raise ValueError(
                f"own_starts_m must be ({n_routes}, {d.shape[0]}) finite distances, got "
                f"shape {own.shape}"
            )
        first = _assign_pieces(d, first, own)
    if n_routes == 1 or not prm.use_solver:
        return first
    found = _solve_routing(d, first, n_routes, prm, own)
    if found is None:
        return first
    better = _routes(d, found, "ortools", own)
    return better if better.makespan_m < first.makespan_m - 1e-9 else first


def _assign_pieces(d: np.ndarray, split: TeamRoutes, own: np.ndarray) -> TeamRoutes:
    """The pieces of ``split`` given to the robots whose starts are nearest their first nodes
    (least total way in)."""
    from scipy.optimize import linear_sum_assignment

    routes = list(split.routes)
    cost = np.array([[own[i, r[0]] if r else 0.0 for r in routes] for i in range(own.shape[0])])
    rows, cols = linear_sum_assignment(cost)
    given = [routes[c] for _, c in sorted(zip(rows, cols, strict=True))]
    return _routes(d, given, split.solver, own)


def _solve_routing(
    d: np.ndarray,
    initial: TeamRoutes,
    n_routes: int,
    prm: TeamTourParams,
    own: np.ndarray | None = None,
) -> list[tuple[int, ...]] | None:
    """OR-Tools' min-makespan routes from ``initial`` (None when it finds none)."""
    pywrapcp, enums = _ortools()
    n, k = d.shape[0], n_routes
    # Nodes: 0 .. n-1 as in d (0 unused), n .. n+k-1 the robots' starts, n+k the routes'
    # common end: free to reach from anywhere, so the routes are open.
    big = 10.0 * float(d[np.isfinite(d)].max() + 1.0) * n
    full = np.zeros((n + k + 1, n + k + 1))
    full[:n, :n] = np.where(np.isfinite(d), d, big)
    starts = np.tile(d[0], (k, 1)) if own is None else own
    full[n : n + k, :n] = np.where(np.isfinite(starts), starts, big)
    full[:n, n : n + k] = big  # never into a start
    mm = np.rint(full * 1000.0).astype(np.int64)
    mm[:, n + k] = 0
    depots = list(range(n, n + k))
    manager = pywrapcp.RoutingIndexManager(n + k + 1, k, depots, [n + k] * k)  # type: ignore[attr-defined]
    model = pywrapcp.RoutingModel(manager)  # type: ignore[attr-defined]
    cb = model.RegisterTransitMatrix(mm.tolist())  # evaluated in C++, no Python callback
    model.SetArcCostEvaluatorOfAllVehicles(cb)
    model.AddDimension(cb, 0, int(mm.sum()) + 1, True, "distance")
    model.GetDimensionOrDie("distance").SetGlobalSpanCostCoefficient(prm.span_cost)
    search = pywrapcp.DefaultRoutingSearchParameters()  # type: ignore[attr-defined]
    search.first_solution_strategy = enums.FirstSolutionStrategy.PATH_CHEAPEST_ARC  # type: ignore[attr-defined]
    search.local_search_metaheuristic = enums.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH  # type: ignore[attr-defined]
    search.solution_limit = prm.solution_limit
    search.time_limit.FromMilliseconds(int(prm.time_limit_s * 1000))
    model.AddDisjunction([manager.NodeToIndex(0)], 0)  # node 0 (the common start) is no stop
    model.CloseModelWithParameters(search)
    start = model.ReadAssignmentFromRoutes([list(r) for r in initial.routes], True)
    sol = (
        model.SolveFromAssignmentWithParameters(start, search)
        if start is not None
        else model.SolveWithParameters(search)
    )
    if sol is None:
        return None
    routes: list[tuple[int, ...]] = []
    for v in range(n_routes):
        i = model.Start(v)
        nodes: list[int] = []
        i = sol.Value(model.NextVar(i))
        while not model.IsEnd(i):
            nodes.append(int(manager.IndexToNode(i)))
            i = sol.Value(model.NextVar(i))
        routes.append(tuple(nodes))
    return routes


@dataclass(frozen=True)
class TeamTour:
    """:func:`plan_team_tour`'s answer: per robot, viewpoint indices of the one-robot tour.

    Attributes:
        routes: Per robot, indices into ``tour.viewpoints_rc`` in visiting order.
        lengths_m: Each route's geodesic length from the start.
        makespan_m: The longest route.
        solver: See :class:`TeamRoutes`.
    """

    routes: tuple[tuple[int, ...], ...]
    lengths_m: tuple[float, ...]
    makespan_m: float
    solver: str


def start_distances_m(
    tour: CoverageTour, geometry: GridGeometry, start_xy_m: tuple[float, float]
) -> np.ndarray:
    """The ``(K + 1, K + 1)`` geodesic matrix of the start (node 0) and ``tour``'s viewpoints,
    on the tour's standing mask (one Dijkstra from the start; the rest is the tour's own)."""
    k = tour.n_viewpoints
    out = np.zeros((k + 1, k + 1))
    out[0, 1:] = out[1:, 0] = _from_point(tour, geometry, start_xy_m)
    out[1:, 1:] = tour.distances_m
    return out


def _from_point(
    tour: CoverageTour, geometry: GridGeometry, xy_m: tuple[float, float]
) -> np.ndarray:
    """Geodesic distances from the standing cell nearest ``xy_m`` to the tour's viewpoints."""
    rc = nearest_allowed_cell(tour.standing, geometry, xy_m)
    cost = np.where(tour.standing, geometry.resolution_m, np.inf)
    field, _ = distance_field(cost, rc)
    vp = tour.viewpoints_rc
    return np.asarray(field[vp[:, 0], vp[:, 1]], dtype=np.float64)


def plan_team_tour(
    tour: CoverageTour,
    geometry: GridGeometry,
    starts_xy_m: list[tuple[float, float]],
    n_robots: int,
    params: TeamTourParams | None = None,
) -> TeamTour:
    """The viewpoints of ``tour`` split into ``n_robots`` routes (the tour's own order is the
    initial split; one robot gets the tour itself). ``starts_xy_m``: one common start (the
    tour's), or one per robot (route ``i`` from start ``i``; the first is the tour's start).

    Raises:
        ValueError: ``n_robots`` < 1 or above the tour's viewpoints (the message says so), or
            neither one start nor one per robot.
    """
    if tour.n_viewpoints == 0:
        raise ValueError("the coverage tour has no viewpoint: nothing to share among robots")
    if len(starts_xy_m) not in (1, n_robots):
        raise ValueError(f"give one start or one per robot ({n_robots}), got {len(starts_xy_m)}")
    d = start_distances_m(tour, geometry, starts_xy_m[0])
    own = None
    if len(starts_xy_m) > 1:
        own = np.zeros((n_robots, d.shape[0]))
        for i, xy in enumerate(starts_xy_m):
            own[i, 1:] = _from_point(tour, geometry, xy)
    order = list(range(1, tour.n_viewpoints + 1))
    found = split_routes(d, n_robots, order, params, own)
    return TeamTour(
        routes=tuple(tuple(v - 1 for v in r) for r in found.routes),
        lengths_m=found.lengths_m,
        makespan_m=found.makespan_m,
        solver=found.solver,
    )


def team_lower_bound_m(
    one_robot_m: float,
    farthest_m: float,
    n_robots: int,
    starts_gap_m: float = 0.0,
    start_spread_m: float | None = None,
) -> float:
    """A lower bound on the team's makespan (the longest drive of any robot) to the goal.

    Args:
        one_robot_m: A lower bound on one robot's drive from robot 0's start.
        farthest_m: A lower bound on the drive from robot 0's start into some region the goal
            forces an explorer to enter (the one-region bound).
        n_robots: Team size k.
        starts_gap_m: Length of a path from robot 0's start through every teammate's start
            in turn (0 when all start at one point).
        start_spread_m: The longest path from robot 0's start to a teammate's (default
            ``starts_gap_m``).

    Returns:
        ``max(farthest_m - start_spread_m, (one_robot_m - starts_gap_m) / (2 k - 1), 0)``.
        Proof: some robot enters the forced region, from a start at most ``start_spread_m``
        from robot 0's. And one robot can do the team's work alone: from robot 0's start
        along the gap path, driving each robot's route out and (but the last) back:
        ``(2k - 1)`` times the makespan plus the gap, at least ``one_robot_m``.
    """
    k = int(n_robots)
    if k < 1:
        raise ValueError(f"the number of robots must be >= 1, got {n_robots!r}")
    gap = max(0.0, float(starts_gap_m))
    spread = gap if start_spread_m is None else max(0.0, float(start_spread_m))
    return max(0.0, float(farthest_m) - spread, (float(one_robot_m) - gap) / (2 * k - 1))


def starts_gap_m(
    allowed: np.ndarray, geometry: GridGeometry, starts_xy_m: list[tuple[float, float]]
) -> tuple[float, float]:
    """Paths in ``allowed`` cells (8-connected between cell centres, plus each start's way to
    its cell's centre) for :func:`team_lower_bound_m`: from the first start through the others
    in turn (``starts_gap_m``), and the longest from the first start to another
    (``start_spread_m``); inf when a start's cell is not allowed."""
    if len(starts_xy_m) < 2:
        return 0.0, 0.0
    res = geometry.resolution_m
    cost = np.where(allowed, res, np.inf)
    cells = [tuple(int(v) for v in geometry.world_to_grid(x, y)) for x, y in starts_xy_m]
    h, w = allowed.shape
    if not all(0 <= r < h and 0 <= c < w and allowed[r, c] for r, c in cells):
        return math.inf, math.inf
    ends = math.sqrt(2.0) * res  # half a diagonal at either end
    from_first, _ = distance_field(cost, cells[0])
    spread = max(float(from_first[b]) + ends for b in cells[1:])
    total = float(from_first[cells[1]]) + ends
    for a, b in zip(cells[1:-1], cells[2:], strict=True):
        field, _ = distance_field(cost, a)
        total += float(field[b]) + ends
    return total, spread
