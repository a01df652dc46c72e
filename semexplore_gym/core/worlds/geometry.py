"""Wall-segment geometry on grids: distance fields, wall-crossing links and flood fill.

These kernels turn the vector walls of a :class:`~semexplore_gym.core.worlds.world.World`
into rasters on any :class:`~semexplore_gym.core.grid.GridGeometry`:

- :func:`segment_distance_field` gives the exact distance from every cell centre to the
  nearest wall (clipped at a maximum, so only a band around each wall is visited);
- :func:`crossed_links` marks the links between 4-neighbour cell centres that a wall crosses;
- :func:`flood_fill_links` floods a mask from seed cells without crossing those links, so a
  wall thinner than a cell still separates its two sides.

All kernels are single-threaded numba, compiled once and cached on disk.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from numba import njit

from semexplore_gym.core.grid import GridGeometry


def as_segments(segments_m: npt.ArrayLike, name: str = "segments_m") -> np.ndarray:
    """Return ``segments_m`` as a C-contiguous float64 ``(N, 4)`` array, checking shape and values."""
    seg = np.asarray(segments_m, dtype=np.float64)
    if seg.size == 0:
        return np.zeros((0, 4), dtype=np.float64)
    if seg.ndim != 2 or seg.shape[1] != 4:
        raise ValueError(f"{name} must have shape (N, 4) as x0, y0, x1, y1, got {seg.shape}")
    if not np.isfinite(seg).all():
        raise ValueError(f"{name} contains NaN or inf")
    return np.ascontiguousarray(seg)


def segments_bounds_m(segments_m: npt.ArrayLike) -> tuple[float, float, float, float]:
    """``(xmin, ymin, xmax, ymax)`` of a set of segments."""
    seg = as_segments(segments_m)
    if seg.shape[0] == 0:
        raise ValueError("cannot take the bounds of an empty segment set")
    xs = seg[:, [0, 2]]
    ys = seg[:, [1, 3]]
    return (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))


def distance_to_segments_m(points_xy_m: npt.ArrayLike, segments_m: npt.ArrayLike) -> np.ndarray:
    """Exact Euclidean distance from each point to the nearest segment.

    Args:
        points_xy_m: ``(K, 2)`` points (or one ``(2,)`` point).
        segments_m: ``(N, 4)`` segments.

    Returns:
        ``(K,)`` float64 distances in metres (``inf`` when there are no segments).
    """
    pts = np.atleast_2d(np.asarray(points_xy_m, dtype=np.float64))
    if pts.shape[-1] != 2:
        raise ValueError(f"points_xy_m must have shape (K, 2), got {pts.shape}")
    seg = as_segments(segments_m)
    if seg.shape[0] == 0:
        return np.full(pts.shape[0], np.inf)
    return _points_to_segments_kernel(np.ascontiguousarray(pts), seg)


@njit(cache=True)
def _points_to_segments_kernel(pts: np.ndarray, seg: np.ndarray) -> np.ndarray:
    out = np.empty(pts.shape[0])
    for k in range(pts.shape[0]):
        px = pts[k, 0]
        py = pts[k, 1]
        best = np.inf
        for i in range(seg.shape[0]):
            x0 = seg[i, 0]
            y0 = seg[i, 1]
            dx = seg[i, 2] - x0
            dy = seg[i, 3] - y0
            l2 = dx * dx + dy * dy
            t = 0.0
            if l2 > 0.0:
                t = ((px - x0) * dx + (py - y0) * dy) / l2
                t = min(1.0, max(0.0, t))
            ex = x0 + t * dx - px
            ey = y0 + t * dy - py
            d2 = ex * ex + ey * ey
            if d2 < best:
                best = d2
        out[k] = np.sqrt(best)
    return out


def segment_distance_field(
    segments_m: npt.ArrayLike, geometry: GridGeometry, max_distance_m: float
) -> np.ndarray:
    """Distance from every cell centre to the nearest wall segment, clipped at ``max_distance_m``.

    Only cells within ``max_distance_m`` of some segment are visited, so the cost grows with the
    total wall length times the band width, not with the grid area.

    Args:
        segments_m: ``(N, 4)`` wall segments.
        geometry: The grid.
        max_distance_m: Clip value; cells farther than this from every wall get exactly this value.

    Returns:
        ``geometry.shape`` float32 array of distances in metres.
    """
    if not (np.isfinite(max_distance_m) and max_distance_m > 0):
        raise ValueError(f"max_distance_m must be a positive finite number, got {max_distance_m!r}")
    seg = as_segments(segments_m)
    out = np.full(geometry.shape, max_distance_m, dtype=np.float32)
    _distance_field_kernel(
        seg,
        float(geometry.origin_x_m),
        float(geometry.origin_y_m),
        float(geometry.resolution_m),
        float(max_distance_m),
        out,
    )
    return out


@njit(cache=True)
def _distance_field_kernel(
    seg: np.ndarray, ox: float, oy: float, res: float, max_d: float, out: np.ndarray
) -> None:
    h, w = out.shape
    for i in range(seg.shape[0]):
        x0 = seg[i, 0]
        y0 = seg[i, 1]
        x1 = seg[i, 2]
        y1 = seg[i, 3]
        # Cell centres are at origin + (index + 0.5) * res.
        c_lo = max(0, int(np.ceil((min(x0, x1) - max_d - ox) / res - 0.5)))
        c_hi = min(w - 1, int(np.floor((max(x0, x1) + max_d - ox) / res - 0.5)))
        r_lo = max(0, int(np.ceil((min(y0, y1) - max_d - oy) / res - 0.5)))
        r_hi = min(h - 1, int(np.floor((max(y0, y1) + max_d - oy) / res - 0.5)))
        dx = x1 - x0
        dy = y1 - y0
        l2 = dx * dx + dy * dy
        for r in range(r_lo, r_hi + 1):
            yc = oy + (r + 0.5) * res
            for c in range(c_lo, c_hi + 1):
                xc = ox + (c + 0.5) * res
                t = 0.0
                if l2 > 0.0:
                    t = ((xc - x0) * dx + (yc - y0) * dy) / l2
                    t = min(1.0, max(0.0, t))
                ex = x0 + t * dx - xc
                ey = y0 + t * dy - yc
                d = np.sqrt(ex * ex + ey * ey)
                if d < out[r, c]:
                    out[r, c] = d


def crossed_links(
    segments_m: npt.ArrayLike, geometry: GridGeometry
) -> tuple[np.ndarray, np.ndarray]:
    """Links between 4-neighbour cell centres that a wall segment touches or crosses.

    Touching counts as crossing (with a tolerance of 1e-7 cells), so two walls meeting at a
    point leave no gap for a flood fill to slip through.

    Returns:
        ``(cut_x, cut_y)``: ``cut_x[r, c]`` (shape ``(H, W-1)``) is True when a wall crosses the
        link from the centre of cell ``(r, c)`` to that of ``(r, c+1)``; ``cut_y[r, c]`` (shape
        ``(H-1, W)``) likewise for ``(r, c)`` to ``(r+1, c)``.
    """
    seg = as_segments(segments_m)
    h, w = geometry.shape
    cut_x = np.zeros((h, max(w - 1, 0)), dtype=np.bool_)
    cut_y = np.zeros((max(h - 1, 0), w), dtype=np.bool_)
    res = float(geometry.resolution_m)
    _cut_links_kernel(
        seg,
        float(geometry.origin_x_m),
        float(geometry.origin_y_m),
        res,
        h,
        w,
        1e-7 * res,
        cut_x,
        cut_y,
    )
    return cut_x, cut_y


@njit(cache=True)
def _cut_links_kernel(
    seg: np.ndarray,
    ox: float,
    oy: float,
    res: float,
    h: int,
    w: int,
    eps: float,
    cut_x: np.ndarray,
    cut_y: np.ndarray,
) -> None:
    for i in range(seg.shape[0]):
        x0 = seg[i, 0]
        y0 = seg[i, 1]
        x1 = seg[i, 2]
        y1 = seg[i, 3]
        # Links along x lie on the lines y = centre of row r.
        if w >= 2:
            r_lo = max(0, int(np.ceil((min(y0, y1) - eps - oy) / res - 0.5)))
            r_hi = min(h - 1, int(np.floor((max(y0, y1) + eps - oy) / res - 0.5)))
            for r in range(r_lo, r_hi + 1):
                yc = oy + (r + 0.5) * res
                if abs(y1 - y0) <= eps:
                    xa = min(x0, x1)
                    xb = max(x0, x1)
                else:
                    t = min(1.0, max(0.0, (yc - y0) / (y1 - y0)))
                    xa = x0 + t * (x1 - x0)
                    xb = xa
                # Link c spans [ox + (c + 0.5) res, ox + (c + 1.5) res].
                c_lo = max(0, int(np.ceil((xa - eps - ox) / res - 1.5)))
                c_hi = min(w - 2, int(np.floor((xb + eps - ox) / res - 0.5)))
                for c in range(c_lo, c_hi + 1):
                    cut_x[r, c] = True
        if h >= 2:
            c_lo = max(0, int(np.ceil((min(x0, x1) - eps - ox) / res - 0.5)))
            c_hi = min(w - 1, int(np.floor((max(x0, x1) + eps - ox) / res - 0.5)))
            for c in range(c_lo, c_hi + 1):
                xc = ox + (c + 0.5) * res
                if abs(x1 - x0) <= eps:
                    ya = min(y0, y1)
                    yb = max(y0, y1)
                else:
                    t = min(1.0, max(0.0, (xc - x0) / (x1 - x0)))
                    ya = y0 + t * (y1 - y0)
                    yb = ya
                r_lo = max(0, int(np.ceil((ya - eps - oy) / res - 1.5)))
                r_hi = min(h - 2, int(np.floor((yb + eps - oy) / res - 0.5)))
                for r in range(r_lo, r_hi + 1):
                    cut_y[r, c] = True


def flood_fill_links(
    passable: np.ndarray, cut_x: np.ndarray, cut_y: np.ndarray, seed_mask: np.ndarray
) -> np.ndarray:
    """4-connected flood fill over ``passable`` cells that never crosses a cut link.

    Args:
        passable: ``(H, W)`` bool, cells the fill may enter.
        cut_x: ``(H, W-1)`` bool from :func:`crossed_links`.
        cut_y: ``(H-1, W)`` bool from :func:`crossed_links`.
        seed_mask: ``(H, W)`` bool, where the fill starts (seeds outside ``passable`` are ignored).

    Returns:
        ``(H, W)`` bool mask of the cells reached.
    """
    passable = np.ascontiguousarray(passable, dtype=np.bool_)
    seed_mask = np.ascontiguousarray(seed_mask, dtype=np.bool_)
    h, w = passable.shape
    if (
        seed_mask.shape != (h, w)
        or cut_x.shape != (h, max(w - 1, 0))
        or cut_y.shape != (max(h - 1, 0), w)
    ):
        raise ValueError(
            f"shape mismatch: passable {passable.shape}, seed_mask {seed_mask.shape}, cut_x {cut_x.shape}, cut_y {cut_y.shape}"
        )
    seeds = np.flatnonzero(seed_mask & passable).astype(np.int64)
    out = np.zeros((h, w), dtype=np.bool_)
    if seeds.size:
        _flood_fill_kernel(
            passable, np.ascontiguousarray(cut_x), np.ascontiguousarray(cut_y), seeds, out
        )
    return out


@njit(cache=True)
def _flood_fill_kernel(
    passable: np.ndarray, cut_x: np.ndarray, cut_y: np.ndarray, seeds: np.ndarray, out: np.ndarray
) -> None:
    h, w = passable.shape
    # Each cell is pushed at most once (it is marked when pushed), so H*W bounds the stack.
    stack = np.empty(h * w, dtype=np.int64)
    top = 0
    for k in range(seeds.shape[0]):
        s = seeds[k]
        r = s // w
        c = s % w
        if not out[r, c]:
            out[r, c] = True
            stack[top] = s
            top += 1
    while top > 0:
        top -= 1
        s = stack[top]
        r = s // w
        c = s % w
        if c + 1 < w and not cut_x[r, c] and passable[r, c + 1] and not out[r, c + 1]:
            out[r, c + 1] = True
            stack[top] = s + 1
            top += 1
        if c > 0 and not cut_x[r, c - 1] and passable[r, c - 1] and not out[r, c - 1]:
            out[r, c - 1] = True
            stack[top] = s - 1
            top += 1
        if r + 1 < h and not cut_y[r, c] and passable[r + 1, c] and not out[r + 1, c]:
            out[r + 1, c] = True
            stack[top] = s + w
            top += 1
        if r > 0 and not cut_y[r - 1, c] and passable[r - 1, c] and not out[r - 1, c]:
            out[r - 1, c] = True
            stack[top] = s - w
            top += 1


def merge_polyline_edges(
    vertices_xy_m: npt.ArrayLike, closed: bool = True, tol_m: float = 1e-9
) -> np.ndarray:
    """Segments along a polyline, merging consecutive collinear edges and dropping repeated vertices.

    Args:
        vertices_xy_m: ``(K, 2)`` vertices.
        closed: Whether the last vertex connects back to the first.
        tol_m: Two edges are collinear when the middle vertex lies within ``tol_m`` of the line
            through its neighbours and the direction does not reverse.

    Returns:
        ``(N, 4)`` segments.
    """
    v = np.asarray(vertices_xy_m, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 2:
        raise ValueError(f"vertices must have shape (K, 2), got {v.shape}")
    if not np.isfinite(v).all():
        raise ValueError("vertices contain NaN or inf")
    keep = np.ones(len(v), dtype=bool)
    if len(v) > 1:
        keep[1:] = np.any(np.abs(np.diff(v, axis=0)) > tol_m, axis=1)
    v = v[keep]
    if closed and len(v) > 1 and np.all(np.abs(v[0] - v[-1]) <= tol_m):
        v = v[:-1]
    n = len(v)
    if n < 2:
        return np.zeros((0, 4))
    # One pass suffices: a run of collinear vertices all lies on the line through its two ends.
    if closed:
        prev = np.roll(v, 1, axis=0)
        nxt = np.roll(v, -1, axis=0)
        mid = v
    else:
        prev = v[:-2]
        nxt = v[2:]
        mid = v[1:-1]
    a = mid - prev
    b = nxt - mid
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    dot = (a * b).sum(axis=1)
    straight = (np.abs(cross) <= tol_m * np.maximum(np.hypot(*(nxt - prev).T), tol_m)) & (dot > 0)
    keep = ~straight if closed else np.concatenate([[True], ~straight, [True]])
    if closed and not keep.any():
        raise ValueError("a closed polyline with all vertices collinear has no area")
    v = v[keep]
    if closed:
        a = v
        b = np.roll(v, -1, axis=0)
    else:
        a = v[:-1]
        b = v[1:]
    return np.ascontiguousarray(np.hstack([a, b]))


def polygon_inside_mask(vertices_xy_m: npt.ArrayLike, geometry: GridGeometry) -> np.ndarray:
    """Cells whose centre lies inside a polygon (even-odd rule, scanline crossings).

    Args:
        vertices_xy_m: ``(K, 2)`` polygon vertices; the polygon is closed implicitly.
        geometry: The grid.

    Returns:
        ``geometry.shape`` bool mask.
    """
    v = np.asarray(vertices_xy_m, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 2 or len(v) < 3:
        raise ValueError(f"a polygon needs (K >= 3, 2) vertices, got shape {v.shape}")
    if not np.isfinite(v).all():
        raise ValueError("polygon vertices contain NaN or inf")
    h, w = geometry.shape
    toggles = np.zeros((h, w + 1), dtype=np.int32)
    _polygon_crossings_kernel(
        np.ascontiguousarray(v),
        float(geometry.origin_x_m),
        float(geometry.origin_y_m),
        float(geometry.resolution_m),
        toggles,
    )
    return (np.cumsum(toggles, axis=1)[:, :w] & 1).astype(bool)


@njit(cache=True)
def _polygon_crossings_kernel(
    v: np.ndarray, ox: float, oy: float, res: float, toggles: np.ndarray
) -> None:
    h = toggles.shape[0]
    w = toggles.shape[1] - 1
    n = v.shape[0]
    for i in range(n):
        x0 = v[i, 0]
        y0 = v[i, 1]
        x1 = v[(i + 1) % n, 0]
        y1 = v[(i + 1) % n, 1]
        if y0 == y1:
            continue
        # Half-open in y so a scanline through a vertex counts each crossing once.
        ylo = min(y0, y1)
        yhi = max(y0, y1)
        r_lo = max(0, int(np.ceil((ylo - oy) / res - 0.5)))
        r_hi = min(h - 1, int(np.ceil((yhi - oy) / res - 0.5)) - 1)
        for r in range(r_lo, r_hi + 1):
            yc = oy + (r + 0.5) * res
            x = x0 + (yc - y0) * (x1 - x0) / (y1 - y0)
            # Cells with centre x > crossing are on the far side of it.
            c = int(np.floor((x - ox) / res - 0.5)) + 1
            c = min(max(c, 0), w)
            toggles[r, c] += 1
