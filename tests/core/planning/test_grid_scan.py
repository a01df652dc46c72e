"""The one-pass grid kernels give exactly the numpy expressions they replace."""

from __future__ import annotations

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, validate_encoded_grid
from semexplore_gym.core.planning.grid_scan import (
    checked_encoded_grid,
    encoded_grid_stats,
    known_cell_count,
)


def _encoded(rng: np.random.Generator, shape: tuple[int, int]) -> np.ndarray:
    return rng.choice(np.array([OCCUPIED, UNKNOWN, FREE], np.uint8), size=shape)


def _misaligned(g: np.ndarray) -> np.ndarray:
    """A copy of ``g`` whose data start one byte past a word boundary."""
    buf = np.zeros(g.size + 1, np.uint8)
    out = buf[1:].reshape(g.shape)
    out[:] = g
    assert out.ctypes.data % 8
    return out


@pytest.mark.parametrize("seed", range(4))
def test_known_cell_count_equals_numpy(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(60):
        shape = (int(rng.integers(1, 90)), int(rng.integers(1, 130)))
        g = _encoded(rng, shape) if rng.random() < 0.7 else rng.integers(0, 256, shape, np.uint8)
        for a in (g, _misaligned(g), g[1:, 2:], np.asfortranarray(g)):
            assert known_cell_count(a) == a.size - np.count_nonzero(a == UNKNOWN)
    # large grids use the word blocks and a byte tail
    g = np.full((1168, 1100), UNKNOWN, np.uint8)
    g[300:600, 200:701] = FREE
    g[400, 200:700] = OCCUPIED
    g[-1, -3:] = FREE
    assert known_cell_count(g) == g.size - np.count_nonzero(g == UNKNOWN)
    # other dtypes fall back to numpy
    ros = np.full((5, 7), -1, np.int8)
    ros[2, 3] = 0
    assert known_cell_count(ros) == ros.size - np.count_nonzero(ros == UNKNOWN)


def test_encoded_grid_stats_finds_every_foreign_value() -> None:
    rng = np.random.default_rng(7)
    g = _encoded(rng, (64, 300))
    assert encoded_grid_stats(g) == (np.count_nonzero(g == UNKNOWN), True)
    for v in (1, 127, 129, 254):
        for flat_index in (0, 5, g.size // 2, g.size - 1):
            b = g.copy()
            b.flat[flat_index] = v
            n_unknown, ok = encoded_grid_stats(b)
            assert not ok and n_unknown == np.count_nonzero(b == UNKNOWN)
            assert not encoded_grid_stats(_misaligned(b))[1]
    with pytest.raises(TypeError, match="uint8"):
        encoded_grid_stats(g.astype(np.int16))


def _error(fn, grid) -> tuple[type, str]:
    try:
        fn(grid)
    except (TypeError, ValueError) as exc:
        return type(exc), str(exc)
    return type(None), ""


def test_checked_encoded_grid_raises_what_validate_raises() -> None:
    rng = np.random.default_rng(3)
    g = _encoded(rng, (40, 250))
    assert checked_encoded_grid(g) is g
    bad_value = g.copy()
    bad_value[17, 201] = 42
    cases = [
        bad_value,
        g.astype(np.int16),
        g[0],
        np.zeros((0, 3), np.uint8),
        [[0, 128], [255, 7]],
        [[0, 128], [255, 255]],
    ]
    for case in cases:
        assert _error(checked_encoded_grid, case) == _error(validate_encoded_grid, case)
