"""Matplotlib drawing of a :class:`~semexplore_gym.core.topometric.TopometricMap` over its grid.

Areas are tinted by type (the renderer's colours: intersection red, pathway blue, dead end grey,
frontier pathway green), openings are drawn as segments (frontier openings magenta), area paths
and graph edges as lines, intersection centres as dots and frontier targets as stars. The
image is drawn with y up (row 0 of the grid at the bottom). matplotlib is imported lazily.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN
from semexplore_gym.core.topometric.types import AreaType, TopometricMap

#: RGB colours of area types (same as :mod:`semexplore_gym.rendering.renderer`).
TYPE_COLOURS: dict[AreaType, tuple[int, int, int]] = {
    AreaType.INTERSECTION: (230, 85, 60),
    AreaType.PATHWAY: (90, 160, 230),
    AreaType.DEAD_END: (150, 150, 150),
    AreaType.FRONTIER_PATHWAY: (70, 190, 90),
}
_TYPE_LABELS = {
    AreaType.INTERSECTION: "intersection",
    AreaType.PATHWAY: "pathway",
    AreaType.DEAD_END: "dead end",
    AreaType.FRONTIER_PATHWAY: "frontier pathway",
}


def _import_pyplot() -> Any:
    try:
        import matplotlib

        if matplotlib.get_backend().lower() not in (
            "agg",
            "module://matplotlib_inline.backend_inline",
        ):
            matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - matplotlib is a dependency
        raise ImportError(
            "drawing a topometric map needs matplotlib: pip install matplotlib"
        ) from e
    return plt


def map_image(tmap: TopometricMap, grid: np.ndarray, tint: float = 0.55) -> np.ndarray:
    """RGB uint8 image ``(H, W, 3)`` of the grid (white free, grey unknown, black occupied) with
    area cells tinted by type; row 0 is the lowest y (draw with ``origin="lower"``)."""
    g = np.asarray(grid)
    if g.shape != tmap.area_ids.shape:
        raise ValueError(
            f"grid shape {g.shape} does not match the map's raster {tmap.area_ids.shape}"
        )
    img = np.full(g.shape + (3,), 160, dtype=np.float32)
    img[g == FREE] = 255.0
    img[g == OCCUPIED] = 0.0
    img[g == UNKNOWN] = 160.0
    types = tmap.area_type_raster()
    for t, rgb in TYPE_COLOURS.items():
        m = types == int(t)
        if m.any():
            img[m] = (1.0 - tint) * img[m] + tint * np.asarray(rgb, dtype=np.float32)
    return img.astype(np.uint8)


def plot_topometric_map(
    tmap: TopometricMap,
    grid: np.ndarray,
    ax: Any = None,
    *,
    show_paths: bool = True,
    show_edges: bool = False,
    show_ids: bool = False,
    title: str | None = None,
) -> Any:
    """Draw ``tmap`` over ``grid`` on a matplotlib axes; returns the figure.

    Args:
        tmap: The segmentation.
        grid: The encoded grid it was computed from (same shape as ``tmap.area_ids``).
        ax: Axes to draw on (a new figure when None).
        show_paths: Draw every area's paths (opening -> centre / opening / far end).
        show_edges: Draw the graph edges' polylines (dense for intersections with many openings).
        show_ids: Write area ids at the area centres.
        title: Axes title (default: the counts and the time).
    """
    plt = _import_pyplot()
    g = tmap.geometry
    xmin, ymin, xmax, ymax = g.extent_m
    if ax is None:
        aspect = (ymax - ymin) / max(xmax - xmin, 1e-9)
        w_in = 9.0
        fig, ax = plt.subplots(figsize=(w_in, max(3.0, min(w_in * aspect, 14.0))))
    else:
        fig = ax.figure
    ax.imshow(
        map_image(tmap, grid),
        origin="lower",
        extent=(xmin, xmax, ymin, ymax),
        interpolation="nearest",
    )
    _draw_lines(ax, tmap, show_paths, show_edges)
    _draw_markers(ax, tmap, show_ids)
    from matplotlib.patches import Patch

    handles = [
        # matplotlib's stubs leave out the RGB arrays it accepts as colours.
        Patch(color=np.asarray(TYPE_COLOURS[t]) / 255.0, label=_TYPE_LABELS[t])  # type: ignore[arg-type]
        for t in TYPE_COLOURS
    ]
    ax.legend(handles=handles, loc="upper right", fontsize=7, framealpha=0.8)
    if title is None:
        c = tmap.counts()
        title = (
            f"{c['intersections']} intersections, {c['pathways']} pathways, {c['dead_ends']} dead ends, "
            f"{c['frontier_pathways']} frontier pathways ({tmap.time_ms:.0f} ms)"
        )
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    return fig


def _draw_lines(ax: Any, tmap: TopometricMap, show_paths: bool, show_edges: bool) -> None:
    """Graph edges (optional), area paths (optional) and openings."""
    lw = 1.2
    if show_edges:
        for e in tmap.edges:
            p = np.asarray(e.path_m)
            if len(p) >= 2:
                ax.plot(p[:, 0], p[:, 1], color=(0.2, 0.2, 0.2), lw=0.6, alpha=0.6)
    if show_paths:
        for a in tmap.areas.values():
            col = np.asarray(TYPE_COLOURS[a.type]) / 255.0 * 0.6
            for p in a.paths_m.values():
                p = np.asarray(p)
                if len(p) >= 2:
                    ax.plot(p[:, 0], p[:, 1], color=col, lw=lw)
    for o in tmap.openings:
        ends = np.asarray(o.endpoints_m)
        ax.plot(
            ends[:, 0],
            ends[:, 1],
            color=(0.85, 0.1, 0.75) if o.is_frontier else (0.1, 0.1, 0.1),
            lw=2.0 if o.is_frontier else 1.5,
        )


def _draw_markers(ax: Any, tmap: TopometricMap, show_ids: bool) -> None:
    """Intersection centres, frontier targets and (optional) area ids."""
    cx = [a.centre_m[0] for a in tmap.areas_of_type(AreaType.INTERSECTION)]
    cy = [a.centre_m[1] for a in tmap.areas_of_type(AreaType.INTERSECTION)]
    if cx:
        ax.scatter(
            cx,
            cy,
            s=28,
            color=np.asarray(TYPE_COLOURS[AreaType.INTERSECTION]) / 255.0 * 0.7,
            zorder=5,
            edgecolors="k",
            linewidths=0.5,
        )
    if tmap.frontiers:
        fx = [f.midpoint_m[0] for f in tmap.frontiers]
        fy = [f.midpoint_m[1] for f in tmap.frontiers]
        ax.scatter(
            fx,
            fy,
            s=70,
            marker="*",
            color=(0.85, 0.1, 0.75),
            zorder=6,
            edgecolors="k",
            linewidths=0.4,
        )
    if show_ids:
        for a in tmap.areas.values():
            ax.text(
                a.centre_m[0],
                a.centre_m[1],
                str(a.id),
                fontsize=6,
                ha="center",
                va="center",
                zorder=7,
            )


def save_topometric_png(
    tmap: TopometricMap, grid: np.ndarray, path: str, dpi: int = 150, **kwargs: Any
) -> None:
    """Draw ``tmap`` (see :func:`plot_topometric_map`) and save it as a PNG."""
    plt = _import_pyplot()
    fig = plot_topometric_map(tmap, grid, **kwargs)
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
