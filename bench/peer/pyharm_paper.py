"""pyHarm peer measurement at the paper's size: 137 DOFs, 4 Jenkins elements, N = 7, 300 samples.

A stand-in for the Harmony model near its first mode (the paper's reduced model is not public):
a free-free chain of 137 equal masses (total 10 kg, as Table 6's M) joined by springs
k_c = 1e9 N/m, held to the ground at 4 contact DOFs (0, 45, 91, 136). Each contact carries a
quarter of Table 6's support: a linear spring (k - k_jenkins)/4 and a standalone Jenkins element
to the ground with k_jenkins/4 and F_c/4. Damping D = alpha M with alpha = d / M = 35 1/s (the
paper's D = alpha M). Force 1000 N cos(Ωt) on DOF 60 (off-centre, so the four contacts move
differently), output DOF 60. First mode 233.5 Hz all stuck, 187.8 Hz all slipping; the next mode
is above 476 Hz, so the FRF is close to Table 6's 1-DOF one. Sweep 170-300 Hz upwards.

Run: OMP_NUM_THREADS=1 taskset -c 0 /tmp/pyharm-venv/bin/python bench/peer/pyharm_paper.py
"""

import os

import numpy as np

from pyharm_common import analysis_options, chain_input, main, parser

HERE = os.path.dirname(os.path.abspath(__file__))

N_DOF = 137
TOTAL_MASS = 10.0  # kg
K_CHAIN = 1.0e9  # N/m between neighbours
CONTACTS = [0, 45, 91, 136]
K_TOTAL = 2.24e7  # N/m, Table 6 stuck support stiffness, shared by the 4 contacts
K_JENKINS = 8.11e6  # N/m, Table 6, shared by the 4 contacts
F_COULOMB = 1000.0  # N, Table 6, shared by the 4 contacts
ALPHA = 35.0  # 1/s, D = ALPHA M
FORCE_DOF = 60
F_EXCIT = 1000.0  # N
HARMONICS = 7
SAMPLES = 300
BAND_HZ = (170.0, 300.0)
LC = 1e-4  # m
WC = 2.0 * np.pi * 238.0  # rad/s


def matrices():
    m = (TOTAL_MASS / N_DOF) * np.eye(N_DOF)
    k = np.zeros((N_DOF, N_DOF))
    for i in range(N_DOF - 1):
        k[i : i + 2, i : i + 2] += K_CHAIN * np.array([[1.0, -1.0], [-1.0, 1.0]])
    for c in CONTACTS:
        k[c, c] += (K_TOTAL - K_JENKINS) / len(CONTACTS)
    return m, k, ALPHA * m


def write_study(folder):
    """Write the same model as a stickslip study (Matrix Market M and K, DOF names, study.toml),
    so that both codes run the identical case."""
    os.makedirs(folder, exist_ok=True)
    m, k, _ = matrices()
    for name, a in (("mass.mtx", m), ("stiffness.mtx", k)):
        rows = [(i, j, a[i, j]) for j in range(N_DOF) for i in range(j, N_DOF) if a[i, j] != 0.0]
        with open(os.path.join(folder, name), "w") as f:
            f.write("%%MatrixMarket matrix coordinate real symmetric\n")
            f.write(f"{N_DOF} {N_DOF} {len(rows)}\n")
            f.writelines(f"{i + 1} {j + 1} {v:.17g}\n" for i, j, v in rows)
    with open(os.path.join(folder, "dofs.txt"), "w") as f:
        f.writelines(f"u{i}\n" for i in range(N_DOF))
    n = len(CONTACTS)
    joints = "".join(
        f'''
[[joint]]
name = "contact{c}"
law = "jenkins"
dof = "u{c}"                # between u{c} and the ground
stiffness = {K_JENKINS / n!r}    # N/m, k_jenkins / 4
replaces_stiffness = false  # in parallel with K, which holds (k - k_jenkins) / 4 here
threshold = {F_COULOMB / n!r}       # N, F_c / 4
'''
        for c in CONTACTS
    )
    study = f'''# 137-DOF stand-in for the paper-size case, as timed with pyHarm (bench/peer/pyharm_paper.py).
[model]
mass_file = "mass.mtx"
stiffness_file = "stiffness.mtx"
dof_file = "dofs.txt"

[damping]
alpha = {ALPHA!r}               # 1/s, D = alpha M

[[load]]
name = "force"
dof = "u{FORCE_DOF}"
{joints}
[excitation]
load = "force"
levels = [{F_EXCIT!r}]

[sweep]
start_hz = {BAND_HZ[0]!r}
end_hz = {BAND_HZ[1]!r}

[harmonic_balance]
harmonics = {HARMONICS}
samples = {SAMPLES}

[[output]]
name = "forced"
dof = "u{FORCE_DOF}"
'''
    with open(os.path.join(folder, "study.toml"), "w") as f:
        f.write(study)


def system_input(band_hz, ds, solver, reductor, max_points=None):
    m, k, d = matrices()
    n = len(CONTACTS)
    jenkins = [(c, None, K_JENKINS / n, F_COULOMB / n) for c in CONTACTS]
    return chain_input(
        "chain", m, k, d, jenkins, FORCE_DOF, F_EXCIT, HARMONICS, SAMPLES, LC, WC,
        analysis_options(band_hz[0], band_hz[1], ds, solver, reductor, max_points),
    )


if __name__ == "__main__":
    p = parser(
        "pyHarm sweep at the paper's size: 137 DOFs, 4 Jenkins elements",
        os.path.join(HERE, "results", "pyharm_paper_frf.csv"),
        default_ds=0.02,
        default_reductor="noreductor",
    )
    p.add_argument("--band", type=float, nargs=2, default=list(BAND_HZ), help="sweep band, Hz")
    p.add_argument("--write-study", metavar="DIR", help="only write the model as a stickslip study into DIR")
    args = p.parse_args()
    if args.write_study:
        write_study(args.write_study)
        raise SystemExit(0)
    band = tuple(args.band)
    inp = system_input(band, args.ds, args.solver, args.reductor, args.max_points)
    # Warm-up on 3 solutions: it compiles the same numba kernels at a fraction of a full sweep.
    warm = system_input((band[0], band[0] + 1.0), args.ds, args.solver, args.reductor, 3)
    main(args, f"137-DOF chain, 4 Jenkins, N = 7, 300 samples, {band[0]:g}-{band[1]:g} Hz", inp, FORCE_DOF, band,
         LC, WC, warmup_inp=warm)
