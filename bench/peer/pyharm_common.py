"""Shared driver for the pyHarm (PyPI `pyharm-os`) peer measurements.

Each case script builds a pyHarm input dictionary (a linear substructure with M, K, D, Jenkins
connectors and a cosine force), then calls `main()` here, which runs the frequency sweep
(pyHarm's pseudo-arclength continuation), times it (median of several runs after a warm-up),
counts the nonlinear-solver work per converged point and writes the FRF to CSV.

pyHarm is not a project dependency: install it in a throwaway virtualenv (see README.md).
"""

import argparse
import copy
import csv
import logging
import os
import statistics
import sys
import time
import warnings

import numpy as np


def _quiet():
    """pyHarm logs every converged point and numba warns about array layouts: silence both so
    that the timings measure the solver, not the terminal."""
    warnings.filterwarnings("ignore")
    logging.disable(logging.CRITICAL)


def _instrument_solvers():
    """Record the work of the nonlinear solver on every solution object.

    pyHarm's default solver wraps scipy.optimize.root (MINPACK hybrd: Powell's hybrid method with
    Broyden updates between Jacobian evaluations); its result carries nfev/njev but pyHarm drops
    them, so keep them on the solution. The NewtonRaphson solver already stores `iter_numb`.
    """
    from pyHarm.NonLinearSolver.ScipyRoot import Solver_ScipyRoot

    original = Solver_ScipyRoot._complete_solution
    if getattr(original, "_instrumented", False):
        return

    def complete_solution(self, S, sol, SolList):
        original(self, S, sol, SolList)
        sol.nfev = int(getattr(S, "nfev", 0))
        sol.njev = int(getattr(S, "njev", 0))

    complete_solution._instrumented = True
    Solver_ScipyRoot._complete_solution = complete_solution


def versions():
    import numba
    import scipy
    from importlib.metadata import version

    return {
        "pyharm-os": version("pyharm-os"),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
        "python": sys.version.split()[0],
    }


def analysis_options(f_lo_hz, f_hi_hz, ds, solver, reductor, max_points=None):
    """pyHarm FRF analysis: tangent predictor, arclength corrector, step halved on failure and
    doubled after 5 accepted steps (pyHarm's 'acceptance' rule), started at the lower bound.
    With `max_points` the sweep also stops after that many solutions (for the costly cases)."""
    opts = {
        "study": "frf",
        "puls_inf": 2.0 * np.pi * f_lo_hz,
        "puls_sup": 2.0 * np.pi * f_hi_hz,
        "ds0": ds,
        "ds_max": ds,
        "ds_min": 1e-6,
        "sign_ds": 1,
        "predictor": "tangent",
        "corrector": "arc_length",
        "stepsizer": "acceptance",
        "solver": solver,
        "verbose": False,
        "predictor_options": {"verbose": False},
    }
    if reductor == "NLdofs":
        opts["reductors"] = [{"type": "NLdofs"}]
    if max_points:
        opts["stopper"] = "solnumber"
        opts["stopper_options"] = {"max_solutions": max_points}
    return opts


def chain_input(name, mass, stiffness, damping, jenkins, force_dof, force, harmonics, samples, lc, wc, analysis):
    """pyHarm input for a linear model (dense M, K, D on one substructure, one DOF per node) with
    standalone Jenkins elements and a cosine force on one DOF.

    `jenkins` is a list of (dof_a, dof_b or None for the ground, k_J, F_c); pyHarm's Jenkins
    force is k_J (u_a - u_b - z) with the slider z moving when |k_J (u_a - u_b - z)| reaches
    mu N0 (here mu = 1, N0 = F_c).
    """
    connectors = {}
    for i, (a, b, k_j, f_c) in enumerate(jenkins):
        connect = {name: [a]} if b is None else [(name, [a]), (name, [b])]
        connectors[f"jenkins{i}"] = {"type": "Jenkins", "connect": connect, "dirs": [0], "mu": 1.0, "N0": f_c,
                                     "k": k_j}
    connectors["force"] = {"type": "CosinusForcing", "connect": {name: [force_dof]}, "dirs": [0], "amp": force}
    return {
        "export": {"status": False},
        "system": {"type": "Base", "nh": harmonics, "nti": samples, "adim": {"status": True, "lc": lc, "wc": wc}},
        "substructures": {
            name: {"type": "substructure", "ndofs": 1, "matrix": {"M": mass, "K": stiffness, "C": damping}}
        },
        "connectors": connectors,
        "analysis": {"frf": analysis},
    }


def run_once(inp):
    """Build the system and run the sweep once; return (setup s, sweep wall s, sweep CPU s, Maestro).

    The CPU time of the process is reported next to the wall time because the machine is shared:
    with one thread it equals the wall time on an idle machine and is much less disturbed by
    other processes."""
    from pyHarm.Maestro import Maestro

    t0 = time.perf_counter()
    maestro = Maestro(copy.deepcopy(inp))
    t1 = time.perf_counter()
    c1 = time.process_time()
    maestro.operate()
    t2 = time.perf_counter()
    c2 = time.process_time()
    return t1 - t0, t2 - t1, c2 - c1, maestro


def collect(maestro, out_dof_index, lc, wc):
    """Converged points of the sweep: frequency (Hz), amplitude of harmonic 1 of the output DOF
    (m), solver work and residual norm. Unknown ordering in pyHarm: harmonic blocks
    [h0 | h1 cos | h1 sin | ...], each over all DOFs, then Ω last; with adimensioning the
    unknowns are x / lc and Ω / wc."""
    analysis = next(iter(maestro.nls.values()))
    ndofs = maestro.system.ndofs // (2 * maestro.system.nh + 1)
    points = []
    rejected = 0
    for sol in analysis.SolList:
        if not sol.flag_accepted:
            rejected += 1
            continue
        x = sol.x
        c1 = x[ndofs + out_dof_index] * lc
        s1 = x[2 * ndofs + out_dof_index] * lc
        points.append(
            {
                "frequency_Hz": x[-1] * wc / (2.0 * np.pi),
                "amplitude_m": float(np.hypot(c1, s1)),
                "nfev": getattr(sol, "nfev", getattr(sol, "iter_numb", 0)),
                "njev": getattr(sol, "njev", getattr(sol, "iter_numb", 0)),
                "residual": float(np.linalg.norm(sol.R_solver)) if getattr(sol, "R_solver", None) is not None else 0.0,
            }
        )
    return points, rejected


def write_csv(path, points):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["frequency_Hz", "amplitude_m", "solver_residual_evals", "solver_jacobian_evals"])
        for p in points:
            w.writerow([f"{p['frequency_Hz']:.9e}", f"{p['amplitude_m']:.9e}", p["nfev"], p["njev"]])


def parser(description, default_csv, default_ds, default_reductor="noreductor"):
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--runs", type=int, default=5, help="timed runs after the warm-up (median reported)")
    p.add_argument("--ds", type=float, default=default_ds, help="arclength step (adimensional), sets the point density")
    p.add_argument(
        "--solver", default="scipyroot", choices=["scipyroot", "NewtonRaphson"], help="pyHarm nonlinear solver"
    )
    p.add_argument(
        "--reductor", default=default_reductor, choices=["noreductor", "NLdofs"], help="NLdofs = condensation"
    )
    p.add_argument("--csv", default=default_csv, help="FRF output file")
    p.add_argument("--no-warmup", action="store_true", help="skip the untimed warm-up run")
    p.add_argument("--max-points", type=int, default=None, help="stop the sweep after this many solutions")
    return p


def main(args, label, inp, out_dof_index, f_band_hz, lc, wc, warmup_inp=None):
    """Warm up (numba JIT of pyHarm's kernels), then time `args.runs` sweeps and report."""
    _quiet()
    import pyHarm  # noqa: F401  (import cost is not part of any timing)

    _instrument_solvers()
    v = versions()
    print(f"# {label}")
    print("# " + ", ".join(f"{k} {val}" for k, val in v.items()))
    print(
        f"# threads: OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}, "
        f"affinity {sorted(os.sched_getaffinity(0))}"
    )
    print(f"# solver {args.solver}, reductor {args.reductor}, ds {args.ds}")
    if not args.no_warmup:
        t = time.perf_counter()
        run_once(warmup_inp if warmup_inp is not None else inp)  # same kernels, so numba compiles them here
        print(f"warm-up run: {time.perf_counter() - t:.2f} s (includes numba compilation)")
    sweeps, cpus, setups = [], [], []
    maestro = None
    for r in range(args.runs):
        setup, sweep, cpu, maestro = run_once(inp)
        setups.append(setup)
        sweeps.append(sweep)
        cpus.append(cpu)
        print(
            f"run {r + 1}: sweep {sweep:.3f} s wall, {cpu:.3f} s CPU (setup {setup * 1e3:.1f} ms), "
            f"load average {os.getloadavg()[0]:.2f}",
            flush=True,
        )
    points, rejected = collect(maestro, out_dof_index, lc, wc)
    write_csv(args.csv, points)
    n = len(points)
    med = statistics.median(sweeps)
    freqs = np.array([p["frequency_Hz"] for p in points])
    amps = np.array([p["amplitude_m"] for p in points])
    df = np.abs(np.diff(freqs))
    ipk = int(np.argmax(amps))
    nfev = np.array([p["nfev"] for p in points[1:]])  # point 0 is the linear start, not a continuation step
    njev = np.array([p["njev"] for p in points[1:]])
    band = f_band_hz[1] - f_band_hz[0]
    print(f"converged points: {n} (rejected steps: {rejected})")
    print(f"sweep wall time, median of {len(sweeps)}: {med:.3f} s (min {min(sweeps):.3f}, max {max(sweeps):.3f})")
    print(f"sweep CPU time, median of {len(cpus)}: {statistics.median(cpus):.3f} s")
    print(f"setup (system build) median: {statistics.median(setups) * 1e3:.1f} ms")
    print(
        f"time per converged point: {med / n * 1e3:.2f} ms wall, {statistics.median(cpus) / n * 1e3:.2f} ms CPU"
    )
    print(
        f"solver work per point: {nfev.mean():.2f} residual evals, {njev.mean():.2f} Jacobian evals "
        f"(median {np.median(nfev):.0f} / {np.median(njev):.0f}, max {nfev.max()} / {njev.max()})"
    )
    print(
        f"point density: {n / band:.3f} points/Hz over {f_band_hz[0]:g}-{f_band_hz[1]:g} Hz; "
        f"frequency step min {df.min():.4g} Hz, median {np.median(df):.4g} Hz, max {df.max():.4g} Hz"
    )
    covered = freqs.max() - freqs.min()
    print(f"covered: {freqs.min():.4f}-{freqs.max():.4f} Hz, {n / covered:.3f} points/Hz over the covered range")
    print(f"peak: {freqs[ipk]:.4f} Hz, amplitude {amps[ipk]:.6e} m")
    print(f"max solver residual norm (adimensional): {max(p['residual'] for p in points):.2e}")
    print(f"FRF written to {args.csv}")
    return maestro
