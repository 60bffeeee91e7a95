"""A real sidecar process for the tests: `python -m mosaic_sidecar` on pipes."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mosaic_sidecar import protocol as P

PACKAGE_ROOT = Path(__file__).resolve().parent.parent


class Sidecar:
    def __init__(self, cwd: Path):
        env = dict(os.environ)
        env["PYTHONPATH"] = str(PACKAGE_ROOT) + os.pathsep + env.get("PYTHONPATH", "")
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "mosaic_sidecar"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            cwd=cwd,
            env=env,
        )
        self.cwd = cwd
        self.next_id = 1

    def request(self, kind: int, payload: bytes = b"") -> tuple[int, int, bytearray]:
        rid = self.next_id
        self.next_id += 1
        assert self.proc.stdin is not None
        self.proc.stdin.write(P.message(kind, rid, payload))
        self.proc.stdin.flush()
        reply = P.read_message(self.proc.stdout)  # type: ignore[arg-type]
        assert reply is not None, self.proc.stderr.read().decode()  # type: ignore[union-attr]
        assert reply[1] == rid
        return reply

    def json(self, kind: int, obj: dict | None = None) -> tuple[int, dict]:
        k, _, payload = self.request(kind, P.encode_json(obj) if obj is not None else b"")
        return k, json.loads(payload)

    def load(self, **request) -> tuple[int, dict]:
        request.setdefault("cwd", str(self.cwd))
        return self.json(P.MessageType.LOAD, request)

    def call(self, x: np.ndarray) -> tuple[int, float | dict, np.ndarray | None]:
        k, _, payload = self.request(P.MessageType.CALL, P.encode_array(x))
        if k == P.MessageType.RESULT:
            us = float(np.frombuffer(payload, "<f8", 1)[0])
            return k, us, P.decode_array(payload, 8)
        return k, json.loads(payload), None

    def close(self) -> int:
        assert self.proc.stdin is not None
        if not self.proc.stdin.closed:
            self.proc.stdin.write(P.message(P.MessageType.SHUTDOWN, 0))
            self.proc.stdin.close()
        code = self.proc.wait(10)
        self.proc.stdout.close()  # type: ignore[union-attr]
        self.proc.stderr.close()  # type: ignore[union-attr]
        return code


@pytest.fixture
def sidecar(tmp_path):
    s = Sidecar(tmp_path)
    yield s
    if s.proc.poll() is None:
        try:
            s.close()
        except (OSError, ValueError, subprocess.TimeoutExpired):
            s.proc.kill()  # a failed test's stuck process: never left behind
            s.proc.wait(5)
