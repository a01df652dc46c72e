"""Checks of output file paths, made before any work is done.

Errors speak of the path and what is wrong with it; a command line adds the name of the flag
that gave the path (``semexplore_gym.cli._flags.check_output_flag``).
"""

from __future__ import annotations

from pathlib import Path

from semexplore_gym.core.validation import one_line, short_repr


def check_output_file(
    path: str, suffixes: tuple[str, ...] = (), *, parent_must_exist: bool = True
) -> None:
    """Refuse an output file path that cannot be written as asked, before any work is done.

    Raises:
        ValueError: ``path`` is empty, a directory, has another suffix than ``suffixes``, its
            name is too long, or (``parent_must_exist``) its parent directory does not exist;
            the message starts with the quoted path (a caller may put the flag name before it).
    """
    if not path or not str(path).strip():
        raise ValueError(f"{short_repr(str(path or ''))} is empty; give a file path")
    p = Path(path)
    shown = short_repr(str(path), 120)
    if len(p.name.encode()) > 255:
        raise ValueError(f"{shown}: the file name is longer than 255 bytes")
    try:
        is_dir = p.is_dir()
        parent_ok = p.parent.is_dir()
    except (OSError, ValueError) as e:
        raise ValueError(f"{shown}: {one_line(str(e))}") from None
    if is_dir:
        raise ValueError(f"{shown} is a directory; give a file path")
    if suffixes and p.suffix.lower() not in suffixes:
        raise ValueError(f"{shown} must end in {' or '.join(suffixes)}")
    if parent_must_exist and not parent_ok:
        raise ValueError(f"{shown}: directory {short_repr(str(p.parent), 120)} does not exist")
