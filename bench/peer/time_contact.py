"""Interleaved timing of stickslip and pyHarm on the 2-D contact case, one core each.

One Python process warms pyHarm up (numba and jax compilation), then alternates: a whole
`stickslip --threads 1 run` process (CPU time = user + system of the child, from getrusage),
then one pyHarm sweep in this process (process CPU time around `Maestro.operate`). Medians of
--runs pairs; the load average is printed with every run.

Usage (from bench/peer, one core):
  OMP_NUM_THREADS=1 taskset -c 0 /tmp/pyharm-venv/bin/python time_contact.py \
      --stickslip ../../target/release/stickslip --study studies/contact2d.toml --runs 5 --ds 0.2
"""

import argparse
import csv
import os
import resource
import statistics
import subprocess
import tempfile
import time

import pyharm_contact as pc
from pyharm_common import _instrument_solvers, _quiet, collect, run_once, versions


def stickslip_once(binary, study, out):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run([binary, "--threads", "1", "run", study, "--out", out, "--no-report"], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    with open(os.path.join(out, "frf.csv")) as f:
        n = sum(1 for _ in csv.DictReader(f))
    return wall, cpu, n


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--stickslip", required=True)
    p.add_argument("--study", required=True)
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--ds", type=float, default=0.2)
    p.add_argument("--cells", type=int, default=1, help="chain of cells (pyharm_contact.py --cells)")
    args = p.parse_args()
    _quiet()
    _instrument_solvers()
    print("# " + ", ".join(f"{k} {v}" for k, v in versions().items()))
    print(f"# {args.cells} cell(s), pyHarm ds {args.ds}, stickslip study {args.study}")
    print(f"# affinity {sorted(os.sched_getaffinity(0))}, OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}")
    inp = pc.system_input(pc.BAND_HZ, args.ds, "scipyroot", "noreductor", cells=args.cells)
    t = time.perf_counter()
    run_once(inp)
    print(f"pyHarm warm-up: {time.perf_counter() - t:.1f} s wall")
    out = tempfile.mkdtemp(prefix="stickslip-contact-")
    ss_wall, ss_cpu, ph_wall, ph_cpu = [], [], [], []
    n_ss = n_ph = 0
    for r in range(args.runs):
        w, c, n_ss = stickslip_once(args.stickslip, args.study, out)
        ss_wall.append(w)
        ss_cpu.append(c)
        load1 = os.getloadavg()[0]
        _, w2, c2, maestro = run_once(inp)
        n_ph = len(collect(maestro, 0, pc.LC, pc.WC)[0])
        ph_wall.append(w2)
        ph_cpu.append(c2)
        print(f"pair {r + 1}: stickslip {n_ss} points, process {w * 1e3:.1f} ms wall, {c * 1e3:.1f} ms CPU "
              f"(load {load1:.2f}); pyHarm {n_ph} points, sweep {w2:.3f} s wall, {c2:.3f} s CPU "
              f"(load {os.getloadavg()[0]:.2f})", flush=True)
    m = statistics.median
    print(f"stickslip whole process, median of {args.runs}: {m(ss_wall) * 1e3:.1f} ms wall, {m(ss_cpu) * 1e3:.1f} ms CPU; "
          f"{n_ss} points: {m(ss_cpu) / n_ss * 1e3:.3f} ms CPU per point")
    print(f"pyHarm sweep (warm), median of {args.runs}: {m(ph_wall):.3f} s wall, {m(ph_cpu):.3f} s CPU; "
          f"{n_ph} points: {m(ph_cpu) / n_ph * 1e3:.2f} ms CPU per point")
    print(f"ratio of CPU per sweep: {m(ph_cpu) / m(ss_cpu):.0f}; per point: "
          f"{(m(ph_cpu) / n_ph) / (m(ss_cpu) / n_ss):.0f}")


if __name__ == "__main__":
    main()
