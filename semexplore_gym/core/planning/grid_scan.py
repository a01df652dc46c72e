"""Fast whole-grid passes over an encoded occupancy grid: known cells and the encoding check.

A planner that runs every control step on a large map (Willow Garage: 1.3 M cells) pays for
each pass over the whole grid: ``grid.size - np.count_nonzero(grid == UNKNOWN)`` builds a
temporary of the grid's size, and :func:`~semexplore_gym.core.grid.validate_encoded_grid`
three of them. :func:`encoded_grid_stats` gets both answers in one read of the grid, eight
cells at a time (the grid viewed as 64-bit words, each byte tested with word arithmetic that
the compiler turns into vector instructions): 3-5x faster than the numpy expressions.

The results are exact: :func:`known_cell_count` equals ``grid.size - np.count_nonzero(grid ==
UNKNOWN)`` for any uint8 grid, and :func:`checked_encoded_grid` raises exactly what
``validate_encoded_grid`` raises (it calls it whenever the fast check finds a problem).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from numba import njit, uint64

from semexplore_gym.core.grid import UNKNOWN, validate_encoded_grid

__all__ = ["checked_encoded_grid", "encoded_grid_stats", "known_cell_count"]

#: Words per block: each block's per-byte counters (one byte per lane) must not overflow.
_BLOCK_WORDS = 248

_LOW7 = 0x7F7F7F7F7F7F7F7F
_HIGH = 0x8080808080808080
_EVEN = 0x00FF00FF00FF00FF


@njit(cache=True, boundscheck=False)
def _byte_sum(acc):  # type: ignore[no-untyped-def]  # pragma: no cover - numba
    """Sum of the eight byte lanes of ``acc``."""
    even = uint64(_EVEN)
    s = (acc & even) + ((acc >> uint64(8)) & even)
    s = s + (s >> uint64(16))
    s = s + (s >> uint64(32))
    return int(s & uint64(0xFFFF))


@njit(cache=True, boundscheck=False)
def _unknown_cells(flat):  # type: ignore[no-untyped-def]  # pragma: no cover - numba
    """Bytes of the uint8 array ``flat`` equal to UNKNOWN (128)."""
    low7 = uint64(_LOW7)
    high = uint64(_HIGH)
    seven = uint64(7)
    n = flat.size
    n_blocks = n // (8 * _BLOCK_WORDS)
    if flat.ctypes.data % 8:
        n_blocks = 0  # not word-aligned: bytes only
    head = n_blocks * _BLOCK_WORDS * 8
    words = flat[:head].view(np.uint64)
    n_unknown = 0
    for b in range(n_blocks):
        acc = uint64(0)  # one counter per byte lane
        for k in range(b * _BLOCK_WORDS, (b + 1) * _BLOCK_WORDS):
            y = words[k] ^ high
            # high bit of each byte set where that byte of y is non-zero (exact: no carries)
            nz_y = (((y & low7) + low7) | y) & high
            acc += ((~nz_y) & high) >> seven
        n_unknown += _byte_sum(acc)
    for k in range(head, n):
        n_unknown += flat[k] == 128
    return n_unknown


@njit(cache=True, boundscheck=False)
def _grid_stats(flat):  # type: ignore[no-untyped-def]  # pragma: no cover - numba
    """:func:`_unknown_cells`, and whether a byte is none of OCCUPIED (0) / UNKNOWN (128) /
    FREE (255)."""
    low7 = uint64(_LOW7)
    high = uint64(_HIGH)
    seven = uint64(7)
    n = flat.size
    n_blocks = n // (8 * _BLOCK_WORDS)
    if flat.ctypes.data % 8:
        n_blocks = 0
    head = n_blocks * _BLOCK_WORDS * 8
    words = flat[:head].view(np.uint64)
    n_unknown = 0
    bad = uint64(0)
    for b in range(n_blocks):
        acc = uint64(0)
        block_bad = uint64(0)
        for k in range(b * _BLOCK_WORDS, (b + 1) * _BLOCK_WORDS):
            x = words[k]
            y = x ^ high
            nz_y = (((y & low7) + low7) | y) & high  # byte != 128
            nz_x = (((x & low7) + low7) | x) & high  # byte != 0
            nx = ~x
            nz_nx = (((nx & low7) + low7) | nx) & high  # byte != 255
            acc += ((~nz_y) & high) >> seven
            block_bad |= nz_x & nz_y & nz_nx
        bad |= block_bad
        n_unknown += _byte_sum(acc)
    ok = bad == 0
    for k in range(head, n):
        v = flat[k]
        n_unknown += v == 128
        ok = ok and (v == 0 or v == 128 or v == 255)
    return n_unknown, ok


def encoded_grid_stats(grid: np.ndarray) -> tuple[int, bool]:
    """``(unknown_cells, all_valid)`` of a uint8 grid in one pass.

    Args:
        grid: A uint8 array of any shape.

    Returns:
        The number of cells equal to UNKNOWN, and whether every cell is OCCUPIED, UNKNOWN or
        FREE.
    """
    flat = np.ravel(grid)
    if flat.dtype != np.uint8:
        raise TypeError(f"grid must have dtype uint8, got {flat.dtype}")
    n_unknown, ok = _grid_stats(flat)
    return int(n_unknown), bool(ok)


def known_cell_count(grid: np.ndarray) -> int:
    """``grid.size - np.count_nonzero(grid == UNKNOWN)``: one fast pass for a uint8 grid."""
    flat = np.ravel(grid)
    if flat.dtype != np.uint8:
        return int(flat.size - np.count_nonzero(flat == UNKNOWN))
    return int(flat.size - _unknown_cells(flat))


def checked_encoded_grid(grid: npt.ArrayLike, name: str = "grid") -> np.ndarray:
    """:func:`~semexplore_gym.core.grid.validate_encoded_grid`, with a fast pass for valid grids.

    Returns ``grid`` as a uint8 array; raises what ``validate_encoded_grid`` raises.
    """
    a = np.asarray(grid)
    if a.ndim == 2 and a.dtype == np.uint8 and a.size and _grid_stats(np.ravel(a))[1]:
        return a
    return validate_encoded_grid(a, name)
