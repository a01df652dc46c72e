"""Animated GIFs written frame by frame (one frame in memory, however long the mission)."""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np


@dataclass(frozen=True)
class GifOptions:
    """An animated GIF of a mission: written to ``path``, a frame every ``every_s`` simulated
    seconds, played back at ``fps`` frames per second."""

    path: str | os.PathLike
    every_s: float = 2.0
    fps: float = 10.0


def _palette_frame(frame: np.ndarray, colors: int = 128) -> tuple[bytes, bytes, int, int]:
    """One RGB frame as GIF pieces: (colour table, LZW image data, width, height).

    Pillow encodes the frame as a one-frame GIF (adaptive palette); the colour table and the
    compressed image blocks are cut out of it, so frames can be appended to a file one by one.
    """
    import io

    from PIL import Image

    img = Image.fromarray(np.ascontiguousarray(frame[..., :3]).astype(np.uint8)).convert(
        "P", palette=Image.Palette.ADAPTIVE, colors=colors
    )
    buf = io.BytesIO()
    img.save(buf, format="GIF", interlace=False)
    data = buf.getvalue()
    if data[:3] != b"GIF":
        raise ValueError("Pillow did not write a GIF")
    packed = data[10]
    table = b""
    pos = 13
    if packed & 0x80:
        size = 3 * (2 ** ((packed & 0x07) + 1))
        table = data[pos : pos + size]
        pos += size
    while pos < len(data):
        block = data[pos]
        if block == 0x21:  # extension: label, then sub-blocks
            pos += 2
            while data[pos]:
                pos += data[pos] + 1
            pos += 1
        elif block == 0x2C:  # image descriptor
            width = int.from_bytes(data[pos + 5 : pos + 7], "little")
            height = int.from_bytes(data[pos + 7 : pos + 9], "little")
            flags = data[pos + 9]
            pos += 10
            if flags & 0x80:  # a local table replaces the global one
                size = 3 * (2 ** ((flags & 0x07) + 1))
                table = data[pos : pos + size]
                pos += size
            start = pos
            pos += 1  # LZW minimum code size
            while data[pos]:
                pos += data[pos] + 1
            pos += 1
            if flags & 0x40:
                raise ValueError("Pillow wrote an interlaced GIF frame")
            return table, data[start:pos], width, height
        else:
            break
    raise ValueError("no image in the GIF Pillow wrote")


class GifStreamWriter:
    """An animated, looping GIF written frame by frame.

    Each :meth:`append` encodes one frame (its own adaptive palette, as a local colour table)
    and writes it to ``PATH.part``; :meth:`close` ends the file and moves it to ``path``.
    Memory holds one frame, not the whole mission (Pillow's ``save_all`` needs every frame).
    """

    def __init__(self, path: str | os.PathLike, fps: float = 10.0, colors: int = 128) -> None:
        self.path = Path(path)
        self.delay_cs = max(2, int(round(100.0 / fps)))
        self.colors = colors
        self.n_frames = 0
        self._size: tuple[int, int] | None = None
        self._tmp = self.path.with_name(self.path.name + ".part")
        self._f: Any = None

    def append(self, frame: np.ndarray) -> None:
        table, image, width, height = _palette_frame(frame, self.colors)
        if self._f is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._f = self._tmp.open("wb")
            self._size = (width, height)
            # Header, logical screen (no global table), loop forever (NETSCAPE2.0).
            self._f.write(b"GIF89a" + _u16(width) + _u16(height) + b"\x00\x00\x00")
            self._f.write(b"\x21\xff\x0bNETSCAPE2.0\x03\x01" + _u16(0) + b"\x00")
        elif (width, height) != self._size:
            raise ValueError(f"GIF frame size {width}x{height} differs from {self._size}")
        n_bits = max(1, (len(table) // 3 - 1).bit_length())
        table = table.ljust(3 * 2**n_bits, b"\x00")
        self._f.write(b"\x21\xf9\x04\x04" + _u16(self.delay_cs) + b"\x00\x00")  # keep frame
        self._f.write(
            b"\x2c" + _u16(0) + _u16(0) + _u16(width) + _u16(height) + bytes([0x80 | (n_bits - 1)])
        )
        self._f.write(table)
        self._f.write(image)
        self.n_frames += 1

    def close(self) -> Path:
        """Finish the file; raises ValueError if no frame was appended."""
        if self._f is None:
            raise ValueError("no frames to write")
        self._f.write(b"\x3b")
        self._f.close()
        self._f = None
        os.replace(self._tmp, self.path)
        return self.path

    def abort(self) -> None:
        """Drop a half-written file (the mission failed)."""
        if self._f is not None:
            self._f.close()
            self._f = None
            self._tmp.unlink(missing_ok=True)


def _u16(v: int) -> bytes:
    return int(v).to_bytes(2, "little")


def save_gif(frames: Iterable[np.ndarray], path: str | os.PathLike, fps: float = 10.0) -> Path:
    """Write RGB frames as an animated, looping GIF, one frame in memory at a time."""
    writer = GifStreamWriter(path, fps=fps)
    try:
        for f in frames:
            writer.append(f)
        return writer.close()
    except BaseException:
        writer.abort()
        raise
