"""``semexplore report``: a result file's tables as Markdown, computed from its data.

RUN_DIR is a benchmark run folder (its ``runs.csv`` is read), a ``runs.csv`` (one trimmed to the
columns a table reads is enough), a team benchmark's run folder (``--robots``: its summary's
tables and paired tests, with the team oracle's columns when it ran, a bold line per world
family instead of a heading), a best-known table such as ``configs/best_known/best_known.csv``,
or the checked missions ``scripts/check_lower_bound.py --missions-out FILE`` writes (the
certified bound against every mission, per family). Several benchmark run folders or
``runs.csv`` files are read as one (their rows concatenated). For a benchmark, ``--table`` picks
the table: ``overview`` (one row per family and policy, the default), ``policies`` (one row per
policy over all worlds), ``regret`` (each policy against the oracle, a run with ``--oracle``),
``slam`` (the SLAM table of a run with ``--env-config slam``), ``slam-vs-perfect`` (a run on the
perfect map and the same run with ``--env-config slam``, missions paired by world, policy and
seed), ``paired`` (per family, each policy's T99 paired with the ``--reference`` policy's by
world and start, with self-stops and collisions) or ``summary`` (the whole ``summary.md`` but
its best-known and learning sections, which read other files; one run folder). The docs build
renders the user guide's result tables with the same function.

Example::

    semexplore report runs/bench10
    semexplore report runs/bench10 --table policies --out runs/bench10/policies.md
    semexplore report runs/perfect runs/slam --table slam-vs-perfect
    semexplore report runs/learners --table paired --reference semantic
    semexplore report configs/best_known/best_known.csv --json
    semexplore report docs/results/oracle/missions.csv
"""

from __future__ import annotations

import argparse
import sys

from semexplore_gym.cli._output import add_json_flag, print_json


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    from semexplore_gym.cli import describe
    from semexplore_gym.evaluation.tables import RUN_TABLES

    p = sub.add_parser(
        "report",
        help="print a benchmark's or a best-known table's results as a Markdown table",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "run_dir",
        metavar="RUN_DIR",
        nargs="+",
        help="a benchmark or team benchmark run folder, a runs.csv, a best-known CSV or "
        "checked missions; "
        "several benchmark run folders or runs.csv files are read as one",
    )
    p.add_argument(
        "--table",
        choices=RUN_TABLES,
        default=None,
        help="which of a benchmark's tables (default: overview; a team run and a best-known CSV "
        "have one)",
    )
    p.add_argument(
        "--reference",
        default=None,
        metavar="POLICY",
        help="the policy spec every other one is compared with (default: semantic)",
    )
    p.add_argument(
        "--out", default=None, metavar="FILE", help="write the Markdown to FILE instead of stdout"
    )
    add_json_flag(p, "the tables (columns and rows) and their Markdown")
    return p


def run(args: argparse.Namespace) -> int:
    from semexplore_gym.cli._flags import check_output_flag
    from semexplore_gym.evaluation.tables import report_tables

    if args.out is not None:
        check_output_flag("--out", args.out)
    result = report_tables(args.run_dir, args.table, args.reference)
    if args.out is not None:
        with open(args.out, "w", encoding="utf-8") as f:
            f.write(result.markdown)
    if args.json:
        print_json(args, {**result.to_dict(), "out": args.out}, ensure_ascii=False)
    elif args.out is not None:
        read = ", ".join(map(str, result.sources or (result.source,)))
        print(f"wrote {args.out} ({result.rows} rows of {read})", file=sys.stderr)
    else:
        sys.stdout.write(result.markdown)
    return 0
