#!/usr/bin/env python3
"""An independent reader of the Blender arm's UDP datagrams, standard library only.

Written from the format of the original MOSAIC's BlenderArm (MosaicLibary/Blocks/Devices/
BlenderArm.cs, AIROB-Lab/MOSAIC at bbacbd2), not from this project's code: every datagram is the
ASCII text "[v0,v1,...,v8]", the nine numbers joined by "," without spaces, in this order:

    0 thumb flexion, 1 thumb rotation, 2 index, 3 middle, 4 ring, 5 little   (0..1)
    6 wrist flexion/extension (flexion -1, extension 1)
    7 wrist ulnar/radial deviation (ulnar -1, radial 1)
    8 wrist supination/pronation                                               (-1..1)

Binds a UDP socket on loopback, prints {"port": P} as its first line (port 0 picks a free one),
receives datagrams until it has been idle for --idle seconds after the first one (or --timeout in
all), then prints one JSON object per datagram, in arrival order: {"values": [...]} or, for a
datagram that is not in the format, {"error": why, "bytes": hex}.

Usage: python3 blender_decode.py [--port P] [--idle S] [--timeout S]
"""

import argparse
import json
import math
import socket
import sys
import time

NAMES = [
    "thumb_flexion",
    "thumb_rotation",
    "index",
    "middle",
    "ring",
    "little",
    "wrist_flexion_extension",
    "wrist_ulnar_radial",
    "wrist_supination_pronation",
]


def decode(data):
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError:
        raise ValueError("not ASCII")
    if not (text.startswith("[") and text.endswith("]")):
        raise ValueError("not enclosed in [ ]: %r" % text)
    items = text[1:-1].split(",")
    if len(items) != len(NAMES):
        raise ValueError("%d values, expected %d" % (len(items), len(NAMES)))
    values = []
    for item in items:
        if item != item.strip() or item == "":
            raise ValueError("value %r has spaces or is empty" % item)
        v = float(item)
        if not math.isfinite(v):
            raise ValueError("value %r is not finite" % item)
        values.append(v)
    for i, v in enumerate(values):
        lo = 0.0 if i < 6 else -1.0
        if v < lo or v > 1.0:
            raise ValueError("%s = %r is outside [%g, 1]" % (NAMES[i], v, lo))
    return {"values": values, "named": dict(zip(NAMES, values))}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", type=int, default=0)
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
            print(json.dumps(decode(data)))
        except ValueError as e:
            print(json.dumps({"error": str(e), "bytes": data.hex()}))
    sys.stdout.flush()


if __name__ == "__main__":
    main()
