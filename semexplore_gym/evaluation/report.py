"""Figures and ``summary.md`` from a benchmark directory (see :mod:`.harness`).

Figures follow the paper's: explored free area over time (mean and a min-max band, one panel
per world), mission-time box plots, map-generation / frontier-detection compute time,
global-navigation compute time, and the trajectory of the median run of each world and policy.
"""

from __future__ import annotations

import math
import os
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.evaluation.path_decomposition import decomposition_table
from semexplore_gym.evaluation.run_row import read_runs
from semexplore_gym.evaluation.run_writer import distance_to_coverage_m, file_slug, task_stem
from semexplore_gym.evaluation.slam_report import slam_table

#: The policy every other one is compared against in ``summary.md``.
REFERENCE_POLICY = "semantic"

SUMMARY_METRICS: tuple[tuple[str, str], ...] = (
    ("mission_time_s", "mission time (s)"),
    ("coverage", "coverage"),
    ("path_length_m", "path length (m)"),
    ("T90_s", "T90 (s)"),
    ("T99_s", "T99 (s)"),
    ("mean_map_generation_ms", "map generation (ms)"),
    ("mean_global_planning_ms", "global planning (ms)"),
    ("wall_time_s", "wall time (s)"),
    ("collisions", "collisions"),
    ("semantic_share", "semantic share of replans"),
)


def _values(rows: list[dict[str, Any]], key: str) -> np.ndarray:
    return np.array(
        [r[key] for r in rows if r.get(key) is not None and math.isfinite(float(r[key]))],
        dtype=np.float64,
    )


def _fmt(x: float, med: float) -> str:
    return f"{x:.3f}" if abs(med) < 10 else f"{x:.1f}"


def no_variation(n: int) -> str:
    """What a cell says instead of a spread or a test when every sample is the same value."""
    return f"no variation ({n} identical samples)"


def _median_iqr(v: np.ndarray) -> str:
    if v.size == 0:
        return "–"
    if v.size >= 2 and np.all(v == v[0]):
        # Duplicated missions have no spread: an IQR of zero width would look like a result.
        return f"{_fmt(float(v[0]), float(v[0]))} — {no_variation(int(v.size))}"
    q1, med, q3 = np.percentile(v, [25, 50, 75])
    return f"{_fmt(med, med)} [{_fmt(q1, med)}–{_fmt(q3, med)}]"


def group_runs(rows: list[dict[str, Any]]) -> dict[str, dict[str, list[dict[str, Any]]]]:
    """``{world: {policy: [rows]}}`` in first-seen order."""
    out: dict[str, dict[str, list[dict[str, Any]]]] = defaultdict(lambda: defaultdict(list))
    for r in rows:
        out[r["world"]][r["policy"]].append(r)
    return out


def group_by_family(
    rows: list[dict[str, Any]], family: Callable[[str], str] | None = None
) -> dict[str, dict[str, list[dict[str, Any]]]]:
    """``{family: {policy: [rows]}}`` in first-seen order (family: :func:`world_family`)."""
    from semexplore_gym.evaluation.suites import world_family

    fam = family or world_family
    out: dict[str, dict[str, list[dict[str, Any]]]] = defaultdict(lambda: defaultdict(list))
    for r in rows:
        out[fam(r["world"])][r["policy"]].append(r)
    return out


COMPARED_METRICS: tuple[tuple[str, str], ...] = (
    ("mission_time_s", "mission time"),
    ("path_length_m", "path length"),
    ("D99_m", "distance to 99 %"),
    ("T90_s", "T90"),
    ("T99_s", "T99"),
    ("mean_map_generation_ms", "map generation ms"),
    ("mean_global_planning_ms", "global planning ms"),
)


def policy_table(by_policy: dict[str, list[dict[str, Any]]]) -> list[str]:
    """One row per policy: mission count, self-stopped count and each metric's median [IQR]."""
    header = (
        "| policy | n | self-stopped | " + " | ".join(label for _, label in SUMMARY_METRICS) + " |"
    )
    lines = [header, "|" + "---|" * (3 + len(SUMMARY_METRICS))]
    for policy, rs in by_policy.items():
        stopped = sum(1 for r in rs if r["self_stopped"])
        cells = [_median_iqr(_values(rs, key)) for key, _ in SUMMARY_METRICS]
        lines.append(f"| {policy} | {len(rs)} | {stopped}/{len(rs)} | " + " | ".join(cells) + " |")
    lines.append("")
    return lines


def _comparison_table(
    by_policy: dict[str, list[dict[str, Any]]], reference: str, paired_by: str
) -> list[str]:
    """The reference policy against each other one, paired by (world, seed)."""
    from scipy.stats import mannwhitneyu, wilcoxon

    if reference not in by_policy or len(by_policy) < 2:
        return []
    lines = [
        f"{reference} vs each other policy, paired by {paired_by}. Ratio = median({reference}) / "
        f"median(other); paired ratio = median over pairs of {reference} / other (worlds of "
        "different sizes pooled in a family weigh alike); p = two-sided Mann–Whitney U; p W = "
        "two-sided Wilcoxon signed-rank test on the pairs' log ratios; wins = missions where "
        f"{reference} is lower.",
        "",
        "| vs | metric | ratio of medians | paired ratio | p (Mann–Whitney U) | p W | wins |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]

    def key(r: dict[str, Any]) -> tuple[str, int]:
        return (r["world"], int(r["seed"]))

    ref_rows = {key(r): r for r in by_policy[reference]}
    for other, rs in by_policy.items():
        if other == reference:
            continue
        other_rows = {key(r): r for r in rs}
        pairs = sorted(set(ref_rows) & set(other_rows))
        for metric, label in COMPARED_METRICS:
            both = [
                (ref_rows[k][metric], other_rows[k][metric])
                for k in pairs
                if ref_rows[k][metric] is not None and other_rows[k][metric] is not None
            ]
            a = np.array([x for x, _ in both], dtype=float)
            b = np.array([y for _, y in both], dtype=float)
            if a.size == 0:
                lines.append(f"| {other} | {label} | – | – | – | – | – |")
                continue
            ratio = np.median(a) / np.median(b) if np.median(b) > 0 else math.inf
            pos = b > 0
            paired = f"{np.median(a[pos] / b[pos]):.2f}" if np.any(pos) else "–"
            if a.size >= 2 and np.all(a == a[0]) and np.all(b == b[0]):
                # Each side one repeated value: a test or a win count over copies means nothing.
                lines.append(
                    f"| {other} | {label} | {ratio:.2f} | {paired} | {no_variation(a.size)} "
                    "| – | – |"
                )
                continue
            wins = int(np.sum(a < b))
            p_cell, pw_cell = "– (1 pair)", "–"
            if a.size >= 2:
                p_cell = f"{mannwhitneyu(a, b, alternative='two-sided').pvalue:.3g}"
                both_pos = (a > 0) & (b > 0)
                log_ratio = np.log(a[both_pos] / b[both_pos])
                if log_ratio.size >= 2 and np.any(log_ratio != 0):
                    pw_cell = f"{wilcoxon(log_ratio, alternative='two-sided').pvalue:.3g}"
            lines.append(
                f"| {other} | {label} | {ratio:.2f} | {paired} | {p_cell} | {pw_cell} "
                f"| {wins}/{a.size} |"
            )
    lines.append("")
    return lines


def overview_table(
    families: dict[str, dict[str, list[dict[str, Any]]]], reference: str
) -> list[str]:
    """One row per (family, policy): medians, and the reference's mission time against it."""
    from scipy.stats import mannwhitneyu, wilcoxon

    lines = [
        "## Overview",
        "",
        f"Medians per family. `{reference} ÷ policy` = median over (world, seed) pairs of "
        f"{reference}'s mission time divided by the policy's (< 1: {reference} is faster); p MW = "
        "two-sided Mann–Whitney U on the paired missions' times; p W = two-sided Wilcoxon "
        "signed-rank test on the pairs' log ratios (the paired test: a family pools worlds of "
        "very different sizes).",
        "",
        "| family | policy | n | self-stopped | coverage | mission time (s) | T90 (s) | "
        f"semantic share | {reference} ÷ policy | p MW | p W |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]

    def med(rs: list[dict[str, Any]], key: str) -> str:
        v = _values(rs, key)
        return _fmt(float(np.median(v)), float(np.median(v))) if v.size else "–"

    for fam, by_policy in families.items():
        ref = {(r["world"], int(r["seed"])): r for r in by_policy.get(reference, [])}
        for policy, rs in by_policy.items():
            ratio, p, pw = "–", "–", "–"
            if policy != reference and ref:
                pairs = [
                    (ref[k]["mission_time_s"], r["mission_time_s"])
                    for r in rs
                    if (k := (r["world"], int(r["seed"]))) in ref and r["mission_time_s"]
                ]
                if pairs:
                    a, b = np.array(pairs, dtype=float).T
                    ratio = f"{np.median(a / b):.2f}"
                    if a.size >= 2 and not (np.all(a == a[0]) and np.all(b == b[0])):
                        p = f"{mannwhitneyu(a, b, alternative='two-sided').pvalue:.3g}"
                    log_ratio = np.log(a / b)
                    if a.size >= 2 and np.any(log_ratio != 0):
                        pw = f"{wilcoxon(log_ratio, alternative='two-sided').pvalue:.3g}"
            stopped = sum(1 for r in rs if r["self_stopped"])
            lines.append(
                f"| {fam} | {policy} | {len(rs)} | {stopped}/{len(rs)} | {med(rs, 'coverage')} | "
                f"{med(rs, 'mission_time_s')} | {med(rs, 'T90_s')} | "
                f"{med(rs, 'semantic_share')} | {ratio} | {p} | {pw} |"
            )
    lines.append("")
    return lines


def _suite_lines(out: Path) -> list[str]:
    """Which suites (name, version) the run came from, as recorded in ``benchmark.json``."""
    import json

    try:
        manifest = json.loads((out / "benchmark.json").read_text())
    except (OSError, ValueError):
        return []
    suites = manifest.get("suites") if isinstance(manifest, dict) else None
    if not suites:
        return []
    named = ", ".join(
        f"`{s.get('name')}` v{s.get('version')}" for s in suites if isinstance(s, dict)
    )
    return [f"Suites: {named}.", ""]


def _version_lines(rows: list[dict[str, Any]]) -> list[str]:
    """Which named expert version each policy spec ran (``runs.csv``'s ``policy_version``)."""
    versions = {r["policy"]: r.get("policy_version") for r in rows if r.get("policy_version")}
    if not versions:
        return []
    named = ", ".join(f"`{p}` = {v}" for p, v in sorted(versions.items()))
    return [f"Expert versions: {named}.", ""]


def write_summary(out_dir: str | os.PathLike, reference: str = REFERENCE_POLICY) -> Path:
    """Write ``summary.md``: per world, per family and over all worlds, medians/IQRs and the
    reference policy against each other one."""
    out = Path(out_dir)
    rows = read_runs(out / "runs.csv")
    if not rows:
        raise ValueError(f"no finished missions in {out / 'runs.csv'}")
    path = out / "summary.md"
    path.write_text("\n".join(summary_lines(out, rows, reference)))
    return path


def summary_lines(
    out_dir: str | os.PathLike, rows: list[dict[str, Any]], reference: str = REFERENCE_POLICY
) -> list[str]:
    """The lines of ``summary.md`` for the missions ``rows`` of the run folder ``out_dir``
    (each row gains its ``D99_m``, read from the folder's traces and trajectories)."""
    out = Path(out_dir)
    add_distance_to_99(out, rows)
    groups = group_runs(rows)
    lines = [
        "# Benchmark summary",
        "",
        f"{len(rows)} missions from `{out / 'runs.csv'}`. Cells: median [IQR].",
        "",
        *_suite_lines(out),
        *_version_lines(rows),
    ]
    families = group_by_family(rows)
    if len(groups) > 1:
        lines += overview_table(families, reference)
        lines += [
            "## Per family",
            "",
            "Every mission of the family's worlds pooled; comparisons paired by (world, seed).",
            "",
        ]
        for fam, by_policy in families.items():
            worlds = sorted({r["world"] for rs in by_policy.values() for r in rs})
            lines += [f"### {fam} ({len(worlds)} world{'s' if len(worlds) != 1 else ''})", ""]
            lines += policy_table(by_policy)
            lines += _comparison_table(by_policy, reference, "(world, seed)")
        lines += [f"## All worlds ({len(groups)} worlds)", ""]
        lines += policy_table(policies_of(rows))
        lines += _comparison_table(policies_of(rows), reference, "(world, seed)")
    lines += decomposition_table(families)
    lines += slam_table(families)
    for world, by_policy in groups.items():
        lines += [f"## {world}", ""]
        lines += policy_table(by_policy)
        lines += _comparison_table(by_policy, reference, "seed")
    return lines


def policies_of(rows: list[dict[str, Any]]) -> dict[str, list[dict[str, Any]]]:
    """``{policy: [rows]}`` over every world, in first-seen order."""
    everything: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for r in rows:
        everything[r["policy"]].append(r)
    return everything


def add_distance_to_99(out: Path, rows: list[dict[str, Any]]) -> None:
    """Set each row's ``D99_m``: the distance driven until coverage first reached 99 % (from
    its trace and trajectory; None when it never did or they are missing)."""
    for r in rows:
        d = distance_to_coverage_m(out, r)
        r["D99_m"] = d if d is not None and math.isfinite(d) else None


def _trace(out: Path, r: dict[str, Any]) -> np.ndarray | None:
    p = out / "traces" / f"{task_stem(r['world'], r['policy'], int(r['seed']))}.csv"
    if not p.exists():
        return None
    t = np.loadtxt(p, delimiter=",", skiprows=1, ndmin=2)
    return t if t.size else None


def write_plots(out_dir: str | os.PathLike) -> list[Path]:
    """Write the benchmark figures as PNGs into ``out_dir``; returns their paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    rows = read_runs(out / "runs.csv")
    if not rows:
        raise ValueError(f"no finished missions in {out / 'runs.csv'}")
    groups = group_runs(rows)
    worlds = list(groups)
    policies = list(dict.fromkeys(r["policy"] for r in rows))
    colours = {p: plt.get_cmap("tab10")(i % 10) for i, p in enumerate(policies)}
    paths: list[Path] = []

    # 1. Explored free area over time, mean and min-max band: per world, and per family with
    # one panel per world class (the family's worlds that differ only in their seed).
    fig, panels = _panels(plt, len(worlds), 5.2)
    for ax, world in zip(panels, worlds, strict=True):
        _area_curves(ax, out, groups[world], colours, world_label(world))
    fig.tight_layout()
    paths.append(_save(fig, out / "explored_area.png"))
    families = group_by_family(rows)
    for fam, by_policy in families.items():
        classes: dict[str, dict[str, list[dict[str, Any]]]] = defaultdict(lambda: defaultdict(list))
        for policy, rs in by_policy.items():
            for r in rs:
                classes[world_class(r["world"])][policy].append(r)
        n_worlds = len({r["world"] for rs in by_policy.values() for r in rs})
        # A lone family whose worlds pool nothing would repeat explored_area.png.
        if len(families) > 1 or len(classes) < n_worlds:
            fig, panels = _panels(plt, len(classes), 5.2)
            for ax, (name, by_pol) in zip(panels, classes.items(), strict=True):
                _area_curves(ax, out, by_pol, colours, world_label(name))
            fig.suptitle(f"{fam}: explored free area over time (mean, min–max band)")
            fig.tight_layout()
            paths.append(_save(fig, out / f"explored_area_{file_slug(fam)}.png"))

    # 2-4. Box plots per world: mission time, map-generation time, global-planning time.
    for key, ylabel, name in (
        ("mission_time_s", "mission time (s)", "mission_time.png"),
        (
            "mean_map_generation_ms",
            "map generation / frontier detection (ms per update)",
            "map_generation_time.png",
        ),
        (
            "mean_global_planning_ms",
            "global navigation planning (ms per plan)",
            "global_planning_time.png",
        ),
    ):
        fig, panels = _panels(plt, len(worlds), 4.2)
        for ax, world in zip(panels, worlds, strict=True):
            names = list(groups[world])
            data = [_values(groups[world][p], key) for p in names]
            ax.boxplot(
                [d if d.size else np.array([np.nan]) for d in data],
                tick_labels=[policy_label(n) for n in names],
            )
            for i, d in enumerate(data):
                ax.scatter(
                    np.full(d.size, i + 1) + np.linspace(-0.08, 0.08, max(d.size, 1))[: d.size],
                    d,
                    s=10,
                    color=colours[names[i]],
                    zorder=3,
                )
            ax.set_title(world_label(world))
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3, axis="y")
        fig.tight_layout()
        paths.append(_save(fig, out / name))

    # 5. Trajectory of the median (by mission time) run of each world and policy.
    paths.append(_trajectory_figure(out, groups, worlds, policies, colours, plt))
    return paths


def world_class(world: str) -> str:
    """A world spelling without its seed: the worlds of a suite that differ only in it.

    ``office:seed=300,size_m=12`` becomes ``office:size_m=12``; other spellings are unchanged.
    """
    head, sep, args = world.partition(":")
    if not sep or "/" in world or "\\" in world:
        return world
    kept = [a for a in args.split(",") if not a.strip().startswith("seed=")]
    return f"{head}:{','.join(kept)}" if kept else head


def _area_curves(
    ax: Any, out: Path, by_policy: dict[str, list[dict[str, Any]]], colours: dict, title: str
) -> None:
    """Mean explored area over time with a min-max band, one line per policy."""
    for policy, rs in by_policy.items():
        traces = [t for t in (_trace(out, r) for r in rs) if t is not None]
        if not traces:
            continue
        t_end = max(float(t[-1, 0]) for t in traces)
        grid = np.linspace(0.0, max(t_end, 1e-6), 300)
        # After a mission ends its area stays at its final value.
        ys = np.stack([np.interp(grid, t[:, 0], t[:, 2]) for t in traces])
        ax.plot(
            grid,
            ys.mean(axis=0),
            color=colours[policy],
            label=f"{policy_label(policy)} (n={len(traces)})",
        )
        ax.fill_between(grid, ys.min(axis=0), ys.max(axis=0), color=colours[policy], alpha=0.2)
    ax.set_title(title)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("explored free area (m²)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)


#: Panels per row of the per-world figures (a suite has dozens of worlds).
PANELS_PER_ROW = 4


def _panels(plt: Any, n: int, width_in: float) -> tuple[Any, list[Any]]:
    """A figure with ``n`` panels, at most :data:`PANELS_PER_ROW` per row; unused ones hidden."""
    cols = min(n, PANELS_PER_ROW)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(width_in * cols, 4 * rows), squeeze=False)
    flat = list(axes.ravel())
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, flat[:n]


def _trajectory_figure(
    out: Path, groups: Any, worlds: list[str], policies: list[str], colours: dict, plt: Any
) -> Path:
    from semexplore_gym.maps import make_world

    fig, axes = plt.subplots(
        len(worlds), len(policies), figsize=(3.6 * len(policies), 3.6 * len(worlds)), squeeze=False
    )
    for i, world in enumerate(worlds):
        for j, policy in enumerate(policies):
            ax = axes[i][j]
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            rs = groups[world].get(policy, [])
            if not rs:
                ax.set_title(f"{world_label(world)} / {policy_label(policy)}: no run", fontsize=8)
                continue
            rs = sorted(rs, key=lambda r: r["mission_time_s"])
            r = rs[(len(rs) - 1) // 2]
            try:
                w = make_world(world.replace("seed=*", f"seed={r['seed']}"))
                seg = w.segments_m
                ax.plot(seg[:, [0, 2]].T, seg[:, [1, 3]].T, color="0.2", lw=0.8)
            except (ValueError, FileNotFoundError):
                pass
            tp = out / "trajectories" / f"{task_stem(r['world'], r['policy'], int(r['seed']))}.npy"
            if tp.exists():
                traj = np.load(tp)
                ax.plot(traj[:, 0], traj[:, 1], color=colours[policy], lw=1.2)
                ax.plot(traj[0, 0], traj[0, 1], "o", color="green", ms=5)
                ax.plot(traj[-1, 0], traj[-1, 1], "s", color="red", ms=5)
            ax.set_title(
                f"{world_label(world)} / {policy_label(policy)}\nseed {r['seed']}: {r['mission_time_s']:.0f} s, cov {r['coverage']:.2f}",
                fontsize=8,
            )
    fig.tight_layout()
    return _save(fig, out / "trajectories.png")


def policy_label(spec: str) -> str:
    """A short figure label for a policy spec: a model or file spec shows its ``[label]``.

    ``sb3:runs/fc/model.zip[frontier PPO]`` becomes ``frontier PPO`` and
    ``sb3:runs/fc/model.zip`` becomes ``sb3:model.zip``; built-in specs such as
    ``semantic[paper]`` are returned unchanged (tables always keep the full spec).
    """
    from semexplore_gym.policies.specs import split_bracket

    name, _, rest = spec.partition(":")
    if name not in ("sb3", "py") or not rest:
        return spec
    inner = split_bracket(spec)[1]
    if inner is not None:
        return inner or spec
    return f"{name}:{Path(rest).name}"


def world_label(world: str, max_parts: int = 3) -> str:
    """A short figure title for a world spelling: map files keep only their last path parts.

    ``/data/maps/turtlebot3/world/map.yaml`` becomes ``turtlebot3/world/map.yaml``; names and
    procedural spellings (``maze:seed=*,size_m=5``) are returned unchanged.
    """
    if "/" not in world and "\\" not in world:
        return world
    parts = Path(world).parts
    return "/".join(parts[-max_parts:])


def _save(fig: Any, path: Path) -> Path:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
