"""pyHarm peer measurement: the 2-D contact case (studies/contact2d.toml).

The 2-DOF model of crates/core/tests/timesim_contact.rs: a tangential DOF x and a normal DOF y
(1 kg and 1e6 N/m to the ground each, 20 N.s/m dashpots), tied to the ground by a point contact
(tangential spring k_t = 5e5 N/m in series with a Coulomb slider of threshold mu N(t), mu = 0.4,
N(t) = N0 + k_n (pressing motion), N0 = 50 N, k_n = 2e6 N/m). Forces in phase, 40 N on x and
15 N on y (the contact stays closed, see README.md). N = 7 harmonics, 300 time samples, sweep
150-230 Hz upwards.

pyHarm's element for this law is Penalty3D (PenaltyUnilateralGap on the normal direction and
Jenkins on two tangential directions, with the Jenkins threshold mu |f_n - N0| following the
normal force). It is three-dimensional, so the node has a third, unforced DOF z (same mass,
spring and dashpot as x) as the second tangential direction; z stays at zero. pyHarm's normal
direction is positive when the contact opens (contact while u_n <= N0 / k_n), stickslip's when
it presses, so pyHarm's y is minus stickslip's and its y force is -15 N (the same motion;
harmonic amplitudes are unchanged).

Run: OMP_NUM_THREADS=1 taskset -c 0 /tmp/pyharm-venv/bin/python bench/peer/pyharm_contact.py
"""

import os

import numpy as np

from pyharm_common import analysis_options, collect, main, parser, write_csv

HERE = os.path.dirname(os.path.abspath(__file__))

MASS = 1.0  # kg, each DOF
K_GROUND = 1.0e6  # N/m, each DOF to the ground
DAMPING = 20.0  # N.s/m, each DOF
K_T = 5.0e5  # N/m, tangential contact stiffness
K_N = 2.0e6  # N/m, normal contact stiffness
MU = 0.4
N0 = 50.0  # N, normal preload
F_X = 40.0  # N, on x
F_Y = 15.0  # N, on y (pressing direction in stickslip's sign)
HARMONICS = 7
SAMPLES = 300
BAND_HZ = (150.0, 230.0)
LC = 1e-4  # m, adimensioning length (x amplitude scale; N0 / k_n = 2.5e-5 m, slip onset mu N0 / k_t = 4e-5 m)
WC = 2.0 * np.pi * 195.0  # rad/s, stuck tangential mode


def matrices(cells):
    """M, K, D of `cells` nodes of 3 components (x, y, z), node-major: each DOF has its mass,
    spring to the ground and dashpot; with several cells, springs K_GROUND join the same component
    of neighbouring nodes (a chain)."""
    n = 3 * cells
    m = MASS * np.eye(n)
    k = K_GROUND * np.eye(n)
    for i in range(cells - 1):
        for c in range(3):
            a, b = 3 * i + c, 3 * (i + 1) + c
            k[np.ix_([a, b], [a, b])] += K_GROUND * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return m, k, DAMPING * np.eye(n)


def system_input(band_hz, ds, solver, reductor, max_points=None, f_y=F_Y, cells=1):
    # Node i, components 0 = x (tangential), 1 = y (normal), 2 = z (second tangential, unforced).
    m, k, d = matrices(cells)
    connectors = {}
    for i in range(cells):
        # Against the ground; dirs[0] is the normal, dirs[1:] the tangential directions.
        connectors[f"contact{i}"] = {"type": "Penalty3D", "connect": {"body": [i]}, "dirs": [1, 0, 2], "mu": MU,
                                     "N0": N0, "k_n": K_N, "k_t": K_T, "g": 0.0}
        connectors[f"force_x{i}"] = {"type": "CosinusForcing", "connect": {"body": [i]}, "dirs": [0], "amp": F_X}
        connectors[f"force_y{i}"] = {"type": "CosinusForcing", "connect": {"body": [i]}, "dirs": [1], "amp": -f_y}
    return {
        "export": {"status": False},
        "system": {"type": "Base", "nh": HARMONICS, "nti": SAMPLES, "adim": {"status": True, "lc": LC, "wc": WC}},
        "substructures": {"body": {"type": "substructure", "ndofs": 3, "matrix": {"M": m, "K": k, "C": d}}},
        "connectors": connectors,
        "analysis": {"frf": analysis_options(band_hz[0], band_hz[1], ds, solver, reductor, max_points)},
    }


def write_study(path, cells, f_y=F_Y):
    """The same chain as a stickslip study (x and y of each cell; z is pyHarm's unforced third
    component and is left out)."""
    dofs = [f"{c}{i}" for i in range(cells) for c in "xy"]
    n = len(dofs)
    k = K_GROUND * np.eye(n)
    for i in range(cells - 1):
        for c in range(2):
            a, b = 2 * i + c, 2 * (i + 1) + c
            k[np.ix_([a, b], [a, b])] += K_GROUND * np.array([[1.0, -1.0], [-1.0, 1.0]])
    rows = ",\n    ".join("[" + ", ".join(f"{v:.1f}" for v in row) + "]" for row in k)
    lines = [
        f"# {cells} cells of the 2-D contact case (studies/contact2d.toml) in a chain: springs of",
        "# 1e6 N/m join the x DOFs and the y DOFs of neighbouring cells; every cell has its contact",
        "# and its forces. Written by pyharm_contact.py --cells N --write-study.",
        "[model]",
        "dofs = [" + ", ".join(f'"{d}"' for d in dofs) + "]",
        f"mass = [{', '.join(['1.0'] * n)}]",
        f"stiffness = [\n    {rows}]",
        "",
        "[damping]",
        f"alpha = {DAMPING / MASS}",
        "",
        "[[load]]",
        'name = "shaker"',
        "values = [" + ", ".join(f"{F_X if c == 'x' else f_y}" for i in range(cells) for c in "xy") + "]",
        "",
    ]
    for i in range(cells):
        lines += [
            "[[joint]]",
            f'name = "contact{i}"',
            'law = "contact2d"',
            f'tangential = [["x{i}"]]',
            f'normal = ["y{i}"]',
            f"preload = {N0}",
            f"normal_stiffness = {K_N}",
            f"tangential_stiffness = {K_T}",
            f"friction = {MU}",
            "",
        ]
    lines += [
        "[excitation]", 'load = "shaker"', "levels = [1.0]", "",
        "[sweep]", f"start_hz = {BAND_HZ[0]}", f"end_hz = {BAND_HZ[1]}", "",
        "[harmonic_balance]", f"harmonics = {HARMONICS}", f"samples = {SAMPLES}", "",
        "[[output]]", 'name = "x"', 'dof = "x0"', "",
        "[[output]]", 'name = "y"', 'dof = "y0"', "",
    ]
    with open(path, "w") as f:
        f.write("\n".join(lines))


if __name__ == "__main__":
    p = parser(
        "pyHarm sweep of the 2-D contact case",
        os.path.join(HERE, "results", "pyharm_contact_frf_x.csv"),
        default_ds=0.2,
    )
    p.add_argument("--csv-y", default=None, help="FRF of y (default: the x file with _x -> _y)")
    p.add_argument("--force-y", type=float, default=F_Y, help="force on y, N (60 opens the contact)")
    p.add_argument("--band", type=float, nargs=2, default=BAND_HZ, metavar=("LO", "HI"))
    p.add_argument("--cells", type=int, default=1, help="cells in a chain (q = 2 cells contact directions)")
    p.add_argument("--write-study", default=None, help="write the stickslip study of this model and stop")
    args = p.parse_args()
    if args.write_study:
        write_study(args.write_study, args.cells, args.force_y)
        raise SystemExit(0)
    inp = system_input(tuple(args.band), args.ds, args.solver, args.reductor, args.max_points, args.force_y,
                       args.cells)
    maestro = main(args, f"2-D contact (Penalty3D), {args.cells} cell(s), F_y = {args.force_y:g} N, N = 7, 300 samples, "
                   f"{args.band[0]:g}-{args.band[1]:g} Hz", inp, 0, tuple(args.band), LC, WC)
    points, _ = collect(maestro, 1, LC, WC)
    csv_y = args.csv_y or args.csv.replace("_x", "_y")
    write_csv(csv_y, points)
    print(f"FRF of y written to {csv_y}")
