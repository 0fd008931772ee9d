# SPDX-License-Identifier: GPL-2.0-or-later
"""Channels of the uncompressed multilayer EXR that the render hook itself
writes (Render Result saved with exr_codec 'NONE', 32-bit float). Needs numpy,
not bpy.

Why this reads the file itself instead of going through OpenEXR: Blender's
Python has no OpenEXR or OpenImageIO module, `bpy.data.images.load` gives no
pixels for multilayer EXRs, and a C reader would make the shipped libhbao.so
depend on OpenEXR's shared libraries, which official Blender builds do not
install (they link OpenEXR statically). The add-on writes this file itself a
few milliseconds earlier, uncompressed, so only the uncompressed scanline
layout needs to be understood: a header of attributes, a table of row
offsets, then one row per chunk holding each channel's row in name order.
numpy then sees each channel as a strided (height, width) view of the file's
bytes: no per-pixel work in Python, no copy. Anything else (compression,
tiles, several parts, deep data, subsampling) is refused with a message.
"""
import struct

import numpy as np

__all__ = ["EXRFormatError", "read_channels", "channel_names"]

_MAGIC = 20000630
_FLAG_TILED = 0x200
_FLAG_LONG_NAMES = 0x400
_FLAG_DEEP = 0x800
_FLAG_MULTIPART = 0x1000
_COMPRESSION_NONE = 0
_LINE_ORDER_INCREASING_Y = 0
# OpenEXR pixel types and their sizes in bytes.
_PIXEL_UINT, _PIXEL_HALF, _PIXEL_FLOAT = 0, 1, 2
_PIXEL_DTYPES = {_PIXEL_UINT: np.dtype("<u4"), _PIXEL_HALF: np.dtype("<f2"),
                 _PIXEL_FLOAT: np.dtype("<f4")}
# Bytes before each row's pixel data: its y coordinate and its data size (int32 each).
_CHUNK_PREFIX_SIZE = 8
_FLOAT_ALIGNMENT = 4


class EXRFormatError(ValueError):
    """The file is not an uncompressed single-part scanline EXR."""


def _read_string(data, offset, path):
    end = data.find(b"\0", offset)
    if end < 0:
        raise EXRFormatError(f"{path}: truncated EXR header")
    return data[offset:end].decode("latin-1"), end + 1


def _parse_header(data, path):
    if len(data) < 8:
        raise EXRFormatError(f"{path}: not an EXR file (too short)")
    magic, version = struct.unpack_from("<ii", data, 0)
    if magic != _MAGIC:
        raise EXRFormatError(f"{path}: not an EXR file")
    flags = version & ~0xFF
    if flags & (_FLAG_TILED | _FLAG_DEEP | _FLAG_MULTIPART):
        raise EXRFormatError(f"{path}: tiled, deep or multi-part EXRs are not supported")
    attributes = {}
    offset = 8
    while True:
        name, offset = _read_string(data, offset, path)
        if not name:
            break
        type_name, offset = _read_string(data, offset, path)
        if offset + 4 > len(data):
            raise EXRFormatError(f"{path}: truncated EXR header")
        (size,) = struct.unpack_from("<i", data, offset)
        offset += 4
        if size < 0 or offset + size > len(data):
            raise EXRFormatError(f"{path}: truncated EXR header")
        attributes[name] = (type_name, data[offset:offset + size])
        offset += size
    return attributes, offset


def _parse_channels(raw, path):
    channels = []
    offset = 0
    while offset < len(raw) and raw[offset] != 0:
        name, offset = _read_string(raw, offset, path)
        pixel_type, _linear, x_sampling, y_sampling = struct.unpack_from("<iB3xii", raw, offset)
        offset += 16
        if pixel_type not in _PIXEL_DTYPES:
            raise EXRFormatError(f"{path}: channel {name} has unknown pixel type {pixel_type}")
        if x_sampling != 1 or y_sampling != 1:
            raise EXRFormatError(f"{path}: channel {name} is subsampled")
        channels.append((name, _PIXEL_DTYPES[pixel_type]))
    return channels


class _Layout:
    """Header, channel list and row offsets of the EXR open in `stream`."""

    _HEADER_READ_SIZE = 1 << 16

    def __init__(self, path, stream):
        data = stream.read(self._HEADER_READ_SIZE)
        while True:
            try:
                attributes, header_end = _parse_header(data, path)
                break
            except EXRFormatError:
                more = stream.read(self._HEADER_READ_SIZE)
                if not more:
                    raise
                data += more
        for required in ("channels", "compression", "dataWindow", "lineOrder"):
            if required not in attributes:
                raise EXRFormatError(f"{path}: EXR header lacks {required}")
        if attributes["compression"][1][0] != _COMPRESSION_NONE:
            raise EXRFormatError(f"{path}: compressed EXR; the hook writes it with exr_codec "
                                 f"'NONE'")
        if attributes["lineOrder"][1][0] != _LINE_ORDER_INCREASING_Y:
            raise EXRFormatError(f"{path}: line order is not increasing y")
        x_min, y_min, x_max, y_max = struct.unpack("<iiii", attributes["dataWindow"][1])
        self.width = x_max - x_min + 1
        self.height = y_max - y_min + 1
        if self.width < 1 or self.height < 1:
            raise EXRFormatError(f"{path}: empty data window")
        self.y_min = y_min
        self.channels = _parse_channels(attributes["channels"][1], path)
        stream.seek(header_end)
        table = stream.read(8 * self.height)
        if len(table) != 8 * self.height:
            raise EXRFormatError(f"{path}: truncated EXR offset table")
        self.offsets = np.frombuffer(table, dtype="<u8")
        self.row_bytes = sum(dtype.itemsize for _, dtype in self.channels) * self.width
        self.chunk_bytes = _CHUNK_PREFIX_SIZE + self.row_bytes


def channel_names(path):
    """The channel names of an EXR file, in file order."""
    with open(path, "rb") as stream:
        return [name for name, _ in _Layout(path, stream).channels]


def read_channels(path, names):
    """{name: (height, width) float32 array, top row first} for the channels
    `names` of the uncompressed EXR at `path`. Raises EXRFormatError, or
    KeyError naming a missing channel and the channels the file has."""
    with open(path, "rb") as stream:
        layout = _Layout(path, stream)
        size = stream.seek(0, 2)
        first_row = int(layout.offsets[0])
        # Read the file into a buffer shifted so that the pixel data of every
        # row starts on a float boundary: the arrays handed to C are aligned.
        shift = -(first_row + _CHUNK_PREFIX_SIZE) % _FLOAT_ALIGNMENT
        buffer = np.empty(size + shift, dtype=np.uint8)
        stream.seek(0)
        if stream.readinto(memoryview(buffer)[shift:]) != size:
            raise EXRFormatError(f"{path}: file changed while being read")
    expected = first_row + np.arange(layout.height, dtype=np.uint64) * layout.chunk_bytes
    if not np.array_equal(layout.offsets, expected):
        raise EXRFormatError(f"{path}: rows are not stored one after another")
    if first_row + layout.height * layout.chunk_bytes > size:
        raise EXRFormatError(f"{path}: truncated EXR pixel data")
    rows = buffer[shift + first_row: shift + first_row + layout.height * layout.chunk_bytes]
    rows = rows.reshape(layout.height, layout.chunk_bytes)
    row_y = rows[:, 0:4].copy().view("<i4").reshape(-1)
    if not np.array_equal(row_y, layout.y_min + np.arange(layout.height)):
        raise EXRFormatError(f"{path}: rows are out of order")

    available = {}
    column = _CHUNK_PREFIX_SIZE
    for name, dtype in layout.channels:
        available[name] = (column, dtype)
        column += dtype.itemsize * layout.width
    result = {}
    for name in names:
        if name not in available:
            raise KeyError(f"{path} has no channel {name!r}; it has: "
                           f"{', '.join(sorted(available))}")
        column, dtype = available[name]
        view = rows[:, column:column + dtype.itemsize * layout.width].view(dtype)
        result[name] = view if dtype == np.float32 else view.astype(np.float32)
    return result

