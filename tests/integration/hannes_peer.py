#!/usr/bin/env python3
"""Peers of the Hannes blocks for the integration tests, standard library only, written from the
original MOSAIC's code (AIROB-Lab/MOSAIC at bbacbd2, MosaicLibary/Blocks/Devices/HannesHand.cs,
HannesGUI.cs, HannesReceiver.cs), not from this project's code.

  dongle --port PTY --log FILE [--timeout S] [--names A,B]
      Plays IIT's Rehab Dongle with a Hannes hand behind it on a serial pty: "$$$" (command
      mode), "scan\\r\\n" (answers a table of devices and "Success"), "con N\\r\\n", "dct\\r\\n";
      packets "%" + command + payload + "&\\r\\n" to the hand, each ACKed ("%\\x02&\\r\\n"). Writes one
      JSON line per command received to FILE; exits after "dct" or the timeout.

  gui [--port P] [--idle S] [--timeout S]
      Receives HannesGUI datagrams on loopback UDP (prints {"port": P} first), then prints one
      JSON line per datagram: activation (kind 15: joint, value), raw EMG (kind 16: signed bytes)
      or ARV (kind 32: little-endian doubles).

  emg --to PORT --count N [--delay S] [--rate HZ] [--channels C]
      Sends N EMG datagrams to 127.0.0.1:PORT: "%", 16, then C little-endian uint16 values
      (value k of datagram i is (i * 977 + k * 8191) % 65536), and prints them as JSON lines.
"""

import argparse
import json
import os
import select
import socket
import struct
import sys
import termios
import time
import tty

# Payload lengths of the hand's commands (command byte included), from HannesHand.cs.
PACKET_LEN = {0: 1, 1: 1, 14: 3, 30: 11}
ACK = b"%\x02&\r\n"


def dongle(args):
    fd = os.open(args.port, os.O_RDWR | os.O_NOCTTY)
    tty.setraw(fd)
    attrs = termios.tcgetattr(fd)
    attrs[3] &= ~termios.ECHO
    termios.tcsetattr(fd, termios.TCSANOW, attrs)
    names = args.names.split(",")
    log = open(args.log, "w")
    buf = b""
    end = time.monotonic() + args.timeout
    done = False

    def record(entry):
        log.write(json.dumps(entry) + "\n")
        log.flush()

    while not done and time.monotonic() < end:
        r, _, _ = select.select([fd], [], [], 0.05)
        if r:
            try:
                chunk = os.read(fd, 4096)
            except OSError:
                break
            if not chunk:
                break
            buf += chunk
        while buf:
            if buf[:1] == b"%":
                if len(buf) < 2:
                    break
                n = PACKET_LEN.get(buf[1])
                if n is None:
                    record({"error": "unknown command %d" % buf[1], "bytes": buf.hex()})
                    buf = buf[1:]
                    continue
                if len(buf) < 1 + n + 3:
                    break
                payload, tail = buf[1 : 1 + n], buf[1 + n : 1 + n + 3]
                buf = buf[1 + n + 3 :]
                if tail != b"&\r\n":
                    record({"error": "bad end %s" % tail.hex(), "payload": list(payload)})
                    continue
                record({"packet": list(payload)})
                os.write(fd, ACK)
            elif buf.startswith(b"$$$"):
                buf = buf[3:]
                record({"text": "$$$"})
            elif b"\r\n" in buf:
                line, buf = buf.split(b"\r\n", 1)
                text = line.decode("ascii", "replace")
                record({"text": text})
                if text == "scan":
                    out = "  #  Con RSSI Address      Name\r\n"
                    for i, name in enumerate(names):
                        out += "%d %d -5%d 00112233445%d %s\r\n" % (i, i + 1, i, i, name)
                    out += "Success\r\n"
                    os.write(fd, out.encode("ascii"))
                elif text.startswith("con "):
                    os.write(fd, ("%s\r\nSuccess\r\nSTREAM_MODE\r\n" % text).encode("ascii"))
                elif text == "dct":
                    os.write(fd, b"Success\r\n")
                    done = True
            else:
                break
    log.close()


def gui(args):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", args.port))
    print(json.dumps({"port": sock.getsockname()[1]}), flush=True)
    received = []
    start = time.monotonic()
    last = None
    while True:
        now = time.monotonic()
        if now - start > args.timeout or (last is not None and now - last > args.idle):
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
    for d in received:
        if len(d) < 5 or d[0] != 0x25 or d[-3:] != b"&\r\n":
            print(json.dumps({"error": "not framed", "bytes": d.hex()}))
            continue
        kind, body = d[1], d[2:-3]
        if kind == 15 and len(body) == 2:
            print(json.dumps({"kind": "activation", "joint": body[0], "value": body[1]}))
        elif kind == 16:
            print(json.dumps({"kind": "raw", "values": list(struct.unpack("<%db" % len(body), body))}))
        elif kind == 32 and len(body) % 8 == 0:
            vals = struct.unpack("<%dd" % (len(body) // 8), body)
            print(json.dumps({"kind": "arv", "values": list(vals)}))
        else:
            print(json.dumps({"error": "kind %d with %d bytes" % (kind, len(body))}))
    sys.stdout.flush()


def emg(args):
    time.sleep(args.delay)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    for i in range(args.count):
        vals = [(i * 977 + k * 8191) % 65536 for k in range(args.channels)]
        sock.sendto(bytes([0x25, 16]) + struct.pack("<%dH" % args.channels, *vals), ("127.0.0.1", args.to))
        print(json.dumps(vals), flush=True)
        time.sleep(1.0 / args.rate)


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="mode", required=True)
    d = sub.add_parser("dongle")
    d.add_argument("--port", required=True)
    d.add_argument("--log", required=True)
    d.add_argument("--timeout", type=float, default=30.0)
    d.add_argument("--names", default="HannesL")
    g = sub.add_parser("gui")
    g.add_argument("--port", type=int, default=0)
    g.add_argument("--idle", type=float, default=1.0)
    g.add_argument("--timeout", type=float, default=30.0)
    e = sub.add_parser("emg")
    e.add_argument("--to", type=int, required=True)
    e.add_argument("--count", type=int, default=50)
    e.add_argument("--delay", type=float, default=1.0)
    e.add_argument("--rate", type=float, default=100.0)
    e.add_argument("--channels", type=int, default=6)
    args = ap.parse_args()
    {"dongle": dongle, "gui": gui, "emg": emg}[args.mode](args)


if __name__ == "__main__":
    main()
