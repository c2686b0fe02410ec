"""Studies: many runs of one analysis, spread over processes or machines with Dask.

A study is a function of one case's parameters that returns named scalars, and a list (or a
grid) of cases. One call runs it::

    import voussoir as vs

    def capacity(friction_deg, kn):
        r = vs.scenarios.arch_static(friction_deg=friction_deg, kn=kn)
        return {"peak_kn": r["peak_load_kn"]}

    cases = vs.study.grid(friction_deg=[28, 30.5, 33], kn=[2e9, 4e9])
    table = vs.study.run(capacity, cases, store="out/study")

- It runs on a given ``distributed.Client`` (a cluster anywhere: ``Client("tcp://host:8786")``,
  ``dask_jobqueue.SLURMCluster``), or by default on a ``LocalCluster`` of one single-threaded
  worker process per core, each process's rayon pool sized to ``threads_per_worker``.
- ``table`` is a pandas DataFrame, one row per case in the order of ``cases``: the case's
  parameters, the values ``case_fn`` returned, and ``error`` (empty when the case ran).
- Each case is written to ``store`` as it completes (one JSON file per case, written
  atomically, named by a hash of the case's parameters: ``case_key``), so that a rerun skips
  the cases already done and an interrupted study resumes; ``store/table.csv`` holds the table
  at the end. The values come back from the store as they were returned (numpy arrays with
  their dtype and shape, floats bit for bit).
- A case that raises (a diverging run, a bad parameter) is a row with its message, never the
  end of the study; a worker that dies has its cases rerun by Dask (``retries``); with
  ``timeout=`` a case that runs too long is killed and is a row with a ``TimeoutError``.
- The numbers are those of a serial loop over the cases, bit for bit, whatever the number of
  workers: every case runs alone in one process, and voussoir's runs are deterministic for any
  number of threads.
"""

from __future__ import annotations

import base64
import hashlib
import itertools
import json
import math
import os
import pickle
import struct
import subprocess
import sys
import tempfile
import threading
import time
import warnings
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence

__all__ = ["grid", "run", "case_key", "arch_static_cases", "arch_static_case", "arch_static_sensitivity"]

def grid(**axes: Sequence[Any]) -> List[Dict[str, Any]]:
    """The cases of a full factorial grid, the last axis varying fastest::

        >>> import voussoir as vs
        >>> vs.study.grid(phi=[30, 35], kn=[1e9, 4e9])
        [{'phi': 30, 'kn': 1000000000.0}, {'phi': 30, 'kn': 4000000000.0}, {'phi': 35, 'kn': 1000000000.0}, {'phi': 35, 'kn': 4000000000.0}]
    """
    names = list(axes)
    for name, values in axes.items():
        if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
            raise TypeError(f"grid: axis {name!r} must be a list of values, not {type(values).__name__}")
    return [dict(zip(names, combo)) for combo in itertools.product(*(list(v) for v in axes.values()))]


# The key that marks a value JSON cannot hold as it is (a numpy array, a tuple, a TimeHistory)
# in the store's files; a dict of the user's holding it is refused.
_TAG = "$voussoir"


def _numpy():
    """numpy when it is imported (a value cannot be a numpy object otherwise)."""
    return sys.modules.get("numpy")


def _time_history_type():
    try:
        from ._voussoir import TimeHistory
    except ImportError:  # pragma: no cover - study.py used outside the package
        return None
    return TimeHistory


def _case_json(value: Any, where: str) -> Any:
    """A parameter as JSON data that tells it apart from every other value, for the case's key.

    Plain JSON values (``None``, ``bool``, ``int``, ``float`` — ``numpy.float64`` included —,
    ``str``, lists, tuples and dicts of them) are themselves, so that the keys of the plain cases
    of stores written before are unchanged (a tuple is its list: JSON cannot tell them apart).
    A numpy array is its dtype, shape and a hash of its bytes (an array of objects: its items);
    another numpy scalar its dtype and value; a ``TimeHistory`` its samples (times and values);
    any other object a hash of its pickle (what Dask sends to a worker). ``where`` names the
    value in the ``TypeError`` or ``ValueError`` of one that cannot be keyed."""
    if value is None or type(value) in (bool, int, str):
        return value
    if isinstance(value, float) and type(value).__module__ in ("builtins", "numpy"):
        return float(value)  # float and numpy.float64 (a float): the same number, the same case
    np = _numpy()
    if np is not None and type(value) is np.str_:
        return str(value)
    if np is not None and type(value) is np.ndarray:
        a = np.ascontiguousarray(value)
        if a.dtype.fields is not None or a.dtype.subdtype is not None:
            raise TypeError(f"{where}: a structured numpy array ({a.dtype}) cannot be keyed; pass its fields")
        if a.dtype.kind == "O":
            return {_TAG: "ndarray", "dtype": "|O", "shape": list(a.shape),
                    "items": [_case_json(v, f"{where}[{i}]") for i, v in enumerate(a.ravel().tolist())]}
        if a.dtype.byteorder == ">" or (a.dtype.byteorder == "=" and sys.byteorder == "big"):
            a = a.astype(a.dtype.newbyteorder("<"))  # the same numbers, the same case
        return {_TAG: "ndarray", "dtype": a.dtype.str, "shape": list(a.shape),
                "sha256": hashlib.sha256(a.tobytes()).hexdigest()}
    if np is not None and isinstance(value, np.generic):
        dtype = value.dtype
        if dtype.kind in "biu":
            return {_TAG: "numpy", "dtype": dtype.str, "value": value.item()}
        if dtype.kind == "f" and dtype.itemsize <= 8:
            return {_TAG: "numpy", "dtype": dtype.str, "value": float(value)}
        if dtype.kind != "O" and dtype.fields is None:
            return {_TAG: "numpy", "dtype": dtype.str, "hex": value.tobytes().hex()}
    if type(value) in (list, tuple):
        return [_case_json(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if type(value) is dict:
        out = {}
        for k, v in value.items():
            if type(k) is not str:
                raise TypeError(f"{where}: a dict with the key {k!r}, not a string (JSON would make it one)")
            if k == _TAG:
                raise ValueError(f"{where}: the key {_TAG!r} of a dict is reserved for the study's store")
            out[k] = _case_json(v, f"{where}[{k!r}]")
        return out
    history = _time_history_type()
    if history is not None and isinstance(value, history):
        return {_TAG: "TimeHistory", "times": _case_json(value.times, f"{where}.times"),
                "values": _case_json(value.values, f"{where}.values")}
    try:
        data = _dumps(value)
    except Exception as e:  # noqa: BLE001 - any pickling failure says the same thing
        raise TypeError(
            f"{where} is a {type(value).__module__}.{type(value).__qualname__}, which the study cannot key "
            f"exactly: it is no JSON value, numpy array or TimeHistory, and it cannot be pickled ({e}); "
            f"pass plain values and build the object inside the case function"
        ) from None
    return {_TAG: "pickle", "type": f"{type(value).__module__}.{type(value).__qualname__}",
            "sha256": hashlib.sha256(data).hexdigest()}


def _case_text(case: Mapping[str, Any], where: str = "case") -> str:
    """The canonical JSON text of a case: what its key hashes, and what its file must hold."""
    data = {}
    for name, value in case.items():
        if not isinstance(name, str):
            raise TypeError(f"{where}: parameter names must be strings, not {name!r}")
        data[name] = _case_json(value, f"{where}: parameter {name!r}")
    return json.dumps(data, sort_keys=True)


def case_key(case: Mapping[str, Any]) -> str:
    """A stable name for a case, the file it is stored in: a hash of its parameters, exact.

    Plain parameters (numbers, strings, lists and dicts of them) are hashed as JSON with sorted
    keys, as before; numpy arrays by dtype, shape and bytes, ``TimeHistory`` objects by their
    samples, other objects by their pickle, so that two different cases never share a key (a
    parameter that is none of these raises ``TypeError``)."""
    return hashlib.sha256(_case_text(case).encode()).hexdigest()[:20]


def _value_json(value: Any, where: str) -> Any:
    """A returned value as JSON data that ``_value_from_json`` turns back into the same value:
    numbers (numpy scalars as Python numbers, floats bit for bit), strings, ``None``, lists,
    tuples, bytes, dicts with string keys, numpy arrays (dtype, shape and bytes) and
    ``TimeHistory`` objects; ``TypeError`` naming ``where`` for anything else."""
    np = _numpy()
    if np is not None and isinstance(value, np.generic) and value.dtype.kind in "biufc":
        value = value.item()  # numpy scalars to Python numbers
    if value is None or type(value) is str:
        return value
    if isinstance(value, bool):
        return bool(value)
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        value = float(value)
        if value != value and struct.pack("<d", value) != struct.pack("<d", math.nan):
            return {_TAG: "float", "hex": struct.pack("<d", value).hex()}  # a NaN of other bits
        return value
    if isinstance(value, str):
        return str.__str__(value)
    if isinstance(value, bytes):
        return {_TAG: "bytes", "data": base64.b64encode(value).decode("ascii")}
    if isinstance(value, complex):
        return {_TAG: "complex", "real": _value_json(value.real, where), "imag": _value_json(value.imag, where)}
    if np is not None and isinstance(value, np.ndarray):
        if type(value) is not np.ndarray:
            raise TypeError(f"{where} is a {type(value).__name__}, a numpy array subclass the store cannot keep; "
                            f"return a plain array (numpy.asarray)")
        a = np.ascontiguousarray(value)
        if a.dtype.fields is not None or a.dtype.subdtype is not None:
            raise TypeError(f"{where} is a structured numpy array ({a.dtype}), which the store cannot keep; "
                            f"return its fields")
        if a.dtype.kind == "O":
            return {_TAG: "ndarray", "dtype": "|O", "shape": list(a.shape),
                    "items": [_value_json(v, f"{where}[{i}]") for i, v in enumerate(a.ravel().tolist())]}
        return {_TAG: "ndarray", "dtype": a.dtype.str, "shape": list(a.shape),
                "data": base64.b64encode(a.tobytes()).decode("ascii")}
    if isinstance(value, (list, tuple)):
        items = [_value_json(v, f"{where}[{i}]") for i, v in enumerate(value)]
        return items if isinstance(value, list) else {_TAG: "tuple", "items": items}
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"{where}: a dict with the key {k!r}, not a string, which the store cannot keep")
            if k == _TAG:
                raise ValueError(f"{where}: the key {_TAG!r} of a dict is reserved for the study's store")
            out[str.__str__(k)] = _value_json(v, f"{where}[{k!r}]")
        return out
    history = _time_history_type()
    if history is not None and isinstance(value, history):
        return {_TAG: "TimeHistory", "times": _value_json(value.times, f"{where}.times"),
                "values": _value_json(value.values, f"{where}.values")}
    raise TypeError(
        f"{where} is a {type(value).__module__}.{type(value).__qualname__}, which the study's store cannot keep "
        f"exactly: return numbers, strings, lists, dicts, numpy arrays or TimeHistory objects"
    )


def _value_from_json(data: Any) -> Any:
    """The value ``_value_json`` wrote (``ValueError`` for a malformed one)."""
    if isinstance(data, list):
        return [_value_from_json(v) for v in data]
    if not isinstance(data, dict):
        return data
    tag = data.get(_TAG)
    if tag is None:
        return {k: _value_from_json(v) for k, v in data.items()}
    if tag == "ndarray":
        import numpy as np

        shape = tuple(int(n) for n in data["shape"])
        if data["dtype"] == "|O":
            a = np.empty(len(data["items"]), dtype=object)
            for i, v in enumerate(data["items"]):
                a[i] = _value_from_json(v)
            return a.reshape(shape)
        return np.frombuffer(base64.b64decode(data["data"]), dtype=np.dtype(data["dtype"])).reshape(shape).copy()
    if tag == "tuple":
        return tuple(_value_from_json(v) for v in data["items"])
    if tag == "float":
        return struct.unpack("<d", bytes.fromhex(data["hex"]))[0]
    if tag == "bytes":
        return base64.b64decode(data["data"])
    if tag == "complex":
        return complex(_value_from_json(data["real"]), _value_from_json(data["imag"]))
    if tag == "TimeHistory":
        history = _time_history_type()
        return history(_value_from_json(data["times"]).tolist(), _value_from_json(data["values"]).tolist())
    raise ValueError(f"an unknown kind of value {tag!r}")


def _run_case(
    case_fn: Callable[..., Mapping[str, Any]], case: Dict[str, Any], reserved: Sequence[str] = ("error",)
) -> Dict[str, Any]:
    """Runs one case; its values (as the store keeps them: ``_value_json``), or its error as
    text. ``reserved``: the names a value may not have (the parameters' and ``error``)."""
    started = time.perf_counter()
    try:
        returned = case_fn(**case)
        if not isinstance(returned, Mapping):
            raise TypeError(f"the case function returned {type(returned).__name__}, not a dict of scalars")
        values: Dict[str, Any] = {}
        for k, v in returned.items():
            name = str(k)
            if name in values:
                raise ValueError(f"the case function returned two values named {name!r}")
            if name == "error":
                raise ValueError(
                    "the case function returned a value named 'error', the table's column of a failed case's "
                    "message: rename it"
                )
            if name in reserved:
                raise ValueError(
                    f"the case function returned a value named {name!r}, the name of a parameter (the table "
                    f"has one column per name): rename it"
                )
            values[name] = _value_json(v, f"the returned value {name!r}")
        error = ""
    except Exception as e:  # noqa: BLE001 - a failed case is a row, not the end of the study
        values, error = {}, f"{type(e).__name__}: {e}"
    return {"values": values, "error": error, "seconds": time.perf_counter() - started}


def _write_atomically(path: str, text: str) -> None:
    """Writes ``text`` to ``path`` through a temporary file in the same folder, renamed over
    it: a reader never sees half a file."""
    folder = os.path.dirname(path) or "."
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".tmp-", suffix=os.path.basename(path))
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


class _Progress:
    """tqdm (terminal or Jupyter) when installed, else a line every few seconds on stderr."""

    def __init__(self, total: int, done: int, enabled: bool):
        self.total, self.done, self.enabled, self.bar = total, done, enabled, None
        self.last = 0.0
        if enabled:
            try:
                from tqdm.auto import tqdm

                self.bar = tqdm(total=total, initial=done, desc="cases", unit="case")
            except ImportError:
                self.bar = None

    def update(self) -> None:
        self.done += 1
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.update(1)
        elif time.monotonic() - self.last > 2.0 or self.done == self.total:
            self.last = time.monotonic()
            print(f"study: {self.done}/{self.total} cases", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


_PICKLER = None


def _reduce_time_history(history: Any):
    return (type(history), (history.times.tolist(), history.values.tolist()))


def _dumps(value: Any) -> bytes:
    """``value`` pickled as Dask pickles it (cloudpickle when installed: the functions of a
    script by value), ``TimeHistory`` objects included (as their samples)."""
    global _PICKLER
    if _PICKLER is None:
        import copyreg
        from collections import ChainMap

        try:
            import cloudpickle

            base = cloudpickle.CloudPickler
        except ImportError:  # pragma: no cover - distributed brings cloudpickle
            base = pickle.Pickler
        table = getattr(base, "dispatch_table", copyreg.dispatch_table)
        history = _time_history_type()
        extra = {history: _reduce_time_history} if history is not None else {}

        class _Pickler(base):  # type: ignore[misc, valid-type]
            dispatch_table = ChainMap(extra, table)

        _PICKLER = _Pickler
    import io

    buffer = io.BytesIO()
    _PICKLER(buffer, protocol=4).dump(value)
    return buffer.getvalue()


# Cases with a timeout run in a child Python process (a "case process") of the process that
# would run them (a Dask worker, or this process for client="serial"), so that one that runs too
# long can be killed: a thread cannot be. The child is started once and runs case after case;
# one is started again after a kill. Messages are pickles, each after its length (8 bytes).
_CHILD_CODE = (
    "import pickle, sys\n"
    "n = int.from_bytes(sys.stdin.buffer.read(8), 'little')\n"
    "sys.path[:] = pickle.loads(sys.stdin.buffer.read(n))\n"
    "from voussoir.study import _child_main\n"
    "_child_main()\n"
)
_STARTUP_SECONDS = 120.0


def _send(f: Any, data: bytes) -> None:
    f.write(len(data).to_bytes(8, "little"))
    f.write(data)
    f.flush()


def _receive(f: Any) -> Optional[bytes]:
    """A message, or None at the end of the pipe (the other process is gone)."""
    header = f.read(8)
    if len(header) < 8:
        return None
    n = int.from_bytes(header, "little")
    data = f.read(n)
    return data if len(data) == n else None


def _die_with_parent() -> None:
    """A case process ends when the process that started it ends, even in a hung case: Linux's
    parent-death signal, else a thread watching the parent."""
    parent = int(os.environ.get("VOUSSOIR_STUDY_PARENT", "0") or 0)
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            ctypes.CDLL(None).prctl(1, 9)  # PR_SET_PDEATHSIG, SIGKILL
        except Exception:  # noqa: BLE001 - the thread below still watches
            pass
    if parent and os.getppid() != parent:
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(1.0)
            if os.getppid() != parent:
                os._exit(1)

    if parent:
        threading.Thread(target=watch, name="voussoir-study-parent", daemon=True).start()


def _child_main() -> None:
    """The loop of a case process: reads (case function, case, reserved names), runs the case
    and writes its outcome, until its parent closes the pipe."""
    requests = sys.stdin.buffer
    answers = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)  # what a case prints goes to stderr, not into the answers
    _die_with_parent()
    _send(answers, b"ready")
    functions: Dict[bytes, Any] = {}
    while True:
        request = _receive(requests)
        if request is None:
            return
        started = time.perf_counter()
        try:
            fn_bytes, case_bytes, reserved = pickle.loads(request)
            if fn_bytes not in functions:
                functions.clear()
                functions[fn_bytes] = pickle.loads(fn_bytes)
            case_fn, case = functions[fn_bytes], pickle.loads(case_bytes)
        except Exception as e:  # noqa: BLE001 - a case that cannot be read here is a row
            outcome = {"values": {}, "error": f"{type(e).__name__}: the case process cannot read the case: {e}",
                       "seconds": time.perf_counter() - started}
        else:
            outcome = _run_case(case_fn, case, reserved)
        _send(answers, pickle.dumps(outcome, protocol=4))


class _CaseTimeout(Exception):
    pass


class _CaseProcess:
    """A case process (``_child_main``), ready for cases."""

    def __init__(self) -> None:
        env = dict(os.environ, VOUSSOIR_STUDY_PARENT=str(os.getpid()))
        extra: Dict[str, Any] = {"start_new_session": True} if os.name == "posix" else {}
        self.proc = subprocess.Popen(
            [sys.executable, "-c", _CHILD_CODE], stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env, **extra
        )
        try:
            _send(self.proc.stdin, pickle.dumps(list(sys.path)))
            ready = self.answer(_STARTUP_SECONDS)
        except _CaseTimeout:
            raise ChildProcessError(f"a case process did not start within {_STARTUP_SECONDS:g} s") from None
        except ChildProcessError:
            raise ChildProcessError(
                f"a case process did not start (exit status {self.proc.returncode}; its error is on stderr): "
                f"{sys.executable} must import voussoir"
            ) from None
        except BaseException:
            self.kill()
            raise
        if ready != b"ready":  # pragma: no cover - the protocol's own check
            self.kill()
            raise ChildProcessError("a case process started wrongly")

    def alive(self) -> bool:
        return self.proc.poll() is None

    def answer(self, timeout: float) -> bytes:
        """The next message, waited for ``timeout`` seconds at most (then the process is killed
        and ``_CaseTimeout`` raised); ``ChildProcessError`` when the process died."""
        box: List[Optional[bytes]] = []

        def read() -> None:
            try:
                box.append(_receive(self.proc.stdout))
            except (OSError, ValueError):
                box.append(None)

        reader = threading.Thread(target=read, name="voussoir-study-case", daemon=True)
        reader.start()
        reader.join(timeout)
        if reader.is_alive():
            self.kill()
            reader.join()
            raise _CaseTimeout()
        if not box or box[0] is None:
            self.kill()
            raise ChildProcessError(f"the case's process died (exit status {self.proc.returncode})")
        return box[0]

    def kill(self) -> None:
        """Kills the process and, on POSIX, the processes it started (its session)."""
        if self.proc.returncode is None:
            try:
                if os.name == "posix":
                    import signal

                    os.killpg(self.proc.pid, signal.SIGKILL)
                else:  # pragma: no cover
                    self.proc.kill()
            except OSError:
                pass
        self.proc.wait()
        for pipe in (self.proc.stdin, self.proc.stdout):
            try:
                pipe.close()
            except OSError:
                pass


class _CaseProcesses:
    """The idle case processes of one process (each busy one belongs to the thread running a
    case in it)."""

    def __init__(self) -> None:
        self.idle: List[_CaseProcess] = []
        self.lock = threading.Lock()

    def run(self, fn_bytes: bytes, case_bytes: bytes, reserved: Sequence[str], timeout: float) -> Dict[str, Any]:
        """One case in a case process: its outcome (``_run_case``), or a ``TimeoutError`` row
        when it ran for more than ``timeout`` seconds (its process killed); raises
        ``ChildProcessError`` when the process died (Dask then reruns it, ``retries``)."""
        request = pickle.dumps((fn_bytes, case_bytes, list(reserved)), protocol=4)
        with self.lock:
            child = self.idle.pop() if self.idle else None
        for attempt in range(2):
            if child is None or not child.alive():
                if child is not None:
                    child.kill()
                child = _CaseProcess()
            try:
                _send(child.proc.stdin, request)
                break
            except OSError:  # it ended while idle (its parent thread ended): a new one
                child.kill()
                child = None
                if attempt == 1:
                    raise ChildProcessError("a case process ended before its case") from None
        started = time.perf_counter()
        try:
            answer = child.answer(timeout)
        except _CaseTimeout:
            return {
                "values": {},
                "error": f"TimeoutError: the case ran for more than timeout={timeout:g} s; its process was killed",
                "seconds": time.perf_counter() - started,
            }
        except BaseException:
            child.kill()
            raise
        with self.lock:
            self.idle.append(child)
        return pickle.loads(answer)

    def close(self) -> None:
        with self.lock:
            idle, self.idle = self.idle, []
        for child in idle:
            child.kill()


_WORKER_PROCESSES: Optional[_CaseProcesses] = None
_WORKER_LOCK = threading.Lock()


def _run_on_worker(
    case_fn: Callable[..., Mapping[str, Any]], case_bytes: bytes, reserved: Sequence[str], timeout: Optional[float]
) -> Dict[str, Any]:
    """The Dask task of a case: the case (pickled by ``_dumps``: a ``TimeHistory`` travels too)
    run in the worker, or with a timeout in one of the worker's case processes."""
    if timeout is None:
        return _run_case(case_fn, pickle.loads(case_bytes), reserved)
    global _WORKER_PROCESSES
    with _WORKER_LOCK:
        if _WORKER_PROCESSES is None:
            import atexit

            _WORKER_PROCESSES = _CaseProcesses()
            atexit.register(_WORKER_PROCESSES.close)
    return _WORKER_PROCESSES.run(_dumps(case_fn), case_bytes, reserved, timeout)


def _load_stored(path: str, text: str, reserved: Sequence[str]) -> Optional[Dict[str, Any]]:
    """The stored record of the case whose canonical text is ``text``, its values read back;
    None when there is none, or one of another case. A file that is no case's record (cut
    short, edited, written by something else) is warned about, by name, and the case is run
    again (its file replaced)."""

    def bad(why: str) -> None:
        warnings.warn(f"study: {path} {why}; the case is run again and the file replaced", RuntimeWarning, stacklevel=4)

    try:
        with open(path, encoding="utf-8") as f:
            stored = json.load(f)
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as e:
        bad(f"cannot be read as JSON ({type(e).__name__}: {e})")
        return None
    if not isinstance(stored, dict) or "case" not in stored:
        bad("is not a case's record (no 'case')")
        return None
    if json.dumps(stored["case"], sort_keys=True) != text:
        return None  # another case's (a key shared before keys were exact): run again
    values, error = stored.get("values", {}), stored.get("error", "")
    if not isinstance(values, dict) or not isinstance(error, str):
        bad("is not a case's record (its 'values' or 'error' is malformed)")
        return None
    for name in values:
        if name in reserved:
            bad(f"holds a value named {name!r}, the name of a parameter or of the error column (an older voussoir)")
            return None
    try:
        decoded = {name: _value_from_json(v) for name, v in values.items()}
    except Exception as e:  # noqa: BLE001 - a malformed value is a malformed file
        bad(f"holds a value that cannot be read ({type(e).__name__}: {e})")
        return None
    seconds = stored.get("seconds", math.nan)
    return {"values": decoded, "error": error, "seconds": seconds if isinstance(seconds, (int, float)) else math.nan}


def run(
    case_fn: Callable[..., Mapping[str, Any]],
    cases: Sequence[Mapping[str, Any]],
    store: Optional[str] = None,
    client: Any = None,
    *,
    threads_per_worker: int = 1,
    retries: int = 2,
    rerun_errors: bool = False,
    progress: bool = True,
    timeout: Optional[float] = None,
):
    """Runs ``case_fn(**case)`` for every case and returns the table (pandas DataFrame).

    ``case_fn`` returns a dict of scalars; it may be any picklable function, one defined in
    your script included (Dask pickles it with cloudpickle). ``store``: the folder the cases are
    kept in as they complete (None: nothing kept); a case already there is not run again
    (``rerun_errors=True`` reruns the ones that failed). ``client``: a ``distributed.Client``;
    None starts a ``LocalCluster`` of ``os.cpu_count() // threads_per_worker`` worker
    processes for the study and closes it after; ``"serial"`` runs the cases one after the
    other in this process. ``threads_per_worker``: the rayon threads of each worker process
    (set through ``RAYON_NUM_THREADS`` when the cluster is started here; a cluster of your own
    sets it in its workers' environment). ``retries``: how many times Dask reruns a case whose
    worker died.

    ``timeout``: the seconds of wall time a case may run (None: no limit, and a case that
    hangs hangs the study). With a timeout every case runs in a child Python process of the
    process that would have run it (a worker, or this process for ``"serial"``), started once
    and reused, since a thread cannot be stopped: a case still running ``timeout`` seconds after
    it started (waiting for a worker does not count) has that process killed, with the
    processes it started, and is a row whose ``error`` is ``"TimeoutError: ..."`` (kept in
    ``store`` like any failure: ``rerun_errors=True`` runs it again). A case process that dies
    is like a worker that dies: its case is run again (``retries``). The numbers do not change.

    Parameters: plain values (numbers, strings, ``None``, lists and dicts of them), numpy arrays
    and scalars, ``TimeHistory`` objects, or any picklable object; each case is named in the
    store by a hash of them (``case_key``), exact: two cases that differ are two cases, however
    alike they print. Returned values: numbers, strings, ``None``, lists, tuples, dicts, numpy
    arrays and ``TimeHistory`` objects, which come back from the store unchanged (another value
    fails its case); a value may not be named like a parameter or ``error`` (the table's
    columns): such a case fails with a ``ValueError`` naming it. A file of the store that is not
    a case's record (cut short, edited) is warned about by name and its case run again.
    """
    cases = [dict(c) for c in cases]
    if timeout is not None:
        if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not (0 < timeout < math.inf):
            raise ValueError(f"timeout must be a positive number of seconds or None, not {timeout!r}")
        timeout = float(timeout)
    texts = []
    for k, c in enumerate(cases):
        for name in c:
            if not isinstance(name, str):
                raise TypeError(f"case {k}: parameter names must be strings, not {name!r}")
        if "error" in c:
            raise ValueError(
                f"case {k}: a parameter named 'error' would be hidden by the table's error column: rename it"
            )
        texts.append(_case_text(c, f"case {k}"))
    keys = [hashlib.sha256(t.encode()).hexdigest()[:20] for t in texts]
    if len(set(keys)) != len(keys):
        seen: Dict[str, int] = {}
        for k, key in enumerate(keys):
            if key in seen:
                raise ValueError(f"cases {seen[key]} and {k} are the same case: {cases[k]}")
            seen[key] = k
    reserved = sorted({name for c in cases for name in c} | {"error"})
    folder = None
    if store is not None:
        folder = os.path.join(os.fspath(store), "cases")
        os.makedirs(folder, exist_ok=True)

    results: Dict[int, Dict[str, Any]] = {}
    if folder is not None:
        for k, key in enumerate(keys):
            stored = _load_stored(os.path.join(folder, key + ".json"), texts[k], reserved)
            if stored is not None and not (rerun_errors and stored["error"]):
                results[k] = stored
    todo = [k for k in range(len(cases)) if k not in results]

    def keep(k: int, outcome: Dict[str, Any]) -> None:
        entry = {"case": json.loads(texts[k]), **outcome}
        if folder is not None:
            _write_atomically(os.path.join(folder, keys[k] + ".json"), json.dumps(entry))
        # What the table shows is what a rerun reads from the store.
        values = {name: _value_from_json(v) for name, v in outcome.get("values", {}).items()}
        results[k] = dict(outcome, values=values)

    bar = _Progress(len(cases), len(cases) - len(todo), progress)
    try:
        if todo and client == "serial" and timeout is None:
            for k in todo:
                keep(k, _run_case(case_fn, cases[k], reserved))
                bar.update()
        elif todo and client == "serial":
            try:
                fn_bytes = _dumps(case_fn)
            except Exception as e:  # noqa: BLE001
                raise TypeError(
                    f"with a timeout each case runs in a process of its own: case_fn must be picklable ({e})"
                ) from None
            processes = _CaseProcesses()
            try:
                for k in todo:
                    case_bytes = _dumps(cases[k])
                    for attempt in range(max(0, retries) + 1):
                        try:
                            outcome = processes.run(fn_bytes, case_bytes, reserved, timeout)
                            break
                        except ChildProcessError as e:
                            outcome = {"values": {}, "error": f"{type(e).__name__}: {e}", "seconds": math.nan}
                    keep(k, outcome)
                    bar.update()
            finally:
                processes.close()
        elif todo:
            own = client is None
            cluster = None
            if own:
                from distributed import Client, LocalCluster

                workers = max(1, (os.cpu_count() or 1) // max(1, threads_per_worker))
                cluster = LocalCluster(
                    n_workers=workers,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    env={"RAYON_NUM_THREADS": str(threads_per_worker)},
                )
                client = Client(cluster)
            try:
                from distributed import as_completed

                futures = {}
                for k in todo:
                    future = client.submit(
                        _run_on_worker,
                        case_fn,
                        _dumps(cases[k]),
                        reserved,
                        timeout,
                        key=f"voussoir-case-{keys[k]}",
                        pure=False,
                        retries=retries,
                    )
                    futures[future] = k
                for future in as_completed(futures):
                    k = futures[future]
                    try:
                        outcome = future.result()
                    except Exception as e:  # noqa: BLE001 - lost beyond its retries
                        outcome = {"values": {}, "error": f"{type(e).__name__}: {e}", "seconds": math.nan}
                    keep(k, outcome)
                    bar.update()
            finally:
                if own:
                    client.close()
                    cluster.close()
    finally:
        bar.close()

    table = _table(cases, [results[k] for k in range(len(cases))])
    if store is not None:
        _write_atomically(os.path.join(os.fspath(store), "table.csv"), table.to_csv(index=False))
    return table


def _table(cases: List[Dict[str, Any]], outcomes: List[Dict[str, Any]]):
    import pandas as pd

    rows = []
    value_names: List[str] = []
    for outcome in outcomes:
        for name in outcome.get("values", {}):
            if name not in value_names:
                value_names.append(name)
    for case, outcome in zip(cases, outcomes):
        row = dict(case)
        for name in value_names:
            row[name] = outcome.get("values", {}).get(name, math.nan)
        row["error"] = outcome.get("error", "") or ""
        rows.append(row)
    return pd.DataFrame(rows)


def arch_static_cases() -> List[Dict[str, Any]]:
    """The cases of ``cargo run --release --example arch_static`` (arch/src/cli/arch_static.rs,
    ``paper_cases``), as keyword arguments of ``voussoir.scenarios.arch_static``: the baseline
    (φ 30.5°, kn 4 GPa/m, ks 0.4 kn, width 0.15 m, large displacements, servo loading), the
    friction sweep 25°–40°, kn 2 and 8 GPa/m (ks scaled with it), small displacements, width
    0.20 m, and the rate study at 0.05, 0.01 and 0.005 m/s."""
    base = {"label": "baseline", "friction_deg": 30.5, "kn": 4e9, "ks": 1.6e9, "width": 0.15, "mode": "large"}
    cases = [dict(base)]
    for phi in range(25, 41):
        if phi != 30.5:
            cases.append(dict(base, label=f"friction {phi}°", friction_deg=float(phi)))
    for kn in (2e9, 8e9):
        cases.append(dict(base, label=f"kn {kn / 1e9:g} GPa/m", kn=kn, ks=kn * base["ks"] / base["kn"]))
    cases.append(dict(base, label="small displacements", mode="small"))
    cases.append(dict(base, label="width 0.20 m", width=0.20))
    for rate in (5e-2, 1e-2, 5e-3):
        cases.append(dict(base, label=f"rate {rate:g} m/s", rate=rate))
    return cases


def arch_static_case(**case: Any) -> Dict[str, Any]:
    """One case of the static study (``voussoir.scenarios.arch_static(**case)``): its peak load
    (kN), the plate's displacement there (mm), its limit analysis (kN) and whether it slides."""
    import voussoir as vs

    r = vs.scenarios.arch_static(**case)
    return {
        "peak_load_kn": r["peak_load_kn"],
        "disp_at_peak_mm": r["disp_at_peak_mm"],
        "raw_peak_load_kn": r["raw_peak_load_kn"],
        "steps": r["steps"],
    }


def arch_static_sensitivity(store: Optional[str] = None, client: Any = None, *, progress: bool = True, **common: Any):
    """The reference arch's static sensitivity study of ``cargo run --release --example
    arch_static`` (``arch_static_cases``, each with ``common`` keywords added) as a study on
    Dask: its table (one row per case: the case's keywords, ``peak_load_kn``,
    ``disp_at_peak_mm``, ``raw_peak_load_kn``, ``steps``, ``error``)."""
    cases = [dict(c, **common) for c in arch_static_cases()]
    return run(arch_static_case, cases, store=store, client=client, progress=progress)
