"""The real sidecar process: hello, load (and its errors), calls, exceptions, reset."""

import textwrap

import numpy as np
import pytest

from mosaic_sidecar import protocol as P

T = P.MessageType


def write(path, text):
    path.write_text(textwrap.dedent(text))
    return path


def test_hello(sidecar):
    kind, info = sidecar.json(T.HELLO)
    assert kind == T.HELLO
    assert info["protocol"] == 1 and info["pid"] == sidecar.proc.pid
    assert info["python"].startswith("3.11")


def test_identity_round_trip_bit_exact(sidecar, tmp_path):
    write(tmp_path / "ident.py", "def identity(x):\n    return x\n")
    kind, ok = sidecar.load(module="ident.py", function="identity", input_shape=[2, 4])
    assert kind == T.OK and ok == {"output_shape": [2, 4]}
    x = np.array(
        [[np.nan, -0.0, 5e-324, -5e-324], [np.inf, -np.inf, 1e308, 0.1 + 0.2]], dtype=np.float64
    )
    kind, us, y = sidecar.call(x)
    assert kind == T.RESULT and us >= 0
    assert y.tobytes() == x.tobytes()


def test_init_state_and_reset(sidecar, tmp_path):
    write(
        tmp_path / "acc.py",
        """
        import numpy as np
        def init(params):
            return {"sum": np.zeros(params["n"]), "gain": params.get("gain", 1)}
        def step(x, state):
            state["sum"] += x.sum(axis=0)
            return state["gain"] * state["sum"]
        """,
    )
    kind, ok = sidecar.load(
        module="acc.py", function="step", init="init", params={"n": 3, "gain": 2}, input_shape=[1, 3]
    )
    # The probe call used a throwaway state: the real one starts at zero.
    assert kind == T.OK and ok["output_shape"] == [1, 3]
    assert sidecar.call(np.ones((1, 3)))[2].tolist() == [[2, 2, 2]]
    assert sidecar.call(np.ones((1, 3)))[2].tolist() == [[4, 4, 4]]
    assert sidecar.json(T.RESET)[0] == T.OK
    assert sidecar.call(np.ones((1, 3)))[2].tolist() == [[2, 2, 2]]


def test_scalar_and_vector_results(sidecar, tmp_path):
    write(tmp_path / "m.py", "def f(x):\n    return float(x.sum())\n")
    assert sidecar.load(module="m.py", function="f", input_shape=[3, 2])[1] == {
        "output_shape": [1, 1]
    }
    assert sidecar.call(np.ones((3, 2)))[2].tolist() == [[6.0]]


def test_installed_module_by_name(sidecar):
    kind, ok = sidecar.load(module="numpy", function="cumsum", input_shape=[1, 4])
    assert kind == T.OK and ok["output_shape"] == [1, 4]
    assert sidecar.call(np.array([[1.0, 2, 3, 4]]))[2].tolist() == [[1, 3, 6, 10]]


def test_missing_module_file(sidecar):
    kind, err = sidecar.load(module="nowhere.py", function="f", input_shape=[1, 1])
    assert kind == T.ERROR and err["kind"] == "missing-module"
    assert "module file not found" in err["message"] and "nowhere.py" in err["message"]


def test_missing_module_name(sidecar):
    kind, err = sidecar.load(module="no_such_module_xyz", function="f", input_shape=[1, 1])
    assert kind == T.ERROR and err["kind"] == "missing-module"
    assert "no module named 'no_such_module_xyz'" in err["message"]


def test_missing_function_lists_what_exists(sidecar, tmp_path):
    write(tmp_path / "m.py", "def step(x):\n    return x\ndef other(x):\n    return x\n")
    kind, err = sidecar.load(module="m.py", function="stp", input_shape=[1, 1])
    assert kind == T.ERROR and "has no function 'stp'" in err["message"]
    assert "other, step" in err["message"]


def test_syntax_error_names_file_and_line(sidecar, tmp_path):
    write(tmp_path / "bad.py", "import numpy\n\ndef f(x):\n    return x +\n")
    kind, err = sidecar.load(module="bad.py", function="f", input_shape=[1, 1])
    assert kind == T.ERROR and err["kind"] == "syntax"
    assert f"SyntaxError in {tmp_path / 'bad.py'}:4" in err["message"]
    assert err["line"] == 4 and err["file"].endswith("bad.py")
    assert "return x +" in err["traceback"]


def test_exception_at_import_has_traceback(sidecar, tmp_path):
    write(tmp_path / "boom.py", "x = 1\nraise RuntimeError('no device')\n")
    kind, err = sidecar.load(module="boom.py", function="f", input_shape=[1, 1])
    assert kind == T.ERROR and "RuntimeError: no device" in err["message"]
    assert "boom.py\", line 2" in err["traceback"]


def test_wrong_return_shape_at_load(sidecar, tmp_path):
    write(tmp_path / "m.py", "import numpy as np\ndef f(x):\n    return np.zeros((2, 2, 2))\n")
    kind, err = sidecar.load(module="m.py", function="f", input_shape=[1, 3])
    assert kind == T.ERROR and err["kind"] == "shape" and "3-D array" in err["message"]


def test_not_an_array_at_load(sidecar, tmp_path):
    write(tmp_path / "m.py", "def f(x):\n    return 'hello'\n")
    kind, err = sidecar.load(module="m.py", function="f", input_shape=[1, 3])
    assert kind == T.ERROR and err["kind"] == "shape" and "not an array of numbers" in err["message"]


def test_expected_output_shape_checked(sidecar, tmp_path):
    write(tmp_path / "m.py", "def f(x):\n    return x\n")
    kind, err = sidecar.load(module="m.py", function="f", input_shape=[1, 3], output_shape=[1, 4])
    assert kind == T.ERROR and "expects [1, 4]" in err["message"]


def test_shape_changing_at_run_time(sidecar, tmp_path):
    write(tmp_path / "m.py", "def f(x):\n    return x[:, : int(x[0, 0]) or 3]\n")
    assert sidecar.load(module="m.py", function="f", input_shape=[1, 3])[0] == T.OK
    kind, err, _ = sidecar.call(np.array([[2.0, 0, 0]]))
    assert kind == T.ERROR and err["kind"] == "shape" and "returned shape [1, 2]" in err["message"]
    assert sidecar.call(np.array([[3.0, 1, 2]]))[0] == T.RESULT  # still serving


def test_exception_in_call_has_traceback_and_keeps_serving(sidecar, tmp_path):
    write(
        tmp_path / "m.py",
        """
        def helper(v):
            if v > 0:
                raise ValueError(f"negative expected, got {v}")
            return v
        def f(x):
            return [helper(x[0, 0])]
        """,
    )
    assert sidecar.load(module="m.py", function="f", input_shape=[1, 1])[0] == T.OK
    kind, err, _ = sidecar.call(np.array([[1.0]]))
    assert kind == T.ERROR and err["kind"] == "call"
    assert err["message"].startswith("ValueError: negative expected, got 1.0 (at ")
    assert "m.py:4, in helper" in err["message"]
    tb = err["traceback"]
    assert "in f" in tb and "in helper" in tb and "mosaic_sidecar" not in tb
    assert sidecar.call(np.array([[-1.0]]))[2].tolist() == [[-1.0]]


def test_init_exception_is_a_load_error(sidecar, tmp_path):
    write(tmp_path / "m.py", "def init(p):\n    return p['missing']\ndef f(x, s):\n    return x\n")
    kind, err = sidecar.load(module="m.py", function="f", init="init", input_shape=[1, 1])
    assert kind == T.ERROR and err["kind"] == "init" and "KeyError: 'missing'" in err["message"]


def test_print_does_not_corrupt_the_stream(sidecar, tmp_path):
    write(tmp_path / "m.py", "import os\ndef f(x):\n    print('hello')\n    os.write(1, b'raw')\n    return x\n")
    assert sidecar.load(module="m.py", function="f", input_shape=[1, 2])[0] == T.OK
    assert sidecar.call(np.array([[1.0, 2.0]]))[2].tolist() == [[1.0, 2.0]]


def test_unknown_message_type(sidecar):
    k, _, payload = sidecar.request(42)
    assert k == T.ERROR and b"unknown message type 42" in payload


@pytest.mark.parametrize("n", [1, 50])
def test_many_calls_in_order(sidecar, tmp_path, n):
    write(tmp_path / "m.py", "def f(x):\n    return x * 2\n")
    assert sidecar.load(module="m.py", function="f", input_shape=[1, 1])[0] == T.OK
    for i in range(n):
        assert sidecar.call(np.array([[float(i)]]))[2][0, 0] == 2 * i


def test_eof_exits_cleanly(sidecar):
    sidecar.proc.stdin.close()
    assert sidecar.proc.wait(10) == 0
