"""The sidecar's life and limits: it never outlives its host, ignores a terminal's Ctrl-C, runs
niced, and its memory is capped (RLIMIT_DATA) with a MemoryError reported as such."""

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from mosaic_sidecar import protocol as P

PACKAGE_ROOT = Path(__file__).resolve().parent.parent
T = P.MessageType


def write(path, text):
    path.write_text(textwrap.dedent(text))
    return path


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie (dead, not reaped) still answers kill(0).
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def wait_gone(pid: int, seconds: float) -> bool:
    t0 = time.monotonic()
    while time.monotonic() - t0 < seconds:
        if not alive(pid):
            return True
        time.sleep(0.02)
    return not alive(pid)


HANG = """
import time
def init(params):
    return {"n": 0}
def f(x, state):
    state["n"] += 1
    if state["n"] >= 2:
        time.sleep(1e6)
    return x
"""


def start_hanging_call(sidecar, tmp_path):
    write(tmp_path / "hang.py", HANG)
    kind, _ = sidecar.load(module="hang.py", function="f", init="init", input_shape=[1, 1])
    assert kind == T.OK
    assert sidecar.call(np.zeros((1, 1)))[0] == T.RESULT
    sidecar.proc.stdin.write(P.message(T.CALL, 99, P.encode_array(np.zeros((1, 1)))))
    sidecar.proc.stdin.flush()
    time.sleep(0.3)  # in time.sleep(1e6) now
    assert sidecar.proc.poll() is None


def test_end_of_stdin_ends_a_process_stuck_in_a_call(sidecar, tmp_path):
    start_hanging_call(sidecar, tmp_path)
    t0 = time.monotonic()
    sidecar.proc.stdin.close()  # the host went away (or asked it to stop)
    assert sidecar.proc.wait(5) == 0
    assert time.monotonic() - t0 < 2


def test_shutdown_then_end_ends_a_process_stuck_in_a_busy_loop(sidecar, tmp_path):
    write(
        tmp_path / "spin.py",
        """
        def init(params):
            return {"n": 0}
        def f(x, state):
            state["n"] += 1
            while state["n"] >= 2:
                pass
            return x
        """,
    )
    assert sidecar.load(module="spin.py", function="f", init="init", input_shape=[1, 1])[0] == T.OK
    assert sidecar.call(np.zeros((1, 1)))[0] == T.RESULT
    sidecar.proc.stdin.write(P.message(T.CALL, 99, P.encode_array(np.zeros((1, 1)))))
    sidecar.proc.stdin.flush()
    time.sleep(0.3)
    assert sidecar.close() == 0


def test_sigint_is_ignored(sidecar, tmp_path):
    write(tmp_path / "ident.py", "def f(x):\n    return x\n")
    assert sidecar.load(module="ident.py", function="f", input_shape=[1, 2])[0] == T.OK
    sidecar.proc.send_signal(signal.SIGINT)
    time.sleep(0.2)
    kind, _, y = sidecar.call(np.array([[1.0, 2.0]]))
    assert kind == T.RESULT and y.tolist() == [[1.0, 2.0]]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux's")
def test_killed_with_its_parent_even_while_stdin_stays_open(tmp_path):
    """The second line: SIGKILL of the parent kills the sidecar (here stdin stays open)."""
    write(tmp_path / "hang.py", HANG)
    env = dict(os.environ)
    env["PYTHONPATH"] = str(PACKAGE_ROOT)
    # A parent that starts the sidecar on our pipes, reports its pid, and waits.
    parent = subprocess.Popen(
        [
            sys.executable,
            "-c",
            textwrap.dedent(
                """
                import subprocess, sys, time
                p = subprocess.Popen([sys.executable, "-m", "mosaic_sidecar"])
                print(p.pid, flush=True, file=sys.stderr)
                time.sleep(1e6)
                """
            ),
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=tmp_path,
        env=env,
    )
    child = int(parent.stderr.readline())
    parent.stdin.write(P.message(T.HELLO, 1))
    parent.stdin.flush()
    assert P.read_message(parent.stdout)[0] == T.HELLO  # running, its watch armed
    parent.kill()
    parent.wait(5)
    try:
        assert wait_gone(child, 3)
    finally:
        if alive(child):
            os.kill(child, signal.SIGKILL)
        parent.stdin.close()


def test_nice_and_memory_limit(sidecar, tmp_path):
    write(
        tmp_path / "mem.py",
        """
        import numpy as np
        def f(x):
            if x[0, 0] > 0:
                return x + np.ones(int(x[0, 0]) * 131072)[:1]
            return x
        """,
    )
    kind, _ = sidecar.load(
        module="mem.py", function="f", input_shape=[1, 1], memory_limit_mb=300, nice=10
    )
    assert kind == T.OK
    pid = sidecar.proc.pid
    with open(f"/proc/{pid}/stat") as f:
        nice = int(f.read().rsplit(")", 1)[1].split()[16])
    assert nice == min(19, os.nice(0) + 10)
    kind, _, y = sidecar.call(np.array([[50.0]]))  # 50 MB: fine
    assert kind == T.RESULT and y.tolist() == [[51.0]]
    kind, err, _ = sidecar.call(np.array([[400.0]]))  # 400 MB: beyond the limit
    assert kind == T.ERROR and err["kind"] == "memory"
    assert err["message"].startswith("MemoryError: ")
    assert "the sidecar's memory limit (MemoryLimit: 300 MB) was reached" in err["message"]
    # The process goes on serving.
    kind, _, y = sidecar.call(np.array([[10.0]]))
    assert kind == T.RESULT and y.tolist() == [[11.0]]
