"""Reads EDF+/BDF+ files written by MOSAIC's EdfRecorder with three independent readers
(pyedflib, edfio, MNE) and checks them against what the pipeline sent.

Usage: python edf_check.py JOB.json  ->  prints one JSON object: {"files": [{path, records,
start, duration, failures: [...]}, ...]}. The job:
  files        [paths]
  labels       signal labels in order (the annotations signal excluded)
  rates        their sampling rates, Hz
  digital      {label: [ints]}: the digital values expected from the start (a killed file holds a
               prefix of them: compared over what it holds)
  physical     {label: [floats]}: physical values sent; each read value must be within one
               digital step of it
  annotations  [[onset, text], ...] expected (onsets from the first sample, s; a killed file
               holds those before its end)
A reader that cannot open a file is a failure, with its message.
"""

import datetime as dt
import json
import sys
import warnings

import edfio
import mne
import numpy as np
import pyedflib

warnings.simplefilter("ignore")
UNIT = {"uV": 1e-6, "mV": 1e-3, "V": 1.0, "": 1.0}


def steps(header_signal):
    lo, hi, dlo, dhi = header_signal
    return (hi - lo) / (dhi - dlo)


def compare(fail, who, label, got, want, tol):
    n = min(len(got), len(want))
    if n == 0:
        fail.append(f"{who} {label}: no samples")
        return
    err = np.abs(np.asarray(got[:n], dtype=float) - np.asarray(want[:n], dtype=float))
    worst = int(np.argmax(err))
    if err[worst] > tol:
        fail.append(
            f"{who} {label}: sample {worst} is {got[worst]!r}, expected {want[worst]!r} (tolerance {tol})"
        )


def check_annotations(fail, who, got, job, duration):
    if "annotations" not in job:
        return
    want = [(round(o, 6), t) for o, t in job.get("annotations", []) if o < duration]
    have = [(round(float(o), 6), str(t)) for o, t in got if str(t) != ""]
    if job.get("killed"):
        have = [a for a in have if a[0] < duration]
    if have != want:
        fail.append(f"{who} annotations {have[:6]}... != expected {want[:6]}...")


def read_pyedflib(path, job, fail, info):
    r = pyedflib.EdfReader(path)
    try:
        labels = [l.strip() for l in r.getSignalLabels()]
        if labels != job["labels"]:
            fail.append(f"pyedflib labels {labels} != {job['labels']}")
        rates = list(r.getSampleFrequencies())
        if not np.allclose(rates, job["rates"], rtol=1e-6):
            fail.append(f"pyedflib rates {rates} != {job['rates']}")
        for k, label in enumerate(labels):
            if label in job.get("digital", {}):
                compare(fail, "pyedflib", label, r.readSignal(k, digital=True), job["digital"][label], 0)
            if label in job.get("physical", {}):
                step = steps((r.getPhysicalMinimum(k), r.getPhysicalMaximum(k), r.getDigitalMinimum(k), r.getDigitalMaximum(k)))
                compare(fail, "pyedflib", label, r.readSignal(k), job["physical"][label], step * 1.0001)
        onsets, _, texts = r.readAnnotations()
        check_annotations(fail, "pyedflib", list(zip(onsets, texts)), job, info["duration"])
        info["pyedflib_records"] = r.datarecords_in_file
    finally:
        r.close()


def read_edfio(path, job, fail, info):
    e = edfio.read_bdf(path) if path.lower().endswith(".bdf") else edfio.read_edf(path)
    labels = [s.label for s in e.signals]
    if labels != job["labels"]:
        fail.append(f"edfio labels {labels} != {job['labels']}")
    rates = [s.sampling_frequency for s in e.signals]
    if not np.allclose(rates, job["rates"], rtol=1e-6):
        fail.append(f"edfio rates {rates} != {job['rates']}")
    for s in e.signals:
        if s.label in job.get("digital", {}):
            compare(fail, "edfio", s.label, s.digital, job["digital"][s.label], 0)
        if s.label in job.get("physical", {}):
            step = steps((s.physical_min, s.physical_max, s.digital_min, s.digital_max))
            compare(fail, "edfio", s.label, s.data, job["physical"][s.label], step * 1.0001)
    start = dt.datetime.combine(e.startdate, e.starttime).replace(tzinfo=dt.timezone.utc)
    info["start"] = start.timestamp()
    info["records"] = e.num_data_records
    info["duration"] = e.num_data_records * e.data_record_duration
    check_annotations(fail, "edfio", [(a.onset, a.text) for a in e.annotations], job, info["duration"])


def read_mne(path, job, fail, info):
    reader = mne.io.read_raw_bdf if path.lower().endswith(".bdf") else mne.io.read_raw_edf
    raw = reader(path, preload=True, verbose="error")
    if raw.ch_names != job["labels"]:
        fail.append(f"mne labels {raw.ch_names} != {job['labels']}")
    top = max(job["rates"])
    if abs(raw.info["sfreq"] - top) > 1e-6 * top:
        fail.append(f"mne sfreq {raw.info['sfreq']} != {top}")
    if abs(raw.n_times / raw.info["sfreq"] - info["duration"]) > 1e-6:
        fail.append(f"mne holds {raw.n_times / raw.info['sfreq']} s, edfio {info['duration']} s")
    extras = raw._raw_extras[0]
    for k, label in enumerate(raw.ch_names):
        # MNE resamples slower signals to the fastest rate: compare values of the fastest only.
        if label in job.get("physical", {}) and job["rates"][k] == top:
            unit = UNIT.get(job.get("dimension", "uV"), 1.0)
            got = raw.get_data(picks=[k])[0] / unit
            lo, hi = extras["physical_min"][k], extras["physical_max"][k]
            dlo, dhi = extras["digital_min"][k], extras["digital_max"][k]
            compare(fail, "mne", label, got, job["physical"][label], steps((lo, hi, dlo, dhi)) * 1.0001)
    annots = [(o, d) for o, d in zip(raw.annotations.onset, raw.annotations.description)]
    check_annotations(fail, "mne", annots, job, info["duration"])


def main():
    job = json.load(open(sys.argv[1]))
    out = []
    for path in job["files"]:
        fail = []
        info = {"path": path, "duration": float("inf")}
        for name, fn in (("edfio", read_edfio), ("pyedflib", read_pyedflib), ("mne", read_mne)):
            try:
                fn(path, job, fail, info)
            except Exception as e:  # noqa: BLE001 - every reader's refusal is a finding
                fail.append(f"{name} cannot read {path}: {type(e).__name__}: {e}")
        info["failures"] = fail
        out.append(info)
    print(json.dumps({"files": out}))


if __name__ == "__main__":
    main()
