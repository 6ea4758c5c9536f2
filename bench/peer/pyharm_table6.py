"""pyHarm peer measurement: the Table 6 1-DOF Jenkins oscillator (shared/reference/table6-jenkins.toml).

Mass M on a damper d and a linear spring (k - k_jenkins) to ground, in parallel with a standalone
Jenkins element to ground (spring k_jenkins in series with a Coulomb slider of threshold F_c), so
the stuck stiffness is k. Force F cos(Ωt) on the mass. N = 7 harmonics, 300 time samples,
sweep 150-350 Hz upwards.

Run: OMP_NUM_THREADS=1 taskset -c 0 /tmp/pyharm-venv/bin/python bench/peer/pyharm_table6.py
"""

import os

import numpy as np

from pyharm_common import analysis_options, main, parser

HERE = os.path.dirname(os.path.abspath(__file__))

# Table 6 (SI units).
MASS = 10.0  # kg
K_TOTAL = 2.24e7  # N/m, total stuck stiffness
K_JENKINS = 8.11e6  # N/m
DAMPING = 350.0  # N.s/m
F_COULOMB = 1000.0  # N
F_EXCIT = 1000.0  # N
HARMONICS = 7
SAMPLES = 300
BAND_HZ = (150.0, 350.0)
# Adimensioning used by pyHarm's continuation (unknowns x / LC, Ω / WC): slip onset amplitude
# F_c / k_jenkins ≈ 1.2e-4 m and the stuck natural frequency ≈ 238 Hz.
LC = 1e-4
WC = 2.0 * np.pi * 238.0


def system_input(band_hz, ds, solver, reductor, max_points=None):
    return {
        "export": {"status": False},
        "system": {
            "type": "Base",
            "nh": HARMONICS,
            "nti": SAMPLES,
            "adim": {"status": True, "lc": LC, "wc": WC},
        },
        "substructures": {
            "mass": {
                "type": "substructure",
                "ndofs": 1,
                "matrix": {
                    "M": np.array([[MASS]]),
                    "K": np.array([[K_TOTAL - K_JENKINS]]),
                    "C": np.array([[DAMPING]]),
                },
            }
        },
        "connectors": {
            # Legacy single-entry `connect` = between node 0 of "mass" and the ground.
            "jenkins": {"type": "Jenkins", "connect": {"mass": [0]}, "dirs": [0], "mu": 1.0, "N0": F_COULOMB,
                        "k": K_JENKINS},
            "force": {"type": "CosinusForcing", "connect": {"mass": [0]}, "dirs": [0], "amp": F_EXCIT},
        },
        "analysis": {"frf": analysis_options(band_hz[0], band_hz[1], ds, solver, reductor, max_points)},
    }


if __name__ == "__main__":
    args = parser(
        "pyHarm sweep of the Table 6 1-DOF Jenkins oscillator",
        os.path.join(HERE, "results", "pyharm_table6_frf.csv"),
        default_ds=0.02,
    ).parse_args()
    inp = system_input(BAND_HZ, args.ds, args.solver, args.reductor, args.max_points)
    main(args, "Table 6 1-DOF Jenkins, N = 7, 300 samples, 150-350 Hz", inp, 0, BAND_HZ, LC, WC)
