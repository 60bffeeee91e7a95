"""The sidecar's loop: one user function, called for every frame the host sends.

One process serves one Python block. The host sends `load` once (module, function, init,
params, input shape); the sidecar imports the module, calls `init(params)` when an Init function
is named, finds the output shape with a probe call on zeros (with a throwaway state, then a
fresh `init`), and replies `ok {output_shape}` or `error {message, traceback}`. Then every
`call` carries one input array and gets a `result` (the output array and the Python-side compute
time) or an `error` with the exception's traceback; the sidecar keeps serving after an error.

The host decides how long the process lives, and the process never outlives it: a watcher thread
sees the end of the host's end of stdin (the host closed it, or died: POLLHUP, without reading a
byte of the protocol) and ends the process after `EXIT_GRACE_S` even when the user's function is
stuck; on Linux the kernel also kills it when its parent dies (PR_SET_PDEATHSIG). SIGINT is
ignored (a Ctrl-C in a terminal reaches the whole process group; the host stops the sidecar
itself). `load` may lower the process's priority (`nice`) and limit its memory
(`memory_limit_mb`: RLIMIT_DATA, before the user's module is imported).
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import os
import platform
import select
import signal
import sys
import threading
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO, Callable

import numpy as np

from . import protocol as P
from .protocol import MessageType as T

_PACKAGE_DIR = str(Path(__file__).resolve().parent)

# After the host's end of stdin closes, how long the main thread may take to finish on its own
# (it reads the `shutdown` before the end) before the process ends anyway.
EXIT_GRACE_S = 0.2
# Exit status after running out of memory outside the user's function (the host says so).
EXIT_OUT_OF_MEMORY = 3


def watch_host(fd: int, grace: float = EXIT_GRACE_S) -> threading.Thread:
    """Ends the process `grace` seconds after the write end of pipe `fd` is closed everywhere.

    poll() with an empty event mask reports only POLLHUP/POLLERR, so the protocol's bytes are left
    to the main thread; the thread waits in poll() without the GIL.
    """

    def run() -> None:
        p = select.poll()
        p.register(fd, 0)
        while True:
            try:
                events = p.poll()
            except InterruptedError:  # pragma: no cover (PEP 475 retries)
                continue
            if any(ev & (select.POLLHUP | select.POLLERR | select.POLLNVAL) for _, ev in events):
                break
        time.sleep(grace)
        os._exit(0)

    t = threading.Thread(target=run, name="mosaic-host-watch", daemon=True)
    t.start()
    return t


def die_with_parent() -> bool:
    """Linux: SIGKILL when the parent (the host, or uv between them) dies. True when set."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        PR_SET_PDEATHSIG = 1
        if libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) != 0:
            return False
    except (OSError, AttributeError):
        return False
    # The parent may have died before the call: then it never fires.
    expected = os.environ.get("MOSAIC_PARENT_PID")
    if expected and expected.isdigit() and os.getppid() != int(expected):
        os._exit(0)
    return True


_limits_applied = False
# The data memory limit in force, MB (0: none), for the messages.
_memory_limit_mb: float = 0


def apply_limits(request: dict) -> None:
    """Lowers the priority by `nice` and caps the data segment at `memory_limit_mb` (once)."""
    global _limits_applied, _memory_limit_mb
    if _limits_applied:
        return
    _limits_applied = True
    nice = int(request.get("nice") or 0)
    if nice > 0:
        try:
            os.nice(nice)
        except OSError:
            pass
    mb = request.get("memory_limit_mb") or 0
    if mb and mb > 0:
        import resource

        limit = int(mb * 1024 * 1024)
        _, hard = resource.getrlimit(resource.RLIMIT_DATA)
        if hard != resource.RLIM_INFINITY and hard < limit:
            limit = hard
        resource.setrlimit(resource.RLIMIT_DATA, (limit, limit))
        _memory_limit_mb = limit / (1024 * 1024)


def memory_hint() -> str:
    """What a MemoryError means here: the limit reached (and the param), or the machine's end."""
    limit_mb = _memory_limit_mb
    if limit_mb > 0:
        return (
            f"the sidecar's memory limit (MemoryLimit: {limit_mb:g} MB) was reached; "
            "raise the block's MemoryLimit (MB, 0 for none) if the function needs more"
        )
    return "the machine is out of memory"


class LoadError(Exception):
    """A load-time problem, with the message the host shows."""

    def __init__(self, message: str, tb: str = "", kind: str = "load", **extra: Any):
        super().__init__(message)
        self.message = message
        self.tb = tb
        self.kind = kind
        self.extra = extra


def user_traceback(exc: BaseException) -> str:
    """The traceback of `exc` without the sidecar's own frames (the user's code only)."""
    te = traceback.TracebackException.from_exception(exc)
    te.stack = traceback.StackSummary.from_list(
        [f for f in te.stack if not f.filename.startswith(_PACKAGE_DIR)]
    )
    return "".join(te.format())


def describe_exception(exc: BaseException) -> str:
    """`Type: message`, with file and line of the innermost user frame."""
    text = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
    frames = [
        f
        for f in traceback.extract_tb(exc.__traceback__)
        if not f.filename.startswith(_PACKAGE_DIR)
    ]
    if frames:
        f = frames[-1]
        text += f" (at {f.filename}:{f.lineno}, in {f.name})"
    return text


def import_user_module(spec: str, cwd: str | None) -> Any:
    """Imports a `.py` file (a path, absolute or relative to `cwd`) or an importable module."""
    looks_like_file = spec.endswith(".py") or "/" in spec or os.sep in spec
    if looks_like_file:
        path = Path(spec)
        if not path.is_absolute() and cwd:
            path = Path(cwd) / path
        if not path.is_file():
            raise LoadError(f"module file not found: {path}", kind="missing-module")
        name = path.stem
        folder = str(path.parent)
        if folder not in sys.path:
            sys.path.insert(0, folder)
        module_spec = importlib.util.spec_from_file_location(name, str(path))
        if module_spec is None or module_spec.loader is None:
            raise LoadError(f"cannot import {path} as a Python module", kind="missing-module")
        module = importlib.util.module_from_spec(module_spec)
        sys.modules[name] = module
        try:
            module_spec.loader.exec_module(module)
        except SyntaxError as e:
            sys.modules.pop(name, None)
            raise syntax_error(e) from None
        except MemoryError as e:
            sys.modules.pop(name, None)
            raise LoadError(
                f"importing {path} failed: {describe_exception(e)}; {memory_hint()}",
                user_traceback(e),
                "memory",
            ) from None
        except Exception as e:
            sys.modules.pop(name, None)
            raise LoadError(
                f"importing {path} failed: {describe_exception(e)}", user_traceback(e), "import"
            ) from None
        return module
    try:
        return importlib.import_module(spec)
    except SyntaxError as e:
        raise syntax_error(e) from None
    except ModuleNotFoundError as e:
        if e.name and spec.split(".")[0] == e.name.split(".")[0]:
            where = f" (not installed, and no {spec.split('.')[0]}.py in {cwd})" if cwd else ""
            raise LoadError(f"no module named '{spec}'{where}", kind="missing-module") from None
        raise LoadError(
            f"importing {spec} failed: {describe_exception(e)}", user_traceback(e), "import"
        ) from None
    except Exception as e:
        raise LoadError(
            f"importing {spec} failed: {describe_exception(e)}", user_traceback(e), "import"
        ) from None


def syntax_error(e: SyntaxError) -> LoadError:
    where = f"{e.filename}:{e.lineno}" + (f":{e.offset}" if e.offset else "")
    text = (e.text or "").rstrip("\n")
    message = f"SyntaxError in {where}: {e.msg}"
    tb = "".join(traceback.format_exception_only(type(e), e))
    return LoadError(
        message,
        tb if text else message,
        "syntax",
        file=e.filename,
        line=e.lineno,
    )


def output_shape_of(y: Any, name: str) -> tuple[int, int]:
    try:
        a = np.asarray(y, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise LoadError(
            f"{name} returned {type(y).__name__}, not an array of numbers ({e})", kind="shape"
        ) from None
    if a.ndim == 0:
        return (1, 1)
    if a.ndim == 1:
        if a.shape[0] == 0:
            raise LoadError(f"{name} returned an empty array", kind="shape")
        return (1, a.shape[0])
    if a.ndim == 2:
        if a.size == 0:
            raise LoadError(f"{name} returned an empty array of shape {list(a.shape)}", kind="shape")
        return (int(a.shape[0]), int(a.shape[1]))
    raise LoadError(
        f"{name} returned a {a.ndim}-D array of shape {list(a.shape)}; "
        "return a matrix [rows, cols], a vector or a number",
        kind="shape",
    )


@dataclass
class Loaded:
    function: Callable[..., Any]
    init: Callable[[dict], Any] | None
    params: dict
    input_shape: tuple[int, int]
    output_shape: tuple[int, int]
    with_state: bool
    label: str
    state: Any = None
    out_size: int = field(init=False)

    def __post_init__(self) -> None:
        self.out_size = self.output_shape[0] * self.output_shape[1]

    def fresh_state(self) -> Any:
        return self.init(self.params) if self.init else None

    def invoke(self, x: np.ndarray, state: Any) -> Any:
        return self.function(x, state) if self.with_state else self.function(x)


def wants_state(fn: Callable[..., Any], has_init: bool) -> bool:
    """True when `fn` is to be called as fn(x, state)."""
    if has_init:
        return True
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return False
    required = [
        p
        for p in sig.parameters.values()
        if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) and p.default is p.empty
    ]
    return len(required) >= 2


def load(request: dict) -> Loaded:
    module_spec = str(request.get("module", ""))
    fn_name = str(request.get("function", ""))
    init_name = request.get("init") or None
    params = request.get("params") or {}
    shape = request.get("input_shape") or [1, 1]
    cwd = request.get("cwd") or None
    expected = request.get("output_shape")
    if not module_spec:
        raise LoadError("no module given", kind="missing-module")
    apply_limits(request)
    module = import_user_module(module_spec, cwd)
    mod_name = getattr(module, "__file__", None) or module_spec

    def lookup(name: str, what: str) -> Callable[..., Any]:
        fn = getattr(module, name, None)
        if fn is None:
            defined = sorted(
                k for k, v in vars(module).items() if callable(v) and not k.startswith("_")
            )
            hint = f" (it defines: {', '.join(defined)})" if defined else ""
            raise LoadError(f"{mod_name} has no {what} '{name}'{hint}", kind="missing-function")
        if not callable(fn):
            raise LoadError(f"{mod_name}: '{name}' is not a function", kind="missing-function")
        return fn

    function = lookup(fn_name, "function")
    init = lookup(str(init_name), "init function") if init_name else None
    input_shape = (int(shape[0]), int(shape[1]))
    loaded = Loaded(
        function=function,
        init=init,
        params=dict(params),
        input_shape=input_shape,
        output_shape=(1, 1),
        with_state=wants_state(function, init is not None),
        label=f"{fn_name}()",
    )

    def guarded(what: str, fn: Callable[[], Any]) -> Any:
        try:
            return fn()
        except LoadError:
            raise
        except MemoryError as e:
            raise LoadError(
                f"{what} raised {describe_exception(e)}; {memory_hint()}",
                user_traceback(e),
                "memory",
            ) from None
        except Exception as e:
            raise LoadError(f"{what} raised {describe_exception(e)}", user_traceback(e), what) from None

    # The probe: a call on zeros with a throwaway state tells the output shape.
    probe_state = guarded("init", loaded.fresh_state)
    x0 = np.zeros(input_shape, dtype=np.float64)
    y = guarded("probe", lambda: loaded.invoke(x0, probe_state))
    out = output_shape_of(y, f"{fn_name}(zeros({list(input_shape)}))")
    if expected is not None:
        exp = (int(expected[0]), int(expected[1]))
        if exp[0] * exp[1] != out[0] * out[1]:
            raise LoadError(
                f"{fn_name} returned shape {list(out)} but the block expects {list(exp)}",
                kind="shape",
            )
        out = exp
    loaded.output_shape = out
    loaded.out_size = out[0] * out[1]
    del probe_state
    loaded.state = guarded("init", loaded.fresh_state)
    return loaded


class Server:
    def __init__(self, inp: BinaryIO, out: BinaryIO):
        self.inp = inp
        self.out = out
        self.loaded: Loaded | None = None

    def send(self, kind: int, rid: int, *parts: bytes) -> None:
        length = sum(len(p) for p in parts)
        data = b"".join((P.header(kind, rid, length), *parts))
        view = memoryview(data)
        while view:
            n = self.out.write(view)
            if n is None:
                continue
            view = view[n:]

    def send_json(self, kind: int, rid: int, obj: Any) -> None:
        self.send(kind, rid, P.encode_json(obj))

    def error(self, rid: int, message: str, tb: str = "", kind: str = "call", **extra: Any) -> None:
        self.send_json(T.ERROR, rid, {"message": message, "traceback": tb, "kind": kind, **extra})

    def hello(self, rid: int) -> None:
        self.send_json(
            T.HELLO,
            rid,
            {
                "protocol": P.VERSION,
                "pid": os.getpid(),
                "python": platform.python_version(),
                "numpy": np.__version__,
            },
        )

    def handle_load(self, rid: int, payload: bytearray) -> None:
        import json

        try:
            request = json.loads(payload.decode("utf-8"))
            self.loaded = load(request)
        except LoadError as e:
            self.loaded = None
            self.error(rid, e.message, e.tb, e.kind, **e.extra)
            return
        except Exception as e:  # a bug in the request or here: still an answer, never a hang
            self.loaded = None
            self.error(rid, f"load failed: {describe_exception(e)}", traceback.format_exc(), "load")
            return
        self.send_json(T.OK, rid, {"output_shape": list(self.loaded.output_shape)})

    def handle_call(self, rid: int, payload: bytearray) -> None:
        lo = self.loaded
        if lo is None:
            self.error(rid, "no function loaded", kind="protocol")
            return
        try:
            x = P.decode_array(payload)
        except P.ProtocolError as e:
            self.error(rid, f"bad call: {e}", kind="protocol")
            return
        if x.dtype != np.float64:
            x = x.astype(np.float64)
        if x.shape != lo.input_shape:
            if x.size != lo.input_shape[0] * lo.input_shape[1]:
                self.error(
                    rid,
                    f"input of shape {list(x.shape)}, expected {list(lo.input_shape)}",
                    kind="protocol",
                )
                return
            x = x.reshape(lo.input_shape)
        t0 = time.perf_counter_ns()
        try:
            y = np.asarray(lo.invoke(x, lo.state), dtype=np.float64)
        except MemoryError as e:
            message = f"{describe_exception(e)}; {memory_hint()}"
            self.error(rid, message, user_traceback(e), "memory")
            return
        except Exception as e:
            self.error(rid, describe_exception(e), user_traceback(e), "call")
            return
        t1 = time.perf_counter_ns()
        if y.size != lo.out_size:
            self.error(
                rid,
                f"{lo.label} returned shape {list(y.shape)}, but its output is "
                f"{list(lo.output_shape)} (found by the probe call at load)",
                kind="shape",
            )
            return
        us = np.array([(t1 - t0) / 1000.0], dtype="<f8").tobytes()
        self.send(T.RESULT, rid, us, P.encode_array(y.reshape(lo.output_shape)))

    def handle_reset(self, rid: int) -> None:
        lo = self.loaded
        if lo is None:
            self.error(rid, "no function loaded", kind="protocol")
            return
        try:
            lo.state = lo.fresh_state()
        except Exception as e:
            self.error(rid, f"init raised {describe_exception(e)}", user_traceback(e), "init")
            return
        self.send_json(T.OK, rid, {})

    def serve(self) -> int:
        while True:
            try:
                msg = P.read_message(self.inp)
            except P.ProtocolError as e:
                # The stream cannot be resynchronised: say why and stop.
                self.error(0, f"protocol error: {e}", kind="protocol")
                return 2
            if msg is None:
                return 0
            kind, rid, payload = msg
            if kind == T.CALL:
                self.handle_call(rid, payload)
            elif kind == T.HELLO:
                self.hello(rid)
            elif kind == T.LOAD:
                self.handle_load(rid, payload)
            elif kind == T.RESET:
                self.handle_reset(rid)
            elif kind == T.SHUTDOWN:
                return 0
            else:
                self.error(rid, f"unknown message type {kind}", kind="protocol")


def main() -> int:
    # The host stops the sidecar; a terminal's Ctrl-C (sent to the whole group) is not for us.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent()
    # The protocol owns the original stdin/stdout; user code that prints or reads stdin gets
    # stderr and /dev/null instead, so it cannot corrupt the stream.
    proto_in = os.fdopen(os.dup(0), "rb", buffering=0)
    watch_host(proto_in.fileno())
    proto_out = os.fdopen(os.dup(1), "wb", buffering=0)
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)
    os.close(devnull)
    os.dup2(2, 1)
    sys.stdin = open(os.devnull)  # noqa: SIM115
    sys.stdout = sys.stderr
    server = Server(proto_in, proto_out)
    try:
        return server.serve()
    except BrokenPipeError:
        return 0
    except MemoryError:
        # Outside the user's function (reading a request, sending a result): say so and end.
        os.write(2, f"mosaic_sidecar: out of memory; {memory_hint()}\n".encode())
        os._exit(EXIT_OUT_OF_MEMORY)
