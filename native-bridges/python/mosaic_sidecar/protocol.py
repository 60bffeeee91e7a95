"""The sidecar's wire format (docs/protocols.md, "Python sidecar").

Every message is a 16-byte header followed by `length` bytes of payload:

    offset  size  type  field
    0       4     u32   magic 0x5950534D ("MSPY" in memory order)
    4       2     u16   protocol version (1)
    6       2     u16   message type (MessageType)
    8       4     u32   request id (echoed in the reply)
    12      4     u32   payload length in bytes

all little-endian. Control messages (hello, load, ok, error) carry UTF-8 JSON; the per-frame
messages (call, result) carry only binary arrays:

    array  = dtype u8 (1: f64, 2: f32), ndim u8, 0 u16, ndim × u32 dims, zero padding to a
             multiple of 8 bytes, then the values (C order, little-endian)
    call   = array
    result = f64 compute time in µs, then array
"""

from __future__ import annotations

import json
import struct
from enum import IntEnum
from typing import Any, BinaryIO

import numpy as np

MAGIC = 0x5950534D
VERSION = 1
HEADER = struct.Struct("<IHHII")
HEADER_SIZE = HEADER.size  # 16
MAX_PAYLOAD = 1 << 30


class MessageType(IntEnum):
    HELLO = 1  # host → sidecar (empty) and sidecar → host (JSON: versions, pid)
    LOAD = 2  # host → sidecar, JSON {module, function, init, params, input_shape, cwd}
    OK = 3  # sidecar → host, JSON (load: {output_shape}; reset: {})
    ERROR = 4  # sidecar → host, JSON {message, traceback, kind, ...}
    CALL = 5  # host → sidecar, array
    RESULT = 6  # sidecar → host, f64 µs + array
    RESET = 7  # host → sidecar: call init again (fresh state) → OK
    SHUTDOWN = 8  # host → sidecar: exit (no reply)


DTYPES = {1: np.dtype("<f8"), 2: np.dtype("<f4")}
DTYPE_CODES = {np.dtype("<f8"): 1, np.dtype("<f4"): 2}


class ProtocolError(Exception):
    """A malformed message: wrong magic, version, type or lengths."""


def header(kind: int, rid: int, length: int) -> bytes:
    return HEADER.pack(MAGIC, VERSION, int(kind), rid & 0xFFFFFFFF, length)


def parse_header(data: bytes | bytearray | memoryview) -> tuple[int, int, int]:
    """(type, id, payload length) of a 16-byte header; raises ProtocolError when malformed."""
    magic, version, kind, rid, length = HEADER.unpack(data)
    if magic != MAGIC:
        raise ProtocolError(f"bad magic 0x{magic:08x} (expected 0x{MAGIC:08x})")
    if version != VERSION:
        raise ProtocolError(f"protocol version {version}, this sidecar speaks {VERSION}")
    if length > MAX_PAYLOAD:
        raise ProtocolError(f"payload of {length} bytes is too large")
    return kind, rid, length


def _array_prefix_size(ndim: int) -> int:
    n = 4 + 4 * ndim
    return (n + 7) & ~7


def encode_array(a: np.ndarray) -> bytes:
    """The array encoding of `a` (f64 or f32; anything else is converted to f64)."""
    a = np.asarray(a)
    if a.dtype.newbyteorder("<") in DTYPE_CODES:
        a = a.astype(a.dtype.newbyteorder("<"), copy=False)
    else:
        a = a.astype("<f8")
    code = DTYPE_CODES[a.dtype]
    prefix = bytearray(_array_prefix_size(a.ndim))
    struct.pack_into("<BBH", prefix, 0, code, a.ndim, 0)
    for i, d in enumerate(a.shape):
        struct.pack_into("<I", prefix, 4 + 4 * i, d)
    return bytes(prefix) + np.ascontiguousarray(a).tobytes()


def decode_array(buf: bytes | bytearray | memoryview, offset: int = 0) -> np.ndarray:
    """The array encoded at `offset`: a view on `buf` (writable when `buf` is a bytearray)."""
    mv = memoryview(buf)
    if len(mv) - offset < 4:
        raise ProtocolError("array header truncated")
    code, ndim, _ = struct.unpack_from("<BBH", mv, offset)
    if code not in DTYPES:
        raise ProtocolError(f"unknown dtype code {code}")
    prefix = _array_prefix_size(ndim)
    if len(mv) - offset < prefix:
        raise ProtocolError("array shape truncated")
    shape = struct.unpack_from(f"<{ndim}I", mv, offset + 4)
    dtype = DTYPES[code]
    count = 1
    for d in shape:
        count *= d
    start = offset + prefix
    if len(mv) - start != count * dtype.itemsize:
        raise ProtocolError(
            f"array of shape {list(shape)} needs {count * dtype.itemsize} bytes, got {len(mv) - start}"
        )
    return np.frombuffer(mv, dtype=dtype, count=count, offset=start).reshape(shape)


def encode_json(obj: Any) -> bytes:
    return json.dumps(obj, allow_nan=True).encode("utf-8")


def message(kind: int, rid: int, payload: bytes = b"") -> bytes:
    return header(kind, rid, len(payload)) + payload


def read_exact(stream: BinaryIO, n: int) -> bytearray | None:
    """Exactly n bytes from `stream`, or None at end of input (before the first byte)."""
    buf = bytearray(n)
    view = memoryview(buf)
    got = 0
    while got < n:
        k = stream.readinto(view[got:])  # type: ignore[attr-defined]
        if not k:
            if got == 0:
                return None
            raise ProtocolError(f"input ended inside a message ({got} of {n} bytes)")
        got += k
    return buf


def read_message(stream: BinaryIO) -> tuple[int, int, bytearray] | None:
    """(type, id, payload) of the next message, or None at end of input."""
    head = read_exact(stream, HEADER_SIZE)
    if head is None:
        return None
    kind, rid, length = parse_header(head)
    payload = read_exact(stream, length) if length else bytearray()
    if payload is None:
        raise ProtocolError("input ended inside a message")
    return kind, rid, payload
