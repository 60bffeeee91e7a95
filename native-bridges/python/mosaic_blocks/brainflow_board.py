"""BrainFlow: one acquisition board read through BrainFlow's BoardShim (or Mindrove's fork of it,
the `mindrove` package), for the BrainFlow block (app/blocks/devices/brainflow.ts).

The sidecar calls `poll(x, state)` for every input the block sends; x is [1, 1] and its value is
a command:

  0  describe: nothing happens (the sidecar's probe call at load sends zeros); row 1 of the
     result holds the number of channels of each selected kind
  1  poll: the board is started on the first poll (in a thread of its own); the samples it
     delivered since the last poll are returned, at most `max_rows`, the rest on the next poll
  2  stop: the stream is stopped and the session released (the pipeline stopped)

The result is [1 + max_rows, width]: row 0 is a header (HEADER below), rows 1 … n the samples of
the selected channels (width ≥ channels; extra columns are 0). Every sample the board delivered
goes out exactly once: a reader thread takes everything BrainFlow holds (get_board_data, which
removes what it returns from BrainFlow's ring buffer) into a queue, and each poll takes from the
queue's head. Lost samples are the gaps in the board's package-number channel.

A failure (prepare_session or start_stream raising, or no data for `silence` s while streaming)
releases the session and tries again after 0.5 s, 1 s, 2 s, 4 s, then every 5 s. A failure is
raised once to the block, by the first poll that has no samples left to return, as a RuntimeError
with a message that says what to check; later attempts failing the same way are only counted.

Params (JSON from the block): board (name or number), library (brainflow | mindrove | auto),
input (BrainFlowInputParams fields), master_board (for the playback and streaming boards),
channels (kinds: exg, emg, eeg, ecg, eog, accel, gyro, magnetometer, package, timestamp),
poll_rate (Hz: the result holds up to 4 polls' samples, at least 32; or max_rows), silence (s;
0: never), buffer (BrainFlow's ring buffer, samples), simulated (BrainFlow's synthetic board in
the board's layout and rate: Resampler), log_level (BrainFlow's logger: 0 trace … 6 off), retry
(a fixed wait between attempts, s, instead of the backoff; tests).

A state of "waiting" (the session started, no data yet) becomes "streaming" with the first data;
data after a failure counts as a reconnection.
"""

from __future__ import annotations

import atexit
import collections
import difflib
import importlib
import importlib.resources
import math
import os
import threading
import time
from typing import Any

import numpy as np

# Header row: [samples in this result, state, lost samples so far, reconnections, failed attempts,
# sampling rate, channels, samples so far]. The block reads it by these indices.
HEADER = 8
H_N, H_STATE, H_LOST, H_RECONNECTS, H_FAILURES, H_RATE, H_CHANNELS, H_TOTAL = range(HEADER)

# States (H_STATE).
IDLE, CONNECTING, STREAMING, RETRYING, ENDED, STOPPED, WAITING = range(7)

CMD_DESCRIBE, CMD_POLL, CMD_STOP = 0, 1, 2

KINDS = {
    "exg": "get_exg_channels",
    "emg": "get_emg_channels",
    "eeg": "get_eeg_channels",
    "ecg": "get_ecg_channels",
    "eog": "get_eog_channels",
    "accel": "get_accel_channels",
    "gyro": "get_gyro_channels",
    "magnetometer": "get_magnetometer_channels",
    "package": "get_package_num_channel",
    "timestamp": "get_timestamp_channel",
}

INPUT_FIELDS = (
    "serial_port",
    "mac_address",
    "ip_address",
    "ip_address_aux",
    "ip_address_anc",
    "ip_port",
    "ip_port_aux",
    "ip_port_anc",
    "ip_protocol",
    "other_info",
    "timeout",
    "serial_number",
    "file",
    "file_aux",
    "file_anc",
)

RETRY_FIRST, RETRY_MAX = 0.5, 5.0
READ_EVERY = 0.01


def _package_files(name: str):
    """importlib.resources.files for a module name too (Python 3.11 accepts only packages)."""
    try:
        return importlib.resources.files(name)
    except TypeError:
        return importlib.resources.files(name.rpartition(".")[0])


def library(name: str):
    """(board_shim module, its input-params class) of `brainflow` or `mindrove`.

    brainflow 5.23.0 finds its native library with importlib.resources.files(__name__), which
    Python 3.11 refuses for a module (it then needs setuptools' pkg_resources, not installed
    here): its `files` is given one that takes the module's package.
    """
    shim = importlib.import_module(f"{name}.board_shim")
    if name == "brainflow":
        shim.files = _package_files
        importlib.import_module("brainflow.data_filter").files = _package_files
        params_class = shim.BrainFlowInputParams
    else:
        params_class = shim.MindRoveInputParams
    return shim, params_class


def library_of(board: Any, requested: str) -> str:
    if requested in ("brainflow", "mindrove"):
        return requested
    return "mindrove" if str(board).upper().startswith("MINDROVE") else "brainflow"


def board_id(shim: Any, board: Any, lib: str, what: str = "board") -> int:
    """The board id of a number or a name (case-insensitive, with or without _BOARD, or the one
    name it begins)."""
    ids = {m.name: int(m) for m in shim.BoardIds}
    if isinstance(board, (int, float)) or str(board).lstrip("-").isdigit():
        number = int(board)
        if number in ids.values():
            return number
        known = ", ".join(f"{n} ({v})" for n, v in sorted(ids.items(), key=lambda kv: kv[1]))
        raise ValueError(f"{lib} has no {what} number {number}; its boards: {known}")
    key = str(board).strip().upper().replace("-", "_").replace(" ", "_")
    for candidate in (key, f"{key}_BOARD"):
        if candidate in ids:
            return ids[candidate]
    starting = [n for n in ids if n.startswith(f"{key}_")]
    if len(starting) == 1:  # "playback" for PLAYBACK_FILE_BOARD
        return ids[starting[0]]
    close = difflib.get_close_matches(key, list(ids), n=3, cutoff=0.5)
    close += [n for n in ids if key in n and n not in close][:3]
    if close:
        raise ValueError(f"{lib} has no {what} named '{board}'; did you mean {' or '.join(close[:3])}?")
    raise ValueError(f"{lib} has no {what} named '{board}' (its boards: {', '.join(ids)})")


def layout(shim: Any, bid: int, kinds: list[str]) -> dict:
    """Rows of the selected channels, sampling rate, package-number row of board `bid`."""
    BoardShim = shim.BoardShim
    rows: list[int] = []
    names: list[str] = []
    counts: list[int] = []
    column_kinds: list[str] = []
    for kind in kinds:
        if kind not in KINDS:
            raise ValueError(f"unknown channel kind '{kind}' (kinds: {', '.join(KINDS)})")
        try:
            found = np.atleast_1d(getattr(BoardShim, KINDS[kind])(bid)).astype(int).tolist()
        except Exception:  # BrainFlowError: the board has none of this kind
            found = []
        if not found:
            raise ValueError(f"the board has no {kind} channels")
        rows += found
        counts.append(len(found))
        column_kinds += [kind] * len(found)
        names += [f"{kind} {i + 1}" for i in range(len(found))]
    try:
        package = int(BoardShim.get_package_num_channel(bid))
    except Exception:
        package = -1
    return {
        "rows": rows,
        "names": names,
        "counts": counts,
        "kinds": column_kinds,
        "rate": float(BoardShim.get_sampling_rate(bid)),
        "package": package,
    }


def input_params(params_class: Any, given: dict, master: int | None) -> Any:
    p = params_class()
    for key, value in (given or {}).items():
        if key not in INPUT_FIELDS:
            raise ValueError(f"unknown BrainFlowInputParams field '{key}' (fields: {', '.join(INPUT_FIELDS)})")
        setattr(p, key, type(getattr(p, key))(value))
    if master is not None:
        p.master_board = master
    return p


def explain(e: Exception, target: str) -> str:
    """A failure in words: what BrainFlow said and what to check."""
    code = getattr(e, "exit_code", None)
    name = str(e).split(":")[0] if code is not None else type(e).__name__
    hints = {
        "UNABLE_TO_OPEN_PORT_ERROR": "the port cannot be opened: check the serial port's name, that it exists and that no other program (the vendor's GUI) holds it",
        "BOARD_NOT_READY_ERROR": "the board does not answer: is it on, charged and in range?",
        "BOARD_NOT_CREATED_ERROR": "the session was not prepared",
        "ANOTHER_BOARD_IS_CREATED_ERROR": "another session with these params is open (another block or program?)",
        "INVALID_ARGUMENTS_ERROR": "BrainFlow refused the params (a missing serial port, address or file?)",
        "GENERAL_ERROR": "BrainFlow reported a general error (its log line above says more)",
        "SYNC_TIMEOUT_ERROR": "the board did not answer in time",
        "UNSUPPORTED_BOARD_ERROR": "this BrainFlow build does not support the board on this system",
        "EMPTY_BUFFER_ERROR": "the board sent nothing",
    }
    hint = hints.get(name, "")
    text = f"{target}: {e}"
    return f"{text} ({hint})" if hint else text


# BrainFlow's synthetic board (brainflow 5.23.0, BoardShim.get_board_descr(SYNTHETIC_BOARD)).
SYNTHETIC = -1
SYNTHETIC_RATE = 250.0
SYNTHETIC_PACKAGE = 0
SYNTHETIC_ROWS = {
    "exg": list(range(1, 17)),
    "accel": [17, 18, 19],
    "gyro": [20, 21, 22],
    "timestamp": [30],
}
# Kinds the synthetic board has no rows of take these (magnetometer: the accelerometer's).
SYNTHETIC_STANDS_IN = {"emg": "exg", "eeg": "exg", "ecg": "exg", "eog": "exg", "magnetometer": "accel"}


class Resampler:
    """BrainFlow's synthetic board in another board's layout (`simulated`): each output column
    takes a synthetic row of its kind (cycling through them: the 16 EXG rows, accel, gyro), the
    package column counts 0…255, and the samples are linearly interpolated from the synthetic
    board's 250 Hz to the board's rate."""

    def __init__(self, board_layout: dict):
        rows: list[int] = []
        seen: dict[str, int] = {}
        self.package_columns: list[int] = []
        for col, kind in enumerate(board_layout["kinds"]):
            if kind == "package":
                self.package_columns.append(col)
                rows.append(SYNTHETIC_PACKAGE)
                continue
            source = SYNTHETIC_ROWS[SYNTHETIC_STANDS_IN.get(kind, kind)]
            k = seen.get(kind, 0)
            seen[kind] = k + 1
            rows.append(source[k % len(source)])
        self.rows = rows
        self.step = SYNTHETIC_RATE / float(board_layout["rate"])  # synthetic samples per output
        self.restart()

    def restart(self) -> None:
        self.prev: np.ndarray | None = None
        self.pos = 0.0  # the next output's position, in synthetic samples after `prev`
        self.counter = 0

    def convert(self, data: np.ndarray) -> np.ndarray:
        """[output samples, columns] from a chunk of synthetic data [rows, samples]."""
        x = data[self.rows].T
        seq = x if self.prev is None else np.vstack((self.prev, x))
        last = seq.shape[0] - 1
        at = np.arange(self.pos, last + 1e-9, self.step) if last >= 0 else np.empty(0)
        i0 = np.floor(at).astype(int)
        i1 = np.minimum(i0 + 1, last)
        frac = (at - i0)[:, np.newaxis]
        out = seq[i0] * (1.0 - frac) + seq[i1] * frac
        n = out.shape[0]
        for col in self.package_columns:
            out[:, col] = (self.counter + np.arange(n)) % 256
        self.counter = (self.counter + n) % 256
        self.pos = (at[-1] + self.step if n else self.pos) - last
        self.prev = seq[-1:].copy()
        return np.ascontiguousarray(out)


class Reader:
    """The board's session, run by a thread: prepare, stream, read, retry."""

    def __init__(self, params: dict):
        board = params.get("board", "SYNTHETIC_BOARD")
        self.lib = library_of(board, str(params.get("library", "auto")))
        self.shim, params_class = library(self.lib)
        self.board = board_id(self.shim, board, self.lib)
        master = params.get("master_board")
        self.master = board_id(self.shim, master, self.lib, "master board") if master not in (None, "") else None
        playback = self.board in (int(self.shim.BoardIds.PLAYBACK_FILE_BOARD), int(self.shim.BoardIds.STREAMING_BOARD))
        if playback and self.master is None:
            raise ValueError(
                "the playback and streaming boards need a master board (the board that recorded the data)"
            )
        self.playback = self.board == int(self.shim.BoardIds.PLAYBACK_FILE_BOARD)
        described = self.master if playback else self.board
        kinds = [str(k) for k in (params.get("channels") or ["exg"])]
        self.layout = layout(self.shim, described, kinds)
        self.inputs = input_params(params_class, params.get("input") or {}, self.master)
        if self.playback and not os.path.isfile(self.inputs.file):
            given = self.inputs.file
            raise ValueError(f"the playback file {given} does not exist" if given else "the playback board needs a playback file")
        self.simulated: Resampler | None = None
        if params.get("simulated"):
            self.simulated = Resampler(self.layout)
        poll_rate = float(params.get("poll_rate", 50))
        self.max_rows = int(params.get("max_rows") or max(32, math.ceil(4 * self.layout["rate"] / poll_rate)))
        self.width = max(HEADER, len(self.layout["rows"]))
        self.silence = float(params.get("silence", 3.0))
        self.buffer = int(params.get("buffer", 450000))
        self.retry_fixed = float(params.get("retry", 0) or 0)
        self.log_level = int(params.get("log_level", 6))
        where = next(
            (str(v) for k in ("serial_port", "ip_address", "mac_address", "file") if (v := getattr(self.inputs, k, ""))),
            "",
        )
        self.target = f"{self.lib} board {board}" + (f" on {where}" if where else "")
        if self.simulated:
            self.target = f"BrainFlow's synthetic board as {self.lib} board {board}"
        self.queue: collections.deque[np.ndarray] = collections.deque()
        self.lock = threading.Lock()
        self.state = IDLE
        self.lost = 0
        self.total = 0
        self.reconnects = 0
        self.failures = 0
        self.failure: str | None = None
        self.failure_new = False
        self.ever = False
        self.last_package: float | None = None
        self.package_min: float | None = None
        self.package_max: float | None = None
        self.stopping = threading.Event()
        self.thread: threading.Thread | None = None
        self.shim.BoardShim.set_log_level(self.log_level)

    # The thread ------------------------------------------------------------------------------

    def start(self) -> None:
        global _active
        if self.thread is not None and self.thread.is_alive():
            return  # running, or a stopped session still ending (a later poll starts anew)
        if _active is not None and _active is not self:
            _active.stop()  # a reset made a new state: one session per sidecar
        _active = self
        self.stopping.clear()
        self.thread = threading.Thread(target=self.run, name="mosaic-brainflow", daemon=True)
        self.thread.start()

    def stop(self) -> None:
        self.stopping.set()
        if self.thread is not None:
            self.thread.join(timeout=5)  # a board inside prepare_session may take longer
            if not self.thread.is_alive():
                self.thread = None
        self.state = STOPPED
        with self.lock:  # a later start begins a new stream
            self.queue.clear()
        if self.simulated:
            self.simulated.restart()
        self.last_package = None

    def run(self) -> None:
        while not self.stopping.is_set():
            self.state = CONNECTING
            shim = self.open_board()
            try:
                shim.prepare_session()
                shim.start_stream(self.buffer)
            except Exception as e:
                self.release(shim)
                self.fail(explain(e, self.target))
                continue
            self.state = WAITING
            reason = self.stream(shim)
            self.release(shim)
            if reason == "ended":
                self.state = ENDED
                self.stopping.wait()
            elif reason:
                self.fail(f"{self.target}: {reason}")

    def open_board(self) -> Any:
        """The board's BoardShim, or BrainFlow's synthetic board when simulated."""
        if self.simulated:
            shim, params_class = library("brainflow")
            shim.BoardShim.set_log_level(self.log_level)
            return shim.BoardShim(SYNTHETIC, params_class())
        return self.shim.BoardShim(self.board, self.inputs)

    def stream(self, shim: Any) -> str | None:
        """Reads until stopped (None), the data stops (a reason) or a playback file ends."""
        last_data = time.monotonic()
        got = False
        while not self.stopping.wait(READ_EVERY):
            try:
                data = shim.get_board_data()
            except Exception as e:
                return f"reading failed: {e}"
            now = time.monotonic()
            if data.shape[1] > 0:
                if not got:
                    self.began()
                    got = True
                last_data = now
                self.take(data)
            elif self.silence > 0 and now - last_data > self.silence:
                if self.playback and got:
                    return "ended"
                if got:
                    return f"no data for {self.silence:g} s"
                return (
                    f"the session started but no data came in {self.silence:g} s "
                    "(is the board on, in range, and this computer on its network or dongle?)"
                )
        return None

    def began(self) -> None:
        """The first data of a session: streaming (again, after a failure: a reconnection)."""
        if self.ever:
            self.reconnects += 1
        self.ever = True
        self.failures = 0
        self.state = STREAMING

    def take(self, data: np.ndarray) -> None:
        if self.simulated:
            self.count_gaps(data[SYNTHETIC_PACKAGE])
            chunk = self.simulated.convert(data)
            if chunk.shape[0] == 0:
                return
        else:
            package = self.layout["package"]
            if package >= 0:
                self.count_gaps(data[package])
            chunk = np.ascontiguousarray(data[self.layout["rows"]].T)
        with self.lock:
            self.queue.append(chunk)
            self.total += chunk.shape[0]

    def count_gaps(self, numbers: np.ndarray) -> None:
        """Samples missing between consecutive package numbers (the counter wraps to its minimum)."""
        if numbers.size == 0:
            return
        lo, hi = float(numbers.min()), float(numbers.max())
        self.package_min = lo if self.package_min is None else min(self.package_min, lo)
        self.package_max = hi if self.package_max is None else max(self.package_max, hi)
        seq = numbers if self.last_package is None else np.concatenate(([self.last_package], numbers))
        d = np.diff(seq)
        ahead = d[d > 1]
        lost = int(np.sum(ahead - 1))
        for k in np.nonzero(d <= 0)[0]:
            # A wrap: from the value before it up to the largest seen, and from the smallest to it.
            lost += int((self.package_max - seq[k]) + (seq[k + 1] - self.package_min))
        self.lost += lost
        self.last_package = float(numbers[-1])

    def release(self, shim: Any) -> None:
        try:
            if shim.is_prepared():
                try:
                    shim.stop_stream()
                except Exception:
                    pass
                shim.release_session()
        except Exception:
            pass

    def fail(self, message: str) -> None:
        self.failures += 1
        self.state = RETRYING
        if message != self.failure:
            self.failure = message
            self.failure_new = True
        self.last_package = None
        wait = self.retry_fixed or min(RETRY_MAX, RETRY_FIRST * 2 ** (self.failures - 1))
        self.stopping.wait(wait)

    # The calls -------------------------------------------------------------------------------

    def result(self, take: bool) -> np.ndarray:
        out = np.zeros((1 + self.max_rows, self.width))
        n = 0
        if take:
            with self.lock:
                while self.queue and n < self.max_rows:
                    chunk = self.queue[0]
                    k = min(chunk.shape[0], self.max_rows - n)
                    out[1 + n : 1 + n + k, : chunk.shape[1]] = chunk[:k]
                    n += k
                    if k == chunk.shape[0]:
                        self.queue.popleft()
                    else:
                        self.queue[0] = chunk[k:]
        h = out[0]
        h[H_N] = n
        h[H_STATE] = self.state
        h[H_LOST] = self.lost
        h[H_RECONNECTS] = self.reconnects
        h[H_FAILURES] = self.failures
        h[H_RATE] = self.layout["rate"]
        h[H_CHANNELS] = len(self.layout["rows"])
        h[H_TOTAL] = self.total
        return out

    def poll(self, command: int) -> np.ndarray:
        if command == CMD_POLL:
            self.start()
            out = self.result(True)
            if out[0, H_N] == 0 and self.failure_new:
                self.failure_new = False
                raise RuntimeError(self.failure)
            return out
        if command == CMD_STOP:
            self.stop()
            return self.result(False)
        out = self.result(False)
        counts = self.layout["counts"]
        out[1, : len(counts)] = counts  # describe: the channels of each selected kind
        return out


_active: Reader | None = None


@atexit.register
def _release_at_exit() -> None:
    if _active is not None:
        _active.stop()


def init(params: dict) -> Reader:
    return Reader(params)


def poll(x: np.ndarray, state: Reader) -> np.ndarray:
    return state.poll(int(np.asarray(x).reshape(-1)[0]))


def channel_names(params: dict) -> list[str]:
    """The names of the selected channels (for tests and tools)."""
    return Reader(params).layout["names"]
