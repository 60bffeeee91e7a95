"""mosaic_blocks.brainflow_board (the BrainFlow block's module), called as the sidecar calls it,
on BrainFlow's own synthetic and playback boards (real BrainFlow sessions; no device needed), a
serial port that does not exist and a silent Cyton on a socat pty pair."""

from __future__ import annotations

import collections
import os
import shutil
import subprocess
import time

import numpy as np
import pytest

from mosaic_blocks import brainflow_board as B

POLL = np.ones((1, 1))
STOP = np.full((1, 1), 2.0)
DESCRIBE = np.zeros((1, 1))


def drain(state: B.Reader, seconds: float, until=None) -> tuple[np.ndarray, np.ndarray]:
    """Polls every 20 ms for `seconds` (or until `until(header)`): (samples, last header)."""
    rows, header = [], None
    t0 = time.monotonic()
    while time.monotonic() - t0 < seconds:
        r = B.poll(POLL, state)
        header = r[0]
        n = int(header[B.H_N])
        rows.append(r[1 : 1 + n, : int(header[B.H_CHANNELS])].copy())
        if until is not None and until(header):
            break
        time.sleep(0.02)
    return np.concatenate(rows), header


def test_board_names_numbers_and_did_you_mean():
    shim, _ = B.library("brainflow")
    assert B.board_id(shim, "SYNTHETIC_BOARD", "brainflow") == -1
    assert B.board_id(shim, "synthetic", "brainflow") == -1
    assert B.board_id(shim, "playback", "brainflow") == -3
    assert B.board_id(shim, -1, "brainflow") == -1
    assert B.board_id(shim, "16", "brainflow") == 16  # GFORCE_PRO_BOARD
    with pytest.raises(ValueError, match=r"no board named 'cyton_dasy'; did you mean CYTON_DAISY_BOARD"):
        B.board_id(shim, "cyton_dasy", "brainflow")
    with pytest.raises(ValueError, match=r"no board number 12345"):
        B.board_id(shim, 12345, "brainflow")
    # Mindrove's fork has its own ids: a MINDROVE name picks it.
    assert B.library_of("MINDROVE_WIFI_BOARD", "auto") == "mindrove"
    mshim, _ = B.library("mindrove")
    assert B.board_id(mshim, "mindrove_wifi", "mindrove") == int(mshim.BoardIds.MINDROVE_WIFI_BOARD)


def test_layout_and_describe():
    state = B.init({"board": "synthetic", "channels": ["exg", "accel", "package"], "poll_rate": 50})
    r = B.poll(DESCRIBE, state)
    # 16 EXG + 3 accel + the package number, at 250 Hz; up to 4 polls of samples (at least 32).
    assert r.shape == (1 + 32, 20)
    assert r[0, B.H_RATE] == 250 and r[0, B.H_CHANNELS] == 20 and r[0, B.H_N] == 0
    assert list(r[1, :3]) == [16, 3, 1]
    assert state.thread is None  # describing opens nothing
    with pytest.raises(ValueError, match="no gyro channels"):
        B.init({"board": "cyton", "channels": ["gyro"]})
    with pytest.raises(ValueError, match="need a master board"):
        B.init({"board": "playback", "input": {"file": "x.csv"}})
    with pytest.raises(ValueError, match="playback file .* does not exist"):
        B.init({"board": "playback", "master_board": "synthetic", "input": {"file": "/nonexistent.csv"}})


def test_synthetic_every_sample_once_at_its_rate():
    state = B.init({"board": "synthetic", "channels": ["exg", "package"], "max_rows": 8})
    try:
        t0 = time.monotonic()
        data, header = drain(state, 2.0)
        elapsed = time.monotonic() - t0
    finally:
        B.poll(STOP, state)
    package = data[:, -1]
    # Consecutive package numbers (0…255, wrapping): nothing lost, nothing repeated, even though a
    # poll returns at most 8 rows and the rest waits for the next.
    assert np.all(np.diff(package) % 256 == 1)
    assert header[B.H_LOST] == 0 and header[B.H_STATE] == B.STREAMING
    # Its rate: 250 Hz over the time polled (the board starts on the first poll).
    assert 250 * (elapsed - 0.6) < len(data) <= 250 * elapsed + 10


def test_playback_gives_the_file_exactly(tmp_path):
    shim, params_class = B.library("brainflow")
    from brainflow.data_filter import DataFilter

    board = shim.BoardShim(int(shim.BoardIds.SYNTHETIC_BOARD), params_class())
    board.prepare_session()
    board.start_stream()
    time.sleep(1.0)
    recorded = board.get_board_data()
    board.stop_stream()
    board.release_session()
    path = str(tmp_path / "rec.csv")
    DataFilter.write_file(recorded, path, "w")
    expected = DataFilter.read_file(path)  # what the file holds (written with 6 decimals)
    state = B.init(
        {
            "board": "playback",
            "master_board": "synthetic",
            "input": {"file": path},
            "channels": ["exg", "package"],
            "silence": 0.5,
        }
    )
    try:
        data, header = drain(state, 10.0, until=lambda h: h[B.H_STATE] == B.ENDED)
    finally:
        B.poll(STOP, state)
    assert header[B.H_STATE] == B.ENDED
    rows = B.layout(shim, -1, ["exg", "package"])["rows"]
    assert np.array_equal(data, expected[rows].T)


def test_wrong_serial_port_is_a_clear_error_once_and_retried():
    state = B.init({"board": "cyton", "input": {"serial_port": "/dev/ttyMOSAIC_NONE"}, "retry": 0.05})
    raised = []
    try:
        t0 = time.monotonic()
        header = None
        while time.monotonic() - t0 < 1.5:
            try:
                header = B.poll(POLL, state)[0]
            except RuntimeError as e:
                raised.append(str(e))
            time.sleep(0.02)
    finally:
        B.poll(STOP, state)
    assert len(raised) == 1
    assert "UNABLE_TO_OPEN_PORT_ERROR" in raised[0] and "serial port" in raised[0]
    assert header is not None and header[B.H_FAILURES] >= 3


def test_gaps_in_package_numbers():
    state = B.init({"board": "synthetic"})
    state.count_gaps(np.array([0.0, 1, 2, 5, 6]))  # 3, 4 missing
    assert state.lost == 2
    state.count_gaps(np.array([7.0, 9]))  # 8 missing, across calls
    assert state.lost == 3
    state.count_gaps(np.array([255.0, 0, 1]))  # 10…254 missing, then a wrap without loss
    assert state.lost == 3 + 245


def test_stop_then_poll_starts_a_new_stream():
    state = B.init({"board": "synthetic", "channels": ["package"]})
    try:
        first, _ = drain(state, 0.5)
        B.poll(STOP, state)
        assert state.thread is None and state.queue == collections.deque()
        again, header = drain(state, 1.0, until=lambda h: h[B.H_N] > 0)
    finally:
        B.poll(STOP, state)
    assert len(first) > 0 and len(again) > 0 and header[B.H_STATE] == B.STREAMING


def test_resampler_interpolates_the_synthetic_board_into_another_layout():
    # A layout of 2 EMG channels, accel x and the package number at 500 Hz (twice the synthetic's
    # 250): each output column takes its kind's synthetic row, the package column counts.
    r = B.Resampler({"kinds": ["emg", "emg", "accel", "package"], "rate": 500.0})
    assert r.rows == [1, 2, 17, 0]
    data = np.zeros((32, 6))
    data[1] = [0, 2, 4, 6, 8, 10]
    data[2] = 100 + data[1]
    data[17] = [0, 1, 0, 1, 0, 1]
    chunks = [r.convert(data[:, :2]), r.convert(data[:, 2:5]), r.convert(data[:, 5:])]
    out = np.concatenate(chunks)
    # 6 synthetic samples span 5 intervals: 11 output samples at twice the rate, whatever the chunks.
    assert out.shape == (11, 4)
    assert np.array_equal(out[:, 0], np.arange(11.0))
    assert np.array_equal(out[:, 1], 100 + np.arange(11.0))
    assert np.array_equal(out[:, 2], [0, 0.5, 1, 0.5, 0, 0.5, 1, 0.5, 0, 0.5, 1])
    assert np.array_equal(out[:, 3], np.arange(11.0))
    # Down to 125 Hz: every other synthetic sample.
    down = B.Resampler({"kinds": ["exg"], "rate": 125.0})
    assert np.array_equal(np.concatenate([down.convert(data[:, :3]), down.convert(data[:, 3:])])[:, 0], [0, 4, 8])


def test_simulated_mindrove_has_its_shape_and_rate():
    state = B.init({"board": "MINDROVE_WIFI_BOARD", "channels": ["exg", "package", "timestamp"], "simulated": True})
    described = B.poll(DESCRIBE, state)[0]
    assert described[B.H_RATE] == 500 and described[B.H_CHANNELS] == 10
    try:
        data, header = drain(state, 1.5)
    finally:
        B.poll(STOP, state)
    assert np.all(np.diff(data[:, 8]) % 256 == 1)
    # Twice the synthetic board's rate by its own arrival stamps (interpolated with the samples):
    # 500 Hz, less what the synthetic board loses to its sleep per sample on a loaded machine.
    ts = data[:, 9]
    assert 0.8 * 500 < (len(data) - 1) / (ts[-1] - ts[0]) < 500 * 1.01
    assert header[B.H_LOST] == 0


@pytest.mark.skipif(shutil.which("socat") is None, reason="needs socat for a pty pair")
def test_a_silent_board_on_a_real_pty_is_a_clear_error(tmp_path):
    # A Cyton on one end of a socat pty pair whose other end never answers.
    port = str(tmp_path / "cyton")
    socat = subprocess.Popen(
        ["socat", f"pty,raw,echo=0,link={port}", f"pty,raw,echo=0,link={tmp_path / 'peer'}"],
        stderr=subprocess.DEVNULL,
    )
    try:
        t0 = time.monotonic()
        while not os.path.exists(port) and time.monotonic() - t0 < 5:
            time.sleep(0.02)
        state = B.init({"board": "cyton", "input": {"serial_port": port}, "retry": 60})
        raised = None
        try:
            while raised is None and time.monotonic() - t0 < 30:
                try:
                    B.poll(POLL, state)
                except RuntimeError as e:
                    raised = str(e)
                time.sleep(0.05)
        finally:
            state.stopping.set()  # its retry wait ends at once; the thread is a daemon
    finally:
        socat.terminate()
        socat.wait()
    assert raised is not None
    assert f"brainflow board cyton on {port}: BOARD_NOT_READY_ERROR" in raised
    assert "the board does not answer" in raised
