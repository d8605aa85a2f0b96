"""Structural check of a MATLAB v5/v6/v7 file before ``scipy.io`` parses it.

scipy's compiled MAT v5 reader trusts the element tags it reads: a data element of an unknown
type indexes past a table (a segmentation fault, found by fuzzing: fuzz/regressions/read_mat),
and sizes that overrun their parent make it read into the next variable. A crash takes the
whole process with it, so every element of the file is checked here against the MAT-file
format first (tags, types, sizes, nesting, the number of cells and struct fields; compressed
variables are inflated and checked the same way) and a damaged file is a
:class:`~contactlab.io.RecordingError` naming the byte where it goes wrong. Files MATLAB and
scipy write pass (tests/test_io_hardening.py checks scipy's own collection of MATLAB files).
"""

from __future__ import annotations

import zlib
from pathlib import Path

from .recording import RecordingError

MI_MATRIX = 14
MI_COMPRESSED = 15
#: element types (miINT8 ... miUTF32) and their item sizes
ITEM_SIZE = {1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 4, 9: 8, 12: 8, 13: 8, 16: 1, 17: 2, 18: 4}
NUMERIC = frozenset({1, 2, 3, 4, 5, 6, 7, 9, 12, 13})
TEXT = frozenset({1, 2, 3, 4, 5, 6, 16, 17, 18})
NAME = frozenset({1, 2, 16})
#: array classes: cell, struct, object, char, sparse, double ... uint64, function, opaque
CELL, STRUCT, OBJECT, CHAR, SPARSE, FUNCTION, OPAQUE = 1, 2, 3, 4, 5, 16, 17
NUMERIC_CLASSES = range(6, 16)
#: MAT v5-v7 stores at most 2 GiB per variable (larger ones need v7.3): a compressed variable
#: inflating beyond that is damaged (or a decompression bomb)
MAX_INFLATED = 2**31
#: nesting beyond this (cells of structs of cells ...) is refused rather than recursed into
MAX_DEPTH = 64


class _Damaged(Exception):
    def __init__(self, at: int, what: str) -> None:
        super().__init__(what)
        self.at, self.what = at, what


class _Reader:
    """Elements of one byte buffer (the file, or a compressed variable inflated) in the file's
    byte order; ``origin`` maps positions in an inflated buffer back to the file for messages."""

    def __init__(self, buf: bytes, order: str, origin: int | None = None) -> None:
        self.buf, self.order, self.origin = buf, order, origin

    def where(self, pos: int) -> int:
        return pos if self.origin is None else self.origin

    def u32(self, pos: int) -> int:
        return int.from_bytes(self.buf[pos : pos + 4], self.order)

    def tag(self, pos: int, end: int) -> tuple[int, int, int, int]:
        """``(type, nbytes, data start, next element)`` of the element at ``pos`` within
        ``[pos, end)``: a full 8-byte tag (data padded to 8 bytes) or a small element (type and
        size in 4 bytes, up to 4 data bytes in the next 4)."""
        if pos + 8 > end:
            raise _Damaged(self.where(pos), "an element tag is cut off")
        first = self.u32(pos)
        if first >> 16:  # small data element
            mdtype, nbytes = first & 0xFFFF, first >> 16
            if nbytes > 4:
                raise _Damaged(self.where(pos), f"a small element claims {nbytes} bytes (max 4)")
            return mdtype, nbytes, pos + 4, pos + 8
        nbytes = self.u32(pos + 4)
        start = pos + 8
        if start + nbytes > end:
            raise _Damaged(self.where(pos), f"an element of {nbytes} bytes overruns its container")
        return first, nbytes, start, min(start + (nbytes + 7) // 8 * 8, end)

    def data(
        self, pos: int, end: int, types: frozenset[int], what: str, *, whole: bool = True
    ) -> tuple[int, int, int]:
        """A data element of one of ``types``: ``(type, item count, next)``. ``whole=False``
        accepts a byte count that is no multiple of the item size (MATLAB writes logical sparse
        values as bytes in an element typed miDOUBLE)."""
        mdtype, nbytes, _start, nxt = self.tag(pos, end)
        if mdtype not in types:
            raise _Damaged(self.where(pos), f"{what} has element type {mdtype}")
        size = ITEM_SIZE[mdtype]
        if whole and nbytes % size:
            raise _Damaged(self.where(pos), f"{what}: {nbytes} bytes are not whole items")
        return mdtype, nbytes // size, nxt

    def ints(self, pos: int, end: int, what: str) -> tuple[list[int], int]:
        """An miINT32 element (or miUINT32, which scipy accepts too) as signed integers."""
        mdtype, nbytes, start, nxt = self.tag(pos, end)
        if mdtype not in (5, 6) or nbytes % 4:
            raise _Damaged(self.where(pos), f"{what} is not an int32 element")
        vals = [
            int.from_bytes(self.buf[start + 4 * i : start + 4 * i + 4], self.order, signed=True)
            for i in range(nbytes // 4)
        ]
        return vals, nxt

    def matrix_element(self, pos: int, end: int, depth: int) -> int:
        """A nested miMATRIX element (a cell, a struct field); returns the next position."""
        mdtype, nbytes, start, nxt = self.tag(pos, end)
        if mdtype != MI_MATRIX:
            raise _Damaged(self.where(pos), f"expected a matrix element, found type {mdtype}")
        self.matrix(start, start + nbytes, depth + 1)
        return nxt

    def matrix(self, pos: int, end: int, depth: int) -> None:
        """The content of an miMATRIX element: flags, dimensions, name, then by class."""
        if depth > MAX_DEPTH:
            raise _Damaged(self.where(pos), f"variables nested more than {MAX_DEPTH} deep")
        if pos == end:
            return  # an empty matrix
        mdtype, nbytes, start, p = self.tag(pos, end)
        if mdtype != 6 or nbytes != 8:
            raise _Damaged(self.where(pos), "the array flags are not two uint32 values")
        flags = self.u32(start)
        cls, is_complex = flags & 0xFF, bool(flags & 0x800)
        if cls == OPAQUE:  # no dimensions: three names and one matrix
            for what in ("opaque name", "opaque type", "opaque class"):
                _t, _n, p = self.data(p, end, NAME, what)
            self.matrix_element(p, end, depth)
            return
        dims, p = self.ints(p, end, "the dimensions")
        if not 1 <= len(dims) <= 32 or min(dims) < 0:
            raise _Damaged(self.where(pos), f"invalid dimensions {dims[:8]}")
        n = 1
        for d in dims:
            n *= d
        _t, _n, p = self.data(p, end, NAME, "the name")
        if cls in NUMERIC_CLASSES:
            for part in ("real part", "imaginary part")[: 1 + is_complex]:
                _t, count, p = self.data(p, end, NUMERIC, f"the {part}")
                if count != n:
                    raise _Damaged(
                        self.where(pos), f"the {part} holds {count} values for dimensions {dims}"
                    )
        elif cls == CHAR:
            self.data(p, end, TEXT, "the characters")
        elif cls == SPARSE:
            if len(dims) != 2:
                raise _Damaged(self.where(pos), f"a sparse matrix with dimensions {dims}")
            for part in ("row indices", "column starts", "values", "imaginary values")[
                : 3 + is_complex
            ]:
                _t, _c, p = self.data(p, end, NUMERIC, f"the sparse {part}", whole=False)
        elif cls == CELL:
            for _ in range(n):
                p = self.matrix_element(p, end, depth)
        elif cls in (STRUCT, OBJECT):
            if cls == OBJECT:
                _t, _n, p = self.data(p, end, NAME, "the class name")
            (namelen, *rest), p = self.ints(p, end, "the field name length")
            if rest or namelen < 1:
                raise _Damaged(self.where(pos), f"field name length {namelen}")
            _t, chars, p = self.data(p, end, NAME, "the field names")
            for _ in range(n * (chars // namelen)):
                p = self.matrix_element(p, end, depth)
        elif cls == FUNCTION:
            self.matrix_element(p, end, depth)
        else:
            raise _Damaged(self.where(pos), f"unknown array class {cls}")


def check_mat5(path: str | Path, *, file: str) -> None:
    """Raise :class:`RecordingError` when the MAT v5 file at ``path`` is structurally damaged
    (see the module docstring); return quietly for a well-formed file."""
    buf = Path(path).read_bytes()
    if len(buf) < 128:
        raise RecordingError("damaged MATLAB file: the 128-byte header is cut off", file=file)
    order = "little" if buf[126:128] == b"IM" else "big"  # as scipy decides it
    top = _Reader(buf, order)
    pos = 128
    try:
        while pos < len(buf):
            mdtype, nbytes, start, _nxt = top.tag(pos, len(buf))
            if nbytes == 0:
                raise _Damaged(pos, "an empty top-level element")
            if mdtype == MI_COMPRESSED:
                inflated = _inflate(buf[start : start + nbytes], pos)
                inner = _Reader(inflated, order, origin=pos)
                _t, ib, istart, _n = inner.tag(0, len(inflated))
                if _t != MI_MATRIX:
                    raise _Damaged(pos, f"a compressed variable holds element type {_t}")
                inner.matrix(istart, istart + ib, 0)
            elif mdtype == MI_MATRIX:
                top.matrix(start, start + nbytes, 0)
            else:
                raise _Damaged(pos, f"a top-level element of type {mdtype} (not a variable)")
            pos = start + nbytes
    except _Damaged as exc:
        raise RecordingError(
            f"damaged MATLAB file at byte {exc.at}: {exc.what}", file=file
        ) from None


def _inflate(data: bytes, at: int) -> bytes:
    d = zlib.decompressobj()
    try:
        out = d.decompress(data, MAX_INFLATED)
    except zlib.error as exc:
        raise _Damaged(at, f"a compressed variable does not inflate ({exc})") from None
    if d.unconsumed_tail:
        raise _Damaged(at, "a compressed variable inflates beyond 2 GiB, the MAT v7 limit")
    return out
