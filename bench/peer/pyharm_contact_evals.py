"""Cost of one residual and one Jacobian evaluation of pyHarm's whole system on the contact case
(the work of one Newton iteration, without its linear solve), against the number of contact
cells (q = 2 cells contact directions).

A short sweep (--max-points points from 150 Hz) gives a converged point; System.Residual and
System.Jacobian are then timed there (process CPU time, median of --repeats after a warm-up call).

Run: OMP_NUM_THREADS=1 taskset -c 0 /tmp/pyharm-venv/bin/python pyharm_contact_evals.py --cells 1 2 4 8
"""

import argparse
import os
import statistics
import time

import numpy as np

import pyharm_contact as pc
from pyharm_common import _quiet, run_once, versions


def cpu_per_call(f, repeats):
    f()
    times = []
    for _ in range(repeats):
        c = time.process_time()
        f()
        times.append(time.process_time() - c)
    return statistics.median(times)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cells", type=int, nargs="+", default=[1, 2, 4, 8])
    p.add_argument("--repeats", type=int, default=20)
    p.add_argument("--max-points", type=int, default=5)
    args = p.parse_args()
    _quiet()
    print("# " + ", ".join(f"{k} {v}" for k, v in versions().items()))
    print(f"# affinity {sorted(os.sched_getaffinity(0))}, OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}")
    for cells in args.cells:
        inp = pc.system_input(pc.BAND_HZ, 0.2 * cells ** 0.5, "scipyroot", "noreductor", args.max_points, cells=cells)
        _, _, _, maestro = run_once(inp)
        analysis = next(iter(maestro.nls.values()))
        x = [s for s in analysis.SolList if s.flag_accepted][-1].x
        system = maestro.system
        r = cpu_per_call(lambda: system.Residual(x), args.repeats)
        j = cpu_per_call(lambda: system.Jacobian(x), args.repeats)
        f_hz = x[-1] * pc.WC / (2 * np.pi)
        print(f"{cells} cell(s), q = {2 * cells}, {len(x)} unknowns, at {f_hz:.2f} Hz: residual {r * 1e3:.2f} ms CPU, "
              f"Jacobian {j * 1e3:.2f} ms CPU (median of {args.repeats}), load average {os.getloadavg()[0]:.2f}",
              flush=True)


if __name__ == "__main__":
    main()
