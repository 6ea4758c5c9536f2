"""Compare a stickslip FRF (frf.csv of `stickslip run`) with a pyHarm FRF CSV of this folder.

pyHarm's points are denser, so its curve is interpolated (linearly in frequency, along its
upward sweep) at stickslip's frequencies; the relative amplitude differences and both discrete
peaks are printed. Near a sharp stick-slip transition the interpolation error of pyHarm's own
points dominates the maximum.

Usage: /tmp/pyharm-venv/bin/python compare_frf.py OUT/frf.csv OUTPUT_NAME results/pyharm_table6_frf.csv
"""

import csv
import sys

import numpy as np


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows


def main(stickslip_csv, output, pyharm_csv):
    s = read(stickslip_csv)
    p = read(pyharm_csv)
    fs = np.array([float(r["frequency_Hz"]) for r in s])
    as_ = np.array([float(r[f"{output}_h1_amp_m"]) for r in s])
    fp = np.array([float(r["frequency_Hz"]) for r in p])
    ap = np.array([float(r["amplitude_m"]) for r in p])
    if np.any(np.diff(fp) <= 0):
        sys.exit("pyHarm curve is not monotonic in frequency (a fold): compare by hand")
    inside = (fs >= fp.min()) & (fs <= fp.max())
    rel = np.abs(np.interp(fs[inside], fp, ap) - as_[inside]) / as_[inside]
    i, j = int(np.argmax(as_)), int(np.argmax(ap))
    print(f"stickslip: {len(fs)} points, peak {fs[i]:.4f} Hz {as_[i]:.6e} m")
    print(f"pyHarm:    {len(fp)} points, peak {fp[j]:.4f} Hz {ap[j]:.6e} m")
    print(f"relative amplitude difference at {inside.sum()} stickslip points: "
          f"median {np.median(rel):.2e}, max {rel.max():.2e} at {fs[inside][np.argmax(rel)]:.3f} Hz")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
