"""Framing: header and array round trips, bit for bit."""

import io
import struct

import numpy as np
import pytest

from mosaic_sidecar import protocol as P


def bits(a: np.ndarray) -> bytes:
    return np.ascontiguousarray(a).tobytes()


SPECIAL = np.array(
    [
        [np.nan, -np.nan, np.inf, -np.inf],
        [0.0, -0.0, 5e-324, -5e-324],  # ±0 and the smallest subnormals
        [2.2250738585072009e-308, 1.7976931348623157e308, np.pi, -1 / 3],
    ]
)


def test_header_layout():
    h = P.header(P.MessageType.CALL, 7, 40)
    assert len(h) == P.HEADER_SIZE == 16
    assert h[:4] == b"MSPY"
    assert struct.unpack("<IHHII", h) == (P.MAGIC, 1, 5, 7, 40)
    assert P.parse_header(h) == (5, 7, 40)


def test_bad_headers():
    with pytest.raises(P.ProtocolError, match="magic"):
        P.parse_header(b"XXXX" + P.header(5, 1, 0)[4:])
    with pytest.raises(P.ProtocolError, match="version"):
        P.parse_header(struct.pack("<IHHII", P.MAGIC, 2, 5, 1, 0))


@pytest.mark.parametrize("shape", [(1, 1), (1, 12), (3, 4), (200, 32)])
def test_array_round_trip_bit_exact(shape):
    rng = np.random.default_rng(1)
    a = rng.standard_normal(shape) * 10.0 ** rng.integers(-300, 300, shape)
    flat = a.reshape(-1)
    flat[: min(12, flat.size)] = SPECIAL.reshape(-1)[: min(12, flat.size)]
    enc = P.encode_array(a)
    assert len(enc) % 8 == 0
    b = P.decode_array(bytearray(enc))
    assert b.shape == shape and b.dtype == np.float64
    assert bits(b) == bits(a)


def test_nan_payloads_survive():
    raw = np.array([0x7FF8000000000001, 0xFFF4000000000000, 0x0000000000000001], dtype="<u8")
    a = raw.view("<f8").reshape(1, 3)
    assert bits(P.decode_array(P.encode_array(a))) == raw.tobytes()


def test_f32_arrays():
    a = np.array([[1.5, -0.0, np.nan]], dtype="<f4")
    b = P.decode_array(P.encode_array(a))
    assert b.dtype == np.float32 and bits(b) == bits(a)


def test_decoded_array_is_writable_on_a_bytearray():
    b = P.decode_array(bytearray(P.encode_array(np.ones((2, 2)))))
    b -= 1  # user code may modify its input in place
    assert not b.any()


def test_length_mismatch():
    enc = P.encode_array(np.ones((2, 2)))
    with pytest.raises(P.ProtocolError, match="needs 32 bytes"):
        P.decode_array(enc[:-8])


def test_message_stream_round_trip():
    a = SPECIAL
    stream = io.BytesIO(
        P.message(P.MessageType.CALL, 3, P.encode_array(a))
        + P.message(P.MessageType.SHUTDOWN, 4)
    )
    kind, rid, payload = P.read_message(stream)
    assert (kind, rid) == (P.MessageType.CALL, 3)
    assert bits(P.decode_array(payload)) == bits(a)
    assert P.read_message(stream) == (P.MessageType.SHUTDOWN, 4, bytearray())
    assert P.read_message(stream) is None


def test_truncated_stream():
    data = P.message(P.MessageType.CALL, 3, P.encode_array(np.ones((1, 4))))
    with pytest.raises(P.ProtocolError, match="ended inside"):
        P.read_message(io.BytesIO(data[:-3]))
