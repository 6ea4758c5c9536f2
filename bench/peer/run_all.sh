#!/usr/bin/env bash
# Runs every pyHarm peer measurement and keeps the printed reports in results/.
# Needs pyHarm in a throwaway virtualenv (not a project dependency):
#   python3 -m venv /tmp/pyharm-venv && /tmp/pyharm-venv/bin/pip install pyharm-os==1.2.2
# Usage: bash bench/peer/run_all.sh [PYTHON]   (about 90 minutes on the loaded 2-core machine)
set -euo pipefail
cd "$(dirname "$0")"
PY=${1:-/tmp/pyharm-venv/bin/python}
ONE="env OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 taskset -c 0"
mkdir -p results

# Table 6 1-DOF, 150-350 Hz: one core, then the default (all cores, default BLAS threads).
$ONE "$PY" pyharm_table6.py > results/table6_one_core.txt
"$PY" pyharm_table6.py --csv /tmp/pyharm_table6_default.csv > results/table6_default_threads.txt
# Same sweep with pyHarm's plain Newton-Raphson solver (iterations = Newton iterations).
$ONE "$PY" pyharm_table6.py --solver NewtonRaphson --csv results/pyharm_table6_newton_frf.csv \
    > results/table6_one_core_newton.txt
# Coarser steps: about the number of points of stickslip's default steps.
$ONE "$PY" pyharm_table6.py --ds 0.2 --csv results/pyharm_table6_frf_ds0.2.csv > results/table6_one_core_ds0.2.txt

# 10-DOF chain, 20-35 Hz: full harmonic system and pyHarm's condensation onto the Jenkins DOFs.
$ONE "$PY" pyharm_chain.py > results/chain_one_core.txt
$ONE "$PY" pyharm_chain.py --reductor NLdofs --csv /tmp/pyharm_chain_condensed.csv \
    > results/chain_one_core_condensed.txt
"$PY" pyharm_chain.py --runs 3 --csv /tmp/pyharm_chain_default.csv > results/chain_default_threads.txt
for ds in 0.1 0.2; do
    $ONE "$PY" pyharm_chain.py --ds $ds --csv results/pyharm_chain_frf_ds$ds.csv > results/chain_one_core_ds$ds.txt
done

# 137 DOFs: a sweep at ds = 0.2 takes hours, so time the first 10 continuation points, once, from the
# band's lower end (stuck) and from 200 Hz (slipping, near the peak).
$ONE "$PY" pyharm_paper.py --runs 1 --ds 0.2 --max-points 10 \
    > results/paper_one_core_from170.txt
$ONE "$PY" pyharm_paper.py --runs 1 --ds 0.2 --max-points 10 --band 200 300 \
    --csv results/pyharm_paper_frf_from200.csv > results/paper_one_core_from200.txt
$ONE "$PY" pyharm_paper.py --runs 1 --ds 0.2 --max-points 5 --band 200 300 --reductor NLdofs \
    --csv /tmp/pyharm_paper_condensed.csv > results/paper_one_core_from200_condensed.txt
# One whole 137-DOF sweep at a coarse density (64 points, about 25 min).
$ONE "$PY" pyharm_paper.py --runs 1 --ds 2.0 --csv results/pyharm_paper_frf_ds2.csv > results/paper_one_core_ds2.txt

# 2-D contact (Penalty3D against stickslip's contact2d), needs the release binary
# (cargo build --release -p stickslip-cli). Dense reference FRF, then interleaved timings.
$ONE "$PY" pyharm_contact.py --runs 1 --no-warmup --ds 0.005 --csv results/pyharm_contact_frf_dense_x.csv \
    > results/contact_one_core_dense.txt
SS=../../target/release/stickslip
$ONE "$PY" time_contact.py --stickslip $SS --study studies/contact2d.toml --ds 0.7 > results/contact_interleaved_ds0.7.txt
$ONE "$PY" time_contact.py --stickslip $SS --study studies/contact2d_dense.toml --ds 0.2 \
    > results/contact_interleaved_ds0.2.txt
for c in 2 4 8; do
    ds=$(python3 -c "print(round(0.7 * $c ** 0.5, 2))")
    $ONE "$PY" time_contact.py --stickslip $SS --study studies/contact2d_chain$c.toml --cells $c --ds $ds \
        > results/contact_chain${c}_interleaved.txt
done
# pyHarm's cost per residual and Jacobian evaluation against the number of contacts.
$ONE "$PY" pyharm_contact_evals.py --cells 1 2 4 8 > results/contact_evals_one_core.txt
# The opening case (60 N on y): pyHarm's Penalty3D stops after the first points.
$ONE "$PY" pyharm_contact.py --runs 1 --no-warmup --force-y 60 --ds 0.02 --max-points 40 \
    --csv /tmp/pyharm_contact_open_x.csv > results/contact_open_one_core.txt || true
