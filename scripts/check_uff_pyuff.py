#!/usr/bin/env python3
"""Read the UFF 58 files written by stickslip with pyuff (the reference implementation) and
compare with what stickslip wrote (DIR/expected.csv, written by the uff_roundtrip test).

Usage: check_uff_pyuff.py DIR        (exit status 1 on any mismatch)

Both sides parse the same decimal text or the same binary floats, and compute even abscissas as
min + i * increment, so values agree to rounding of the sum: 1e-12 relative to sum(|data|).
"""
import csv
import sys
from pathlib import Path

import numpy as np
import pyuff


def main(directory: Path) -> int:
    failures = 0
    rows = list(csv.DictReader(open(directory / "expected.csv")))
    for row in rows:
        name = row["file"]
        sets = pyuff.UFF(str(directory / name)).read_sets()
        d = sets if isinstance(sets, dict) else sets[0]
        data = np.asarray(d["data"])
        x = np.asarray(d["x"])
        expect_binary = int(row["binary"])
        checks = []
        checks.append(("type", d["type"] == 58))
        checks.append(("binary", int(d.get("binary", 0)) == expect_binary))
        single = row["precision"] == "single"
        checks.append(("ord_data_type", d["ord_data_type"] in ((2, 5) if single else (4, 6))))
        n = int(row["num_pts"])
        checks.append(("num_pts", d["num_pts"] == n and len(data) == n and len(x) == n))
        scale = max(float(np.sum(np.abs(data))), 1e-300)

        def near(a, b, s=scale):
            return abs(a - b) <= 1e-12 * s

        xs = max(abs(float(row["x_last"])), 1e-300)
        checks.append(("x[0]", near(float(x[0]), float(row["x_first"]), xs)))
        checks.append(("x[-1]", near(float(x[-1]), float(row["x_last"]), xs)))
        first = complex(float(row["first_re"]), float(row["first_im"]))
        last = complex(float(row["last_re"]), float(row["last_im"]))
        total = complex(float(row["sum_re"]), float(row["sum_im"]))
        checks.append(("data[0]", abs(complex(data[0]) - first) <= 1e-12 * scale))
        checks.append(("data[-1]", abs(complex(data[-1]) - last) <= 1e-12 * scale))
        checks.append(("sum(data)", abs(complex(np.sum(data)) - total) <= 1e-12 * scale))
        bad = [c for c, ok in checks if not ok]
        if bad:
            failures += 1
            print(f"FAIL {name}: {', '.join(bad)} (pyuff: num_pts={d['num_pts']} x0={x[0]} x-1={x[-1]} "
                  f"first={data[0]} last={data[-1]} sum={np.sum(data)})")
        else:
            print(f"ok   {name}: {n} points")
    print(f"{len(rows) - failures}/{len(rows)} files read by pyuff {pyuff.__version__} as written")
    return 1 if failures or not rows else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__)
        sys.exit(2)
    sys.exit(main(Path(sys.argv[1])))
