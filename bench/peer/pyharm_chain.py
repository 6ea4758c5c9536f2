"""pyHarm peer measurement: a 10-DOF spring-mass chain with 4 Jenkins elements.

Chain: 10 masses of 1 kg (DOF 0..9), linear springs k = 1e6 N/m from the ground to DOF 0 and
between neighbours i, i+1. Four standalone Jenkins elements (k_J = 1e6 N/m, F_c = 50 N), each in
parallel with the linear spring of the links 0-1, 1-2, 2-3, 3-4 (the links of largest strain in the
first mode). Rayleigh damping D = alpha M + beta K with K the linear chain stiffness (Jenkins
elements excluded). Force 10 N cos(Ωt) on DOF 9, output DOF 9. First mode: 23.79 Hz all slipping,
28.42 Hz all stuck; the Jenkins elements stick below about 50 N / 1e6 N/m = 50 µm of relative
motion and slip near resonance (stuck linear peak: ~500 µm across each link).
N = 7 harmonics, 300 time samples, sweep 20-35 Hz upwards.

Run: OMP_NUM_THREADS=1 taskset -c 0 /tmp/pyharm-venv/bin/python bench/peer/pyharm_chain.py
"""

import os

import numpy as np

from pyharm_common import analysis_options, chain_input, main, parser

HERE = os.path.dirname(os.path.abspath(__file__))

N_DOF = 10
MASS = 1.0  # kg per DOF
K_LINK = 1.0e6  # N/m, ground-0 and each i-(i+1)
K_JENKINS = 1.0e6  # N/m
F_COULOMB = 50.0  # N
JENKINS_LINKS = [(0, 1), (1, 2), (2, 3), (3, 4)]
ALPHA = 2.0  # 1/s
BETA = 1.0e-5  # s
FORCE_DOF = 9
F_EXCIT = 10.0  # N
HARMONICS = 7
SAMPLES = 300
BAND_HZ = (20.0, 35.0)
LC = 1e-3  # m, adimensioning length (tip amplitude scale)
WC = 2.0 * np.pi * 26.0  # rad/s, adimensioning frequency (first mode)


def matrices():
    m = MASS * np.eye(N_DOF)
    k = np.zeros((N_DOF, N_DOF))
    k[0, 0] += K_LINK
    for i in range(N_DOF - 1):
        k[i : i + 2, i : i + 2] += K_LINK * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return m, k, ALPHA * m + BETA * k


def system_input(band_hz, ds, solver, reductor, max_points=None):
    m, k, d = matrices()
    jenkins = [(a, b, K_JENKINS, F_COULOMB) for a, b in JENKINS_LINKS]
    return chain_input(
        "chain", m, k, d, jenkins, FORCE_DOF, F_EXCIT, HARMONICS, SAMPLES, LC, WC,
        analysis_options(band_hz[0], band_hz[1], ds, solver, reductor, max_points),
    )


if __name__ == "__main__":
    args = parser(
        "pyHarm sweep of a 10-DOF chain with 4 Jenkins elements",
        os.path.join(HERE, "results", "pyharm_chain_frf.csv"),
        default_ds=0.02,
    ).parse_args()
    inp = system_input(BAND_HZ, args.ds, args.solver, args.reductor, args.max_points)
    main(args, "10-DOF chain, 4 Jenkins, N = 7, 300 samples, 20-35 Hz", inp, FORCE_DOF, BAND_HZ, LC, WC)
