"""Reads an XDF file with pyxdf (an independent reader) and prints what it found as JSON.

Usage: xdf_check.py FILE [--full]

For every stream: the header fields, the channel labels, the footer (or null), the number of
samples, the first and last timestamps; with --full also every timestamp and value (floats as
JSON numbers: Python's repr round-trips float64 exactly, float32 values are widened exactly).
The file is loaded twice: with pyxdf's defaults (clock synchronisation and dejittering, what a
user gets) and raw (synchronize_clocks=False, dejitter_timestamps=False), whose values are
reported. Run with tests/reference/.venv/bin/python (pyxdf 1.17.5).
"""

import json
import math
import sys

import pyxdf


def first(d, key, default=None):
    v = d.get(key)
    return v[0] if isinstance(v, list) and v else default


def labels(info):
    desc = first(info, "desc")
    if not isinstance(desc, dict):
        return []
    channels = first(desc, "channels")
    if not isinstance(channels, dict):
        return []
    return [first(c, "label", "") for c in channels.get("channel", [])]


def number(x):
    x = float(x)
    return x if math.isfinite(x) else str(x)


def stream_json(s, full):
    info = s["info"]
    ts = s["time_stamps"]
    footer = None
    if "footer" in s:
        f = s["footer"]["info"]
        footer = {
            "first_timestamp": float(first(f, "first_timestamp")),
            "last_timestamp": float(first(f, "last_timestamp")),
            "sample_count": int(first(f, "sample_count")),
        }
    out = {
        "name": first(info, "name"),
        "type": first(info, "type"),
        "channel_count": int(first(info, "channel_count")),
        "nominal_srate": float(first(info, "nominal_srate")),
        "channel_format": first(info, "channel_format"),
        "source_id": first(info, "source_id"),
        "labels": labels(info),
        "footer": footer,
        "n": len(ts),
        "first": float(ts[0]) if len(ts) else None,
        "last": float(ts[-1]) if len(ts) else None,
        "clock_times": [float(t) for t in s["clock_times"]],
    }
    if full:
        out["time_stamps"] = [float(t) for t in ts]
        series = s["time_series"]
        if first(info, "channel_format") == "string":
            out["values"] = [list(row) for row in series]
        else:
            out["values"] = [[number(v) for v in row] for row in series.tolist()]
    return out


def main():
    path = sys.argv[1]
    full = "--full" in sys.argv[2:]
    # What a user gets: pyxdf's defaults must load the file (footers or not).
    default_streams, _ = pyxdf.load_xdf(path)
    streams, header = pyxdf.load_xdf(
        path, synchronize_clocks=False, dejitter_timestamps=False
    )
    print(
        json.dumps(
            {
                "version": first(header["info"], "version"),
                "default_counts": [len(s["time_stamps"]) for s in default_streams],
                "streams": [stream_json(s, full) for s in streams],
            }
        )
    )


if __name__ == "__main__":
    main()
