"""A serial device played by pyserial, for tests/integration/serial.test.ts.

Opens PORT (one end of a socat pty pair; MOSAIC's SerialPort block has the other), waits until
MOSAIC writes a first frame to it (so nothing is sent before MOSAIC listens), then streams
COUNT frames at RATE Hz and exits. Frame k carries the values of `frame_values(k)`.

  lines:  "v1,v2,v3\\n", plus one malformed line after frame FIRST+5 ("oops,1\\n")
  binary: AA 55 | i16 | f32 | u16 | CRC-16/CCITT-FALSE over the 8 payload bytes (little endian),
          plus one frame with a corrupted checksum after frame FIRST+5

Everything MOSAIC writes (lines, or binary frames) is decoded and written as JSON lines to
--received (one [values] per frame), so the test can check the outgoing direction too.
"""

import argparse
import json
import struct
import sys
import time

import serial


def frame_values(k):
    return [k - 50, k * 0.25, (k * 7) % 65536]


def crc16(data):
    crc = 0xFFFF
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


def encode(mode, values):
    if mode == "lines":
        return (",".join(repr(float(v)) if isinstance(v, float) else str(v) for v in values) + "\n").encode()
    payload = struct.pack("<hfH", int(values[0]), values[1], int(values[2]))
    return b"\xaa\x55" + payload + struct.pack("<H", crc16(payload))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", required=True)
    ap.add_argument("--mode", choices=["lines", "binary"], required=True)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--count", type=int, default=100)
    ap.add_argument("--rate", type=float, default=200.0)
    ap.add_argument("--received", required=True)
    ap.add_argument("--wait", type=float, default=20.0, help="seconds to wait for MOSAIC")
    a = ap.parse_args()

    dev = serial.Serial(a.port, baudrate=115200, timeout=0.05)
    received = open(a.received, "a", encoding="utf-8")
    pending = b""

    def drain(block=False):
        nonlocal pending
        # Blocking (up to the port timeout) only while waiting for MOSAIC; never while streaming.
        waiting = dev.in_waiting
        if waiting or block:
            pending += dev.read(max(waiting, 1))
        frames = 0
        if a.mode == "lines":
            while b"\n" in pending:
                line, pending = pending.split(b"\n", 1)
                if line.strip():
                    received.write(json.dumps([float(x) for x in line.decode().split(",")]) + "\n")
                    frames += 1
        else:
            while len(pending) >= 12:
                i = pending.find(b"\xaa\x55")
                if i < 0:
                    pending = pending[-1:]
                    break
                pending = pending[i:]
                if len(pending) < 12:
                    break
                payload, (cs,) = pending[2:10], struct.unpack("<H", pending[10:12])
                if crc16(payload) == cs:
                    received.write(json.dumps(list(struct.unpack("<hfH", payload))) + "\n")
                    frames += 1
                    pending = pending[12:]
                else:
                    pending = pending[1:]
        received.flush()
        return frames

    deadline = time.monotonic() + a.wait
    while drain(block=True) == 0:
        if time.monotonic() > deadline:
            print("serial_device: MOSAIC never wrote to the port", file=sys.stderr)
            return 3

    period = 1.0 / a.rate
    t = time.monotonic()
    for k in range(a.first, a.first + a.count):
        dev.write(encode(a.mode, frame_values(k)))
        if k == a.first + 5:
            if a.mode == "lines":
                dev.write(b"oops,1\n")
            else:
                bad = bytearray(encode(a.mode, frame_values(k)))
                bad[-1] ^= 0xFF
                dev.write(bytes(bad))
        drain()
        t += period
        time.sleep(max(0.0, t - time.monotonic()))
    dev.flush()
    time.sleep(0.2)
    drain()
    dev.close()
    print(f"serial_device: sent frames {a.first}..{a.first + a.count - 1} ({a.mode})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
