"""Throughput of a parameter study of Table 6 sweeps: serial, local processes, a Dask
LocalCluster; the overhead per sample against the sweep itself.

    pip install ./crates/python pandas "dask[distributed]"
    python bench/params/throughput.py [SAMPLES] [WORKERS]     # default 400 2

Each sample is one sweep of the 1-DOF Table 6 study (examples/jenkins-1dof) at 1000 N over
150-350 Hz, N = 7, 300 time samples, with the friction threshold and the damping drawn by a
seeded Latin hypercube. Prints one line per scheduler (wall clock, sweeps per second) and the
overhead per sample: workers x wall clock / samples minus the sweep's own cost (the samples
run back to back in one call of the native library, no Python in between). The wall clock
includes starting the worker processes or the cluster, except on the running cluster.
"""

import pathlib
import sys
import time

import stickslip

ROOT = pathlib.Path(__file__).resolve().parents[2]
KEYS = {"joint.joint.threshold": (500.0, 2000.0), "damping.alpha": (20.0, 50.0)}


def main():
    samples = int(sys.argv[1]) if len(sys.argv) > 1 else 400
    workers = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    base = stickslip.Study.from_toml(ROOT / "examples" / "jenkins-1dof" / "study.toml")
    d = base.to_dict()
    d["excitation"]["levels"] = [1000.0]
    study = stickslip.Study.from_dict(d, base.path)

    # The sweeps themselves: every sample in one native call.
    design = stickslip.design(study, KEYS, samples=samples, seed=1)
    started = time.perf_counter()
    design.run(list(range(samples)))
    native = time.perf_counter() - started
    per_sweep = native / samples
    print(f"{samples} sweeps, {workers} workers; sweep alone: {per_sweep * 1e3:.2f} ms "
          f"({native:.2f} s back to back)")

    from dask.distributed import Client, LocalCluster

    # A cluster already running (as on a real cluster, started once for many studies).
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
    client = Client(cluster)
    runs = [("serial", "serial", None), ("processes", "processes", None),
            ("dask, new LocalCluster", "dask", None), ("dask, running cluster", "dask", client)]
    for label, scheduler, address in runs:
        lanes = 1 if scheduler == "serial" else workers
        started = time.perf_counter()
        out = stickslip.run_parameters(study, KEYS, samples=samples, seed=1, scheduler=scheduler,
                                       workers=workers, address=address)
        wall = time.perf_counter() - started
        assert not out.failed and len(out.outcomes) == samples
        overhead = lanes * wall / samples - per_sweep
        print(f"{label:>24} x{lanes}: {wall:7.2f} s, {samples / wall:7.1f} sweeps/s, "
              f"overhead {overhead * 1e3:+.2f} ms per sample ({overhead / per_sweep:+.0%} of a sweep)")
    client.close()
    cluster.close()


if __name__ == "__main__":
    main()
