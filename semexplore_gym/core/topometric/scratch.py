"""Grid-sized scratch arrays of a segmentation, kept between calls by a segmenter."""

from __future__ import annotations

import numpy as np


class ScratchArrays:
    """Grid-sized scratch arrays, kept by a :class:`~.segmentation.TopometricSegmenter` between
    calls.

    Fresh arrays of a few MB cost more in page faults than the pass that fills them (a 1600^2
    map needs about 50 MB of scratch: 10-15 % of its segmentation time when freshly mapped).
    """

    def __init__(self, keep: bool) -> None:
        self.keep = keep
        self._bufs: dict[str, np.ndarray] = {}

    def take(self, name: str, n: int, dtype: type, fill: int | None = None) -> np.ndarray:
        """A 1-D array of ``n`` elements, all ``fill`` (or undefined), reused while large enough."""
        b = self._bufs.get(name)
        if b is not None and b.size >= n:
            b = b[:n]
            if fill is not None:
                b.fill(fill)
            return b
        # headroom when kept: an explored map grows a little between successive calls
        size = n + n // 4 + 1024 if self.keep else n
        # zeros come from calloc: pages nobody touches are never faulted in
        b = np.zeros(size, dtype) if fill == 0 else np.empty(size, dtype)
        if self.keep:
            self._bufs[name] = b
        b = b[:n]
        if fill:
            b.fill(fill)
        return b
