"""An independent LSL peer for tests/integration/lsl.test.ts, written with pylsl (its own liblsl).

Both directions at once, each in its own thread, printing one JSON line per event:
  - reader: resolves MOSAIC's outlet by name, subscribes, says "inlet-ready" (with what the
    stream declares), pulls N samples, checks every value against the test's formula
    (k * 32 + c) / 8 - 5000.5 and reports the count, the mismatches and every timestamp;
  - writer: an outlet (double64, RATE Hz, CHANNELS channels, source id "py-peer") that waits
    for a consumer, then pushes N samples in real time in small chunks, sample k carrying
    -(k * 32 + c) / 4 + 0.125 and the timestamp t0 + k / RATE (t0 reported in "outlet-start").
Markers mode: reads MOSAIC's marker stream and sends string markers back (see markers()).
Example mode: reads pipelines/examples/lsl-outlet.yaml's streams (see read_example()).

Discovery follows LSLAPICFG (the test's lsl_api.cfg: this machine only).
"""

import json
import sys
import threading
import time

import pylsl

RATE = 2000
CHANNELS = 32
lock = threading.Lock()


def say(obj):
    with lock:
        print(json.dumps(obj), flush=True)


def labels_of(info):
    out = []
    ch = info.desc().child("channels").child("channel")
    while not ch.empty():
        out.append(ch.child_value("label"))
        ch = ch.next_sibling()
    return out


def reader(name, n):
    streams = pylsl.resolve_byprop("name", name, 1, 30)
    if not streams:
        say({"event": "inlet-failed", "why": f"no stream named {name}"})
        return
    inlet = pylsl.StreamInlet(streams[0], max_buflen=60, recover=False)
    inlet.open_stream(30)
    info = inlet.info(10)
    say(
        {
            "event": "inlet-ready",
            "name": info.name(),
            "type": info.type(),
            "channels": info.channel_count(),
            "rate": info.nominal_srate(),
            "format": info.channel_format(),
            "source_id": info.source_id(),
            "labels": labels_of(info),
        }
    )
    got = 0
    bad = 0
    stamps = []
    deadline = time.time() + 60
    while got < n and time.time() < deadline:
        chunk, ts = inlet.pull_chunk(timeout=0.2, max_samples=4096)
        for s, t in zip(chunk, ts):
            for c in range(len(s)):
                if s[c] != (got * 32 + c) / 8 - 5000.5:
                    bad += 1
            got += 1
            stamps.append(t)
    say({"event": "inlet-done", "samples": got, "bad": bad, "timestamps": stamps})


def writer(name, n):
    info = pylsl.StreamInfo(name, "EMG", CHANNELS, RATE, "double64", "py-peer")
    outlet = pylsl.StreamOutlet(info, chunk_size=0, max_buffered=60)
    if not outlet.wait_for_consumers(30):
        say({"event": "no-consumer"})
        return
    t0 = pylsl.local_clock()
    say({"event": "outlet-start", "t0": t0})
    k = 0
    while k < n:
        due = min(n, int((pylsl.local_clock() - t0) * RATE) + 1)
        if due > k:
            rows = [[-(j * 32 + c) / 4 + 0.125 for c in range(CHANNELS)] for j in range(k, due)]
            outlet.push_chunk(rows, [t0 + j / RATE for j in range(k, due)])
            k = due
        time.sleep(0.002)
    say({"event": "outlet-done", "samples": k})
    # Keep the outlet until the test has read everything (it closes our stdin).
    sys.stdin.read()


def markers(name_in, name_out):
    """Reads MOSAIC's string markers; sends int32 and string markers back."""
    streams = pylsl.resolve_byprop("name", name_in, 1, 30)
    inlet = pylsl.StreamInlet(streams[0], max_buflen=60, recover=False)
    inlet.open_stream(30)
    info = inlet.info(10)
    out_info = pylsl.StreamInfo(name_out, "Markers", 1, 0, "string", "py-markers")
    outlet = pylsl.StreamOutlet(out_info)
    say({"event": "markers-ready", "format": info.channel_format(), "type": info.type()})
    if not outlet.wait_for_consumers(30):
        say({"event": "no-consumer"})
        return
    t0 = pylsl.local_clock()
    sent = ["rest", "power", "7", "oops", "power"]
    for i, m in enumerate(sent):
        outlet.push_sample([m], t0 + i * 0.1)
    say({"event": "markers-sent", "t0": t0, "markers": sent})
    got = []
    deadline = time.time() + 30
    line = sys.stdin.readline()  # the test says how many markers to expect
    want = int(line.strip() or "0")
    while len(got) < want and time.time() < deadline:
        chunk, ts = inlet.pull_chunk(timeout=0.2)
        got.extend([[s[0], t] for s, t in zip(chunk, ts)])
    say({"event": "markers-received", "markers": got})
    sys.stdin.read()


def read_example(seconds):
    """Reads pipelines/examples/lsl-outlet.yaml's two streams for `seconds`."""
    emg = pylsl.resolve_byprop("name", "MosaicEMG", 1, 30)
    cues = pylsl.resolve_byprop("name", "MosaicCues", 1, 30)
    if not emg or not cues:
        say({"event": "example-failed", "why": "MosaicEMG or MosaicCues not found"})
        return
    i = pylsl.StreamInlet(emg[0], max_buflen=60)
    j = pylsl.StreamInlet(cues[0], max_buflen=60)
    i.open_stream(10)
    j.open_stream(10)
    info = i.info(10)
    n = 0
    stamps = []
    marks = []
    end = time.time() + seconds
    while time.time() < end:
        chunk, ts = i.pull_chunk(timeout=0.1, max_samples=8192)
        n += len(chunk)
        stamps += ts
        chunk, ts = j.pull_chunk(timeout=0.0)
        marks += [m[0] for m in chunk]
    steps = [b - a for a, b in zip(stamps, stamps[1:])] or [0.0]
    say(
        {
            "event": "example-read",
            "channels": info.channel_count(),
            "rate": info.nominal_srate(),
            "format": info.channel_format(),
            "labels": labels_of(info),
            "samples": n,
            "step_min": min(steps),
            "step_max": max(steps),
            "markers": marks,
        }
    )


def main():
    mode = sys.argv[1]
    if mode == "stream":
        n = int(sys.argv[2])
        threads = [
            threading.Thread(target=reader, args=("MosaicOut", n)),
            threading.Thread(target=writer, args=("PyOut", n)),
        ]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    elif mode == "markers":
        markers("MosaicMarkers", "PyMarkers")
    elif mode == "example":
        read_example(float(sys.argv[2]))


if __name__ == "__main__":
    main()
