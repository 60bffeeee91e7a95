#!/usr/bin/env python3
"""An independent decoder of MOSAIC's UDP datagrams (docs/protocols.md), standard library only.

Binds a UDP socket on loopback, prints {"port": P} as its first line (port 0 picks a free one),
receives datagrams until it has been idle for --idle seconds after the first one (or --timeout
in all), then prints one JSON object per datagram, in arrival order.

Streamlined datagram, little-endian:
    | count u8 | type u8 | category u8 | subcategory u8 | timestamp f64 | count values | counter u16 |
type byte = 0x20 if floating point, else 0x10 if signed, plus the size of one value in bytes.

Usage: python3 udp_decode.py [--port P] [--format streamlined|f32|f64] [--idle S] [--timeout S]
"""

import argparse
import json
import math
import socket
import struct
import sys
import time

# (float?, signed?, size) -> struct code
CODES = {
    (True, True, 8): "d",
    (True, True, 4): "f",
    (False, True, 1): "b",
    (False, True, 2): "h",
    (False, True, 4): "i",
    (False, True, 8): "q",
    (False, False, 1): "B",
    (False, False, 2): "H",
    (False, False, 4): "I",
    (False, False, 8): "Q",
}


def value_code(type_byte):
    is_float = bool(type_byte & 0x20)
    is_signed = is_float or bool(type_byte & 0x10)
    if type_byte & 0x20 and type_byte & 0x10:
        raise ValueError("type byte 0x%02x has both the float and the signed flag" % type_byte)
    size = type_byte & 0x0F
    code = CODES.get((is_float, is_signed, size))
    if code is None or type_byte & 0xC0:
        raise ValueError("unknown type byte 0x%02x" % type_byte)
    return code, size


def decode_streamlined(data):
    if len(data) < 14:
        raise ValueError("%d bytes is shorter than header and counter" % len(data))
    count, type_byte, category, subcategory, timestamp = struct.unpack_from("<BBBBd", data, 0)
    code, size = value_code(type_byte)
    expected = 12 + count * size + 2
    if len(data) != expected:
        raise ValueError("%d values need %d bytes, got %d" % (count, expected, len(data)))
    values = list(struct.unpack_from("<%d%s" % (count, code), data, 12))
    (counter,) = struct.unpack_from("<H", data, 12 + count * size)
    return {
        "count": count,
        "type": type_byte,
        "category": category,
        "subcategory": subcategory,
        "timestamp": timestamp,
        "values": values,
        "counter": counter,
    }


def decode_raw(data, fmt):
    code, size = ("f", 4) if fmt == "f32" else ("d", 8)
    if len(data) % size:
        raise ValueError("%d bytes is not a whole number of %s values" % (len(data), fmt))
    return {"values": list(struct.unpack("<%d%s" % (len(data) // size, code), data))}


def clean(x):
    """JSON has no NaN or infinities: write them as strings."""
    if isinstance(x, float) and not math.isfinite(x):
        return repr(x)
    return x


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", type=int, default=0)
    ap.add_argument("--format", choices=["streamlined", "f32", "f64"], default="streamlined")
    ap.add_argument("--idle", type=float, default=1.0)
    ap.add_argument("--timeout", type=float, default=30.0)
    args = ap.parse_args()

    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", args.port))
    print(json.dumps({"port": sock.getsockname()[1]}), flush=True)

    received = []
    start = time.monotonic()
    last = None
    while True:
        now = time.monotonic()
        if now - start > args.timeout:
            break
        if last is not None and now - last > args.idle:
            break
        wait = args.timeout - (now - start)
        if last is not None:
            wait = min(wait, args.idle - (now - last))
        sock.settimeout(max(0.001, wait))
        try:
            data, _ = sock.recvfrom(65535)
        except socket.timeout:
            continue
        last = time.monotonic()
        received.append(data)

    for data in received:
        try:
            if args.format == "streamlined":
                d = decode_streamlined(data)
            else:
                d = decode_raw(data, args.format)
            d["values"] = [clean(v) for v in d["values"]]
            print(json.dumps(d))
        except ValueError as e:
            print(json.dumps({"error": str(e), "bytes": data.hex()}))
    sys.stdout.flush()


if __name__ == "__main__":
    main()
