"""Comma-separated lists on the command line: worlds (whose parameters hold commas too),
policies and suites; each world built once up front, and repeats refused."""

from __future__ import annotations

from semexplore_gym.core.validation import short_repr


def split_list(text: str) -> list[str]:
    """The non-empty, stripped items of a comma-separated list."""
    return [t.strip() for t in text.split(",") if t.strip()] if text else []


def split_worlds(text: str) -> list[str]:
    """Split on commas that start a new world: ``maze:seed=1,size_m=6,maze2`` keeps the params."""
    out: list[str] = []
    for part in split_list(text):
        if out and "=" in part and ":" not in part and ":" in out[-1]:
            out[-1] += "," + part  # a key=value of the previous world's parameters
        else:
            out.append(part)
    return out


def check_worlds(worlds: list[str], seed: int) -> None:
    """Build each world once before any mission starts, so a typo fails at once, not per mission.

    Raises:
        ValueError: an unknown or malformed world spelling (the message names it).
        FileNotFoundError: a map file that does not exist.
    """
    from semexplore_gym.maps import make_world

    for world in worlds:
        try:
            make_world(world.replace("seed=*", f"seed={seed}"))
        except FileNotFoundError as e:
            raise FileNotFoundError(f"--worlds {world!r}: {e}") from None
        except ValueError as e:
            raise ValueError(f"--worlds {world!r}: {e}") from None


def refuse_repeats(flag: str, items: list[str]) -> None:
    """A ValueError naming the first item ``flag`` lists twice."""
    dup = next((x for i, x in enumerate(items) if x in items[:i]), None)
    if dup is not None:
        raise ValueError(
            f"{flag} lists {short_repr(dup)} twice; each must appear once "
            "(a repeat would count the same missions twice)"
        )
