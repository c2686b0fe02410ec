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
  atomically), so that a rerun skips the cases already done and an interrupted study resumes;
  ``store/table.csv`` holds the table at the end.
- A case that raises (a diverging run, a bad parameter) is a row with its message, never the
  end of the study; a worker that dies has its cases rerun by Dask (``retries``).
- The numbers are those of a serial loop over the cases, bit for bit, whatever the number of
  workers: every case runs alone in one process, and voussoir's runs are deterministic for any
  number of threads.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
import sys
import tempfile
import time
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


def case_key(case: Mapping[str, Any]) -> str:
    """A stable name for a case (its parameters, JSON with sorted keys, hashed): the file it is
    stored in."""
    text = json.dumps(case, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def _scalar(value: Any) -> Any:
    """A returned value as a plain scalar (numpy scalars to Python numbers)."""
    if hasattr(value, "item") and callable(value.item):
        try:
            return value.item()
        except (TypeError, ValueError):
            pass
    return value


def _run_case(case_fn: Callable[..., Mapping[str, Any]], case: Dict[str, Any]) -> Dict[str, Any]:
    """Runs one case; its values, or its error as text."""
    started = time.perf_counter()
    try:
        values = case_fn(**case)
        if not isinstance(values, Mapping):
            raise TypeError(f"the case function returned {type(values).__name__}, not a dict of scalars")
        values = {str(k): _scalar(v) for k, v in values.items()}
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
    """
    cases = [dict(c) for c in cases]
    for k, c in enumerate(cases):
        for name, value in c.items():
            if not isinstance(name, str):
                raise TypeError(f"case {k}: parameter names must be strings, not {name!r}")
    keys = [case_key(c) for c in cases]
    if len(set(keys)) != len(keys):
        seen: Dict[str, int] = {}
        for k, key in enumerate(keys):
            if key in seen:
                raise ValueError(f"cases {seen[key]} and {k} are the same case: {cases[k]}")
            seen[key] = k
    folder = None
    if store is not None:
        folder = os.path.join(os.fspath(store), "cases")
        os.makedirs(folder, exist_ok=True)

    results: Dict[int, Dict[str, Any]] = {}
    if folder is not None:
        for k, key in enumerate(keys):
            path = os.path.join(folder, key + ".json")
            if os.path.exists(path):
                with open(path, encoding="utf-8") as f:
                    stored = json.load(f)
                if stored.get("case") == json.loads(json.dumps(cases[k], default=repr)):
                    if not (rerun_errors and stored.get("error")):
                        results[k] = stored
    todo = [k for k in range(len(cases)) if k not in results]

    def keep(k: int, outcome: Dict[str, Any]) -> None:
        entry = {"case": cases[k], **outcome}
        results[k] = entry
        if folder is not None:
            _write_atomically(os.path.join(folder, keys[k] + ".json"), json.dumps(entry, default=repr))

    bar = _Progress(len(cases), len(cases) - len(todo), progress)
    try:
        if todo and client == "serial":
            for k in todo:
                keep(k, _run_case(case_fn, cases[k]))
                bar.update()
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
                        _run_case, case_fn, cases[k], key=f"voussoir-case-{keys[k]}", pure=False, retries=retries
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
