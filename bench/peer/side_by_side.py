"""Whole-process CPU of `stickslip run` against pyHarm's CPU per sweep, side by side, one core.

Each round runs pyHarm's sweep (`pyharm_table6.py` or `pyharm_chain.py --runs R`, one BLAS
thread: the median CPU time of its timed sweeps), then `stickslip --threads 1 run STUDY
--no-plots` of every binary given, interleaved run by run (the order alternates), and prints
the medians and the ratios. stickslip's figure is the CPU time (user + system, from wait4) of
the whole process: start-up, reading the study, the sweep, the located peaks, frf.csv, frf.npz,
peaks.csv and the report. The studies `studies/*_pyharm_density.toml` have about pyHarm's
point count (527 and 333 points against its 518 and 319).

Usage (from bench/peer; the process pins itself and its children to core 0):
  python3 side_by_side.py --case chain --rounds 4 --runs 9 \
      --stickslip ../../target/release/stickslip [--stickslip before=/path/to/other/stickslip]
"""

import argparse
import os
import re
import statistics
import subprocess
import tempfile

CASES = {
    "table6": ("pyharm_table6.py", "studies/table6_pyharm_density.toml"),
    "chain": ("pyharm_chain.py", "studies/chain10_pyharm_density.toml"),
}


def stickslip_cpu(binary, study, out):
    child = subprocess.Popen(
        [binary, "--threads", "1", "run", study, "--out", out, "--no-plots", "--quiet"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    _, status, usage = os.wait4(child.pid, 0)
    if status != 0:
        raise SystemExit(f"{binary} run {study} failed (status {status})")
    return usage.ru_utime + usage.ru_stime


def pyharm_cpu(python, script, runs):
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    with tempfile.TemporaryDirectory() as tmp:
        out = subprocess.run(
            [python, script, "--runs", str(runs), "--csv", os.path.join(tmp, "frf.csv")],
            env=env,
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    found = re.search(r"sweep CPU time, median of \d+: ([0-9.]+) s", out)
    if not found:
        raise SystemExit(f"{script} printed no CPU time:\n{out}")
    return float(found.group(1))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--case", choices=sorted(CASES), required=True)
    p.add_argument("--rounds", type=int, default=4)
    p.add_argument("--runs", type=int, default=9, help="stickslip runs of each binary per round")
    p.add_argument("--pyharm-runs", type=int, default=3, help="pyHarm's timed sweeps per round")
    p.add_argument("--python", default="/tmp/pyharm-venv/bin/python", help="the pyHarm virtualenv's python")
    p.add_argument(
        "--stickslip",
        action="append",
        required=True,
        help="a stickslip binary, optionally labelled LABEL=PATH; several are interleaved",
    )
    args = p.parse_args()
    os.sched_setaffinity(0, {0})
    script, study = CASES[args.case]
    binaries = [b.split("=", 1) if "=" in b else (os.path.basename(b), b) for b in args.stickslip]
    ratios = {label: [] for label, _ in binaries}
    with tempfile.TemporaryDirectory() as out:
        for r in range(args.rounds):
            py = pyharm_cpu(args.python, script, args.pyharm_runs)
            cpu = {label: [] for label, _ in binaries}
            for i in range(args.runs):
                for label, binary in binaries if i % 2 == 0 else binaries[::-1]:
                    cpu[label].append(stickslip_cpu(binary, study, out))
            line = [f"round {r + 1}: pyHarm {py:.3f} s per sweep"]
            for label, _ in binaries:
                median = statistics.median(cpu[label])
                ratios[label].append(py / median)
                line.append(f"{label} {median * 1e3:.2f} ms ({py / median:.0f}x)")
            line.append(f"load {os.getloadavg()[0]:.2f}")
            print("; ".join(line), flush=True)
    for label, values in ratios.items():
        print(f"{label}: ratio {min(values):.0f}-{max(values):.0f}x, median of the rounds {statistics.median(values):.0f}x")


if __name__ == "__main__":
    main()
