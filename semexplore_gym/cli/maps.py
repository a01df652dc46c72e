"""``semexplore maps``: the catalogue of public real-world maps, and fetching them.

Example::

    semexplore maps list
    semexplore maps get tb3-world                       # into the cache, sha256-checked
    semexplore maps get tb3-world --from ~/maps         # offline: copy from your own folder
    semexplore maps get 'dungeon-test-*'                # a pattern: the 100 DungeonMaps test maps
    semexplore maps path tb3-world                      # where map:tb3-world is read from
    semexplore explore --world map:tb3-world
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any

from semexplore_gym.cli._output import add_json_flag, print_json

MIRROR_ENV = "SEMEXPLORE_MAPS_MIRROR"


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "maps",
        help="list, download and locate public real-world maps (world=map:NAME)",
        description="The map catalogue: public ROS maps pinned to a commit, with licence and "
        "sha256. Downloaded maps are used with --world map:NAME.",
    )
    actions = p.add_subparsers(dest="maps_action", metavar="ACTION")
    lst = actions.add_parser("list", help="one line per map: name, size, licence, source")
    lst.add_argument(
        "--files",
        action="store_true",
        help="also one line per file: its download URL at the pinned commit and its sha256",
    )
    get = actions.add_parser(
        "get", help="download maps into the cache (or --dir), verifying each file's sha256"
    )
    get.add_argument(
        "names",
        nargs="+",
        metavar="NAME",
        help="catalogue map name(s); a quoted pattern ('dungeon-test-*') names every match",
    )
    get.add_argument(
        "--dir",
        default=None,
        help="maps directory to put NAME/ in (default: the cache; see 'semexplore maps path')",
    )
    get.add_argument(
        "--from",
        dest="from_dir",
        default=None,
        metavar="DIR",
        help="copy from a local directory holding the map's files (DIR/NAME/FILE or DIR/FILE) "
        "instead of downloading",
    )
    get.add_argument(
        "--mirror",
        default=os.environ.get(MIRROR_ENV) or None,
        metavar="URL",
        help=f"download from URL/OWNER/REPO/COMMIT/PATH instead of raw.githubusercontent.com "
        f"(default: ${MIRROR_ENV})",
    )
    get.add_argument(
        "--timeout-s", type=float, default=30.0, help="network timeout (default: %(default)s)"
    )
    path = actions.add_parser(
        "path", help="the file map:NAME loads, or without NAME the cache directory"
    )
    path.add_argument("name", nargs="?", default=None, metavar="NAME")
    p.set_defaults(_maps_parser=p)
    add_json_flag(lst, "the catalogue (each map's name, size, licence, source and files)")
    add_json_flag(get, "each map's name and the world file it now loads")
    add_json_flag(path, "the path")
    for action in (lst, get, path):
        action.set_defaults(_prog=action.prog)  # errors read "semexplore maps get: error: ..."
    return p


def _size(n_bytes: int) -> str:
    return f"{n_bytes / 1024:.0f} KB" if n_bytes < 1024 * 1024 else f"{n_bytes / 2**20:.1f} MB"


def _list(args: argparse.Namespace) -> int:
    from semexplore_gym.maps.catalogue import CATALOGUE

    if args.json:
        maps = [_entry_record(m) for m in CATALOGUE.values()]
        print_json(args, {"maps": maps})
        return 0
    files = args.files
    rows = [(m.name, _size(m.size_bytes), m.licence, m.source) for m in CATALOGUE.values()]
    widths = [max(len(r[i]) for r in rows) for i in range(3)]
    for entry, (name, size, licence, source) in zip(CATALOGUE.values(), rows, strict=True):
        print(f"{name:<{widths[0]}}  {size:>{widths[1]}}  {licence:<{widths[2]}}  {source}")
        for f in entry.files if files else ():
            where = entry.url(f) or "written by this package (the source has none)"
            print(f"    {f.filename}  sha256 {f.sha256}  {where}")
    return 0


def _entry_record(entry: Any) -> dict[str, Any]:
    """A catalogue entry for ``maps list --json``."""
    files = [{"filename": f.filename, "sha256": f.sha256, "url": entry.url(f)} for f in entry.files]
    return {
        "name": entry.name,
        "size_bytes": entry.size_bytes,
        "licence": entry.licence,
        "source": entry.source,
        "files": files,
    }


def _expand_patterns(names: list[str]) -> list[str]:
    """Each name, or for a pattern with ``*``, ``?`` or ``[`` every catalogue name it matches."""
    import fnmatch

    from semexplore_gym.maps.catalogue import CATALOGUE

    out: list[str] = []
    for name in names:
        if not any(ch in name for ch in "*?["):
            out.append(name)
            continue
        matches = [n for n in CATALOGUE if fnmatch.fnmatchcase(n, name)]
        if not matches:
            raise ValueError(f"no catalogue map matches {name!r} (see: semexplore maps list)")
        out += matches
    return list(dict.fromkeys(out))


def _get(args: argparse.Namespace) -> int:
    from semexplore_gym.maps.catalogue import (
        RAW_GITHUB_BASE,
        get_catalogue_map,
        maps_cache_dir,
    )
    from semexplore_gym.maps.download import MapFetchError, copy_map, download_map

    if not (args.timeout_s > 0):
        raise ValueError(f"--timeout-s must be positive, got {args.timeout_s!r}")
    args.names = _expand_patterns(args.names)
    for name in args.names:
        get_catalogue_map(name)  # unknown names fail before anything is fetched
    root = Path(args.dir).expanduser() if args.dir else maps_cache_dir()
    fetched: dict[str, str] = {}
    for name in args.names:
        try:
            if args.from_dir:
                world = copy_map(name, Path(args.from_dir).expanduser(), root / name)
            else:
                world = download_map(
                    name,
                    root / name,
                    base_url=args.mirror or RAW_GITHUB_BASE,
                    timeout_s=args.timeout_s,
                )
        except MapFetchError as e:
            from semexplore_gym.cli import error_prefix

            print(f"{error_prefix(args)} {e}", file=sys.stderr)
            return 1
        fetched[name] = str(world)
        if not args.json:
            print(f"{name}: {world}")
    if args.json:
        print_json(args, {"maps": fetched})
    return 0


def _path(args: argparse.Namespace) -> int:
    from semexplore_gym.maps.catalogue import maps_cache_dir, resolve_map_file

    where = resolve_map_file(args.name) if args.name else maps_cache_dir()
    if args.json:
        print_json(args, {"path": str(where)})
    else:
        print(where)
    return 0


def run(args: argparse.Namespace) -> int:
    if args.maps_action == "list":
        return _list(args)
    if args.maps_action == "get":
        return _get(args)
    if args.maps_action == "path":
        return _path(args)
    args._maps_parser.print_help()
    return 2
