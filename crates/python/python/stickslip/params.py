"""Parameter studies: one study run for many values of some of its numbers.

The samples (a grid, a seeded Latin hypercube, or rows given by the caller) are drawn by the
Rust library exactly as ``stickslip params`` draws them; they run in batches serially, on
threads or local processes, or on a ``dask.distributed`` cluster, and are gathered in one
pandas table: one row per sample and force level with the peak of the first harmonic, its
frequency and the energy the joints dissipate there. A sample that fails is a row with its
error; the others go on. Finished samples can be cached on disk so that a rerun resumes.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
import time
from typing import Callable, Iterable, Optional

import numpy as np

from . import _stickslip
from ._stickslip import SUMMARY_COLUMNS, ParamError
from ._study import Study

__all__ = ["design", "run_parameters", "ParamResults"]


def _spec(key: str, values) -> str:
    """``KEY=SPEC`` from a Python description: ``(lo, hi)`` a range (Latin hypercube),
    ``(lo, hi, n)`` n grid values, a list the values themselves, a string the SPEC as is."""
    if isinstance(values, str):
        return f"{key}={values}"
    if isinstance(values, tuple) and len(values) == 2:
        return f"{key}={float(values[0])!r}:{float(values[1])!r}"
    if isinstance(values, tuple) and len(values) == 3:
        lo, hi, n = values
        if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool)):
            raise ParamError(f"--vary {key}: (lo, hi, n) needs an integer n, got {n!r}")
        return f"{key}={float(lo)!r}:{float(hi)!r}:{int(n)}"
    if isinstance(values, (list, np.ndarray)):
        return f"{key}=" + ",".join(repr(float(v)) for v in values)
    raise ParamError(f"--vary {key}: expected (lo, hi), (lo, hi, n) or a list of values, got {values!r}")


def _native_study(study):
    if isinstance(study, Study):
        return study._native
    if isinstance(study, (str, os.PathLike)):
        return Study.from_toml(study)._native
    return study  # a dict shaped like a study file


def design(study, vary=None, samples: Optional[int] = None, seed: int = 0, *, values=None):
    """The samples of a parameter study, without running them.

    ``vary`` maps dotted keys (``"joint.blade1.threshold"``, ``"damping.alpha"``,
    ``"excitation.levels[0]"``) to ``(lo, hi)`` (a Latin hypercube of ``samples`` points,
    seeded by ``seed``), ``(lo, hi, n)`` or a list (a grid). Or ``values`` gives the samples
    themselves: a dict key -> array, or a pandas DataFrame, one entry per sample."""
    native = _native_study(study)
    if values is not None:
        if vary is not None:
            raise ParamError("give either vary (ranges or grids) or values (the samples), not both")
        keys = list(values.keys())
        columns = [np.asarray(values[k], dtype=float).ravel() for k in keys]
        lengths = {len(c) for c in columns}
        if len(lengths) > 1:
            raise ParamError(f"values: every key needs one value per sample, got lengths {sorted(lengths)}")
        rows = np.stack(columns, axis=1).tolist() if columns else []
        return _stickslip.ParamDesign.from_samples(native, keys, rows)
    if not vary:
        raise ParamError("vary at least one key, e.g. vary={'joint.joint.threshold': (500.0, 2000.0)}")
    varies = [_spec(k, v) for k, v in vary.items()]
    return _stickslip.ParamDesign(native, varies, samples, seed)


class _Payload:
    """What a worker needs to rebuild the design: the study as a dict and how the samples were
    made (a few kB, shipped with each batch instead of a pickled native object)."""

    def __init__(self, token, study_dict, path, keys, samples, output, curves):
        #: Names the design in a worker's memory (study and design identifiers).
        self.token = token
        self.study_dict = study_dict
        self.path = path
        self.keys = keys
        self.samples = samples
        self.output = output
        self.curves = curves


_DESIGNS: dict = {}


def _run_batch(payload: _Payload, indices: list) -> list:
    """Run samples ``indices`` (in a worker): plain dicts back, errors inside them."""
    key = payload.token
    d = _DESIGNS.get(key)
    if d is None:
        study = _stickslip.Study.from_dict(payload.study_dict, payload.path)
        d = _stickslip.ParamDesign.from_samples(study, payload.keys, payload.samples)
        _DESIGNS.clear()  # one design per worker at a time: studies are not kept around
        _DESIGNS[key] = d
    return d.run(list(indices), payload.output, payload.curves)


class _Cache:
    """Finished samples on disk, one JSON file per sample (and one .npz of its curves), named
    by the sample's identifier; the folder is bound to one study by ``study.json``."""

    def __init__(self, folder, study_id: str):
        self.folder = os.fspath(folder)
        os.makedirs(self.folder, exist_ok=True)
        manifest = os.path.join(self.folder, "study.json")
        if os.path.exists(manifest):
            with open(manifest) as f:
                found = json.load(f).get("study_id")
            if found != study_id:
                raise ParamError(
                    f"{self.folder}: this cache holds samples of another study (id {found}, this study is "
                    f"{study_id}); refusing to mix them: give another cache folder or delete this one")
        else:
            self._write(manifest, json.dumps({"study_id": study_id}))

    def _write(self, path, text):
        fd, tmp = tempfile.mkstemp(dir=self.folder, suffix=".tmp")
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)  # atomic: an interrupted run never leaves half a file

    def get(self, sample_id: str, values, curves: bool):
        path = os.path.join(self.folder, sample_id + ".json")
        if not os.path.exists(path):
            return None
        with open(path) as f:
            entry = json.load(f)
        if entry["values"] != [float(v) for v in values]:
            return None
        if curves and entry["error"] is None:
            npz = os.path.join(self.folder, sample_id + ".npz")
            if not os.path.exists(npz):
                return None
            with np.load(npz) as z:
                entry["curves"] = (list(z["columns"]), z["table"])
        entry["values"] = np.asarray(entry["values"])
        return entry

    def put(self, sample_id: str, outcome: dict):
        entry = {k: outcome[k] for k in ("sample", "rows", "error")}
        entry["values"] = [float(v) for v in outcome["values"]]
        if "curves" in outcome:
            columns, table = outcome["curves"]
            tmp = os.path.join(self.folder, sample_id + ".tmp.npz")
            np.savez(tmp, columns=np.asarray(columns), table=table)
            os.replace(tmp, os.path.join(self.folder, sample_id + ".npz"))
        self._write(os.path.join(self.folder, sample_id + ".json"), json.dumps(entry))


class ParamResults:
    """The outcome of a parameter study."""

    def __init__(self, keys, outcomes, seconds):
        self.keys = list(keys)
        self.outcomes = sorted(outcomes, key=lambda o: o["sample"])
        #: Wall-clock time of the run (s).
        self.seconds = seconds

    def to_pandas(self):
        """One row per sample and force level: ``sample``, the varied keys, then
        ``SUMMARY_COLUMNS``. A failed sample is one row with its ``error``."""
        import pandas as pd

        rows = []
        for o in self.outcomes:
            base = {"sample": o["sample"], **{k: float(v) for k, v in zip(self.keys, o["values"])}}
            for r in o["rows"]:
                rows.append({**base, **r})
            if o["error"] is not None:
                rows.append({**base, **{c: None for c in SUMMARY_COLUMNS}, "points": 0, "complete": False,
                             "error": o["error"]})
        columns = ["sample", *self.keys, *SUMMARY_COLUMNS]
        frame = pd.DataFrame(rows, columns=columns)
        for c in ("level_N", "peak_frequency_Hz", "peak_amplitude_m", "peak_energy_J"):
            frame[c] = frame[c].astype(float)
        frame["points"] = frame["points"].astype("int64")
        frame["complete"] = frame["complete"].astype(bool)
        # Text columns as Python objects (None where there is no error) whatever the pandas
        # version's default string type: tables from different runs compare equal.
        for c in ("ending", "error"):
            frame[c] = pd.Series([None if v is None or v != v else str(v) for v in frame[c]], dtype=object)
        return frame

    def to_xarray(self):
        """The table as an xarray Dataset indexed by row (needs xarray)."""
        return self.to_pandas().to_xarray()

    def curves(self, sample: int):
        """The full curves of a sample (run with ``curves=True``) as a DataFrame with the
        columns of ``frf.csv``."""
        import pandas as pd

        o = self.outcomes[sample]
        if o["sample"] != sample:
            o = next(x for x in self.outcomes if x["sample"] == sample)
        if "curves" not in o:
            raise ParamError(f"sample {sample} has no curves: run with curves=True"
                             + (f" (it failed: {o['error']})" if o["error"] else ""))
        columns, table = o["curves"]
        frame = pd.DataFrame(table, columns=[str(c) for c in columns])
        frame["newton_iterations"] = frame["newton_iterations"].astype("int64")
        return frame

    @property
    def failed(self) -> list:
        """Indices of the samples that failed."""
        return [o["sample"] for o in self.outcomes if o["error"] is not None]


def _batches(indices: list, size: int) -> list:
    return [indices[i:i + size] for i in range(0, len(indices), size)]


def _dask_client(address, workers: int, timeout: float):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ParamError("scheduler='dask' needs dask.distributed: pip install 'dask[distributed]'") from e
    if address is None:
        # One thread per worker process: the solver is single-threaded per sample and the
        # samples are the parallelism.
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        return Client(cluster), cluster
    if not isinstance(address, str):
        return address, None  # a Client given by the caller
    try:
        return Client(address, timeout=f"{timeout}s"), None
    except (OSError, TimeoutError) as e:
        raise ParamError(f"no Dask scheduler answers at {address} (waited {timeout:g} s): start one with "
                         f"`dask scheduler`, check the address, or leave it out for a local cluster ({e})") from None


def run_parameters(study, vary=None, samples: Optional[int] = None, seed: int = 0, *, values=None,
                   scheduler: str = "serial", workers: int = 2, address=None, batch_size: Optional[int] = None,
                   cache=None, curves: bool = False, output: Optional[str] = None,
                   progress: Optional[Callable[[int, int], None]] = None, timeout: float = 5.0) -> ParamResults:
    """Run a study at every sample of a design (see :func:`design` for ``vary``, ``samples``,
    ``seed`` and ``values``).

    ``scheduler``: ``"serial"``, ``"threads"`` (the solver releases the GIL), ``"processes"``
    (``workers`` local processes) or ``"dask"`` (a ``LocalCluster`` of ``workers`` processes,
    or the cluster whose scheduler is at ``address``, or an existing ``Client`` given as
    ``address``; an address that does not answer within ``timeout`` seconds raises).
    Samples go in batches of ``batch_size`` (default: about four batches per worker, at most
    16 samples each) so that scheduling costs little against the sweeps. ``cache``: a folder
    where each finished sample is stored; a rerun takes them from there (and refuses a folder
    written by another study). ``curves``: keep every point of every sample
    (:meth:`ParamResults.curves`). ``output``: the output whose peak is summarised (default
    the first). ``progress(done, total)`` is called as samples finish."""
    started = time.perf_counter()
    d = design(study, vary, samples, seed, values=values)
    native = _native_study(study)
    if not isinstance(native, _stickslip.Study):
        native = _stickslip.Study.from_dict(native)
    n = len(d)
    keys = d.keys
    all_samples = d.samples.tolist()
    store = _Cache(cache, d.study_id) if cache is not None else None
    outcomes, todo = [], []
    for i in range(n):
        hit = store.get(d.sample_id(i), all_samples[i], curves) if store else None
        if hit is not None:
            outcomes.append(hit)
        else:
            todo.append(i)
    done = len(outcomes)
    if progress:
        progress(done, n)
    payload = _Payload(f"{d.study_id}-{d.design_id}", native.to_dict(), native.path, keys, all_samples, output, curves)
    if batch_size is None:
        lanes = 1 if scheduler == "serial" else max(1, workers)
        batch_size = max(1, min(16, math.ceil(len(todo) / (4 * lanes)))) if todo else 1
    batches = _batches(todo, int(batch_size))

    def finished(batch_outcomes: Iterable[dict]):
        nonlocal done
        for o in batch_outcomes:
            if store:
                store.put(d.sample_id(o["sample"]), o)
            outcomes.append(o)
            done += 1
        if progress:
            progress(done, n)

    if scheduler == "serial" or not batches:
        for b in batches:
            finished(_run_batch(payload, b))
    elif scheduler in ("threads", "processes"):
        import concurrent.futures as cf

        if scheduler == "threads":
            pool = cf.ThreadPoolExecutor(max_workers=workers)
        else:
            import multiprocessing

            # spawn: a fresh interpreter per worker, safe whatever threads the parent runs.
            pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))
        with pool:
            futures = [pool.submit(_run_batch, payload, b) for b in batches]
            for f in cf.as_completed(futures):
                finished(f.result())
    elif scheduler == "dask":
        from dask.distributed import as_completed

        client, cluster = _dask_client(address, workers, timeout)
        try:
            # The payload goes to the workers once; each task carries only its indices.
            [shipped] = client.scatter([payload], broadcast=True)
            futures = client.map(_run_batch, [shipped] * len(batches), batches, pure=False)
            for f in as_completed(futures):
                finished(f.result())
        finally:
            if cluster is not None:
                client.close()
                cluster.close()
    else:
        raise ParamError(f"unknown scheduler {scheduler!r}, expected 'serial', 'threads', 'processes' or 'dask'")
    return ParamResults(keys, outcomes, time.perf_counter() - started)
