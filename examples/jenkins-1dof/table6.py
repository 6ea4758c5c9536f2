"""The Table 6 study (paper Section 4.4, Fig. 15a) redone from Python, then a parameter study
of the friction threshold and the damping on it.

    pip install ./crates/python pandas          # once, from the repository's root
    python examples/jenkins-1dof/table6.py      # about a second per sweep set

The 1-DOF friction oscillator: M = 10 kg on k = 2.24e7 N/m, of which k_J = 8.11e6 N/m is a
Jenkins element of threshold F_c = 1000 N; D = 35 M. Stuck it resonates at
sqrt(k/M)/2π = 238.2 Hz, fully slipping at sqrt((k - k_J)/M)/2π = 190.3 Hz.
"""

import math
import pathlib

import stickslip

HERE = pathlib.Path(__file__).resolve().parent


def main():
    # 1. The study as written in study.toml, run at its four force levels.
    study = stickslip.Study.from_toml(HERE / "study.toml")
    results = study.run()
    frame = results.to_pandas()
    print(f"{len(frame)} converged points over levels {study.levels} N")
    print(f"stuck resonance {math.sqrt(2.24e7 / 10) / (2 * math.pi):.1f} Hz, "
          f"slipping resonance {math.sqrt((2.24e7 - 8.11e6) / 10) / (2 * math.pi):.1f} Hz")
    for level, points in frame.groupby("level_N"):
        peak = points.loc[points["mass_h1_amp_m"].idxmax()]
        print(f"  {level:7.0f} N: peak {peak['mass_h1_amp_m']:.3e} m at {peak['frequency_Hz']:.1f} Hz, "
              f"joint dissipates {peak['joint_energy_J']:.3e} J/cycle, stuck {peak['joint_stick_fraction']:.0%} of the period")

    # 2. The same study built from a dict (here: the file's, at the paper's 1000 N only).
    d = study.to_dict()
    d["excitation"]["levels"] = [1000.0]
    paper_level = stickslip.Study.from_dict(d, study.path)

    # 3. A seeded Latin hypercube over the threshold and the damping: 40 sweeps, two local
    #    processes (scheduler="dask" runs them on a dask.distributed cluster instead).
    table = stickslip.run_parameters(
        paper_level,
        {"joint.joint.threshold": (500.0, 2000.0), "damping.alpha": (20.0, 50.0)},
        samples=40, seed=1, scheduler="processes", workers=2,
    ).to_pandas()
    print(table[["joint.joint.threshold", "damping.alpha", "peak_frequency_Hz", "peak_amplitude_m",
                 "peak_energy_J"]].describe().loc[["min", "mean", "max"]].to_string())


# Local processes start fresh interpreters that import this file: the work runs only when it
# is the program.
if __name__ == "__main__":
    main()
