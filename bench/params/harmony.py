"""Throughput of a parameter study of Harmony sweeps: serial, local processes, a Dask
LocalCluster; the overhead per sample against the sweep itself.

    pip install ./crates/python pandas "dask[distributed]"
    python bench/params/harmony.py [SAMPLES] [WORKERS] [REFINEMENT]     # default 40 2 0.5

Each sample is one sweep of the Harmony example (examples/harmony, enriched reduction, four
Jenkins joints, N = 7, 512 time samples, 300 -> 170 Hz) at 1875 N, with blade 1's friction
threshold and the damping drawn by a seeded Latin hypercube. The varied keys leave the reduced
model unchanged, so a worker builds it once (mesh, assembly, modes, reduction) and every
sample after is a sweep. Measured first, in one native call: a sample built from scratch
(build + sweep) and then the others on its reduced model back to back (the sweep alone). Then
one line per scheduler: wall clock, sweeps per second, and the overhead per sample, workers x
wall clock / samples minus the sweep alone (it includes each worker's one build). The wall
clock includes starting the worker processes or the cluster, except on the running cluster.
"""

import pathlib
import sys
import time

import stickslip

ROOT = pathlib.Path(__file__).resolve().parents[2]
KEYS = {"joint.blade1.threshold": (250.0, 330.0), "damping.alpha": (10.0, 20.0)}


def main():
    samples = int(sys.argv[1]) if len(sys.argv) > 1 else 40
    workers = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    refinement = float(sys.argv[3]) if len(sys.argv) > 3 else 0.5
    base = stickslip.Study.from_toml(ROOT / "examples" / "harmony" / "study.toml")
    d = base.to_dict()
    d["model"]["harmony"]["refinement"] = refinement
    d["excitation"]["levels"] = [1875.0]
    study = stickslip.Study.from_dict(d, base.path)

    design = stickslip.design(study, KEYS, samples=samples, seed=1)
    started = time.perf_counter()
    design.run([0])
    first = time.perf_counter() - started
    started = time.perf_counter()
    design.run(list(range(1, samples)))
    per_sweep = (time.perf_counter() - started) / (samples - 1)
    build = first - per_sweep
    print(f"refinement {refinement}, {samples} sweeps, {workers} workers; a sample from scratch "
          f"{first:.2f} s (build {build:.2f} s), sweep alone {per_sweep:.2f} s; "
          f"without reuse {samples} samples would be {samples * first:.0f} s serial")

    from dask.distributed import Client, LocalCluster

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
        print(f"{label:>24} x{lanes}: {wall:7.2f} s, {samples / wall:6.2f} sweeps/s, "
              f"overhead {overhead:+.2f} s per sample ({overhead / per_sweep:+.0%} of a sweep)", flush=True)
    client.close()
    cluster.close()


if __name__ == "__main__":
    main()
