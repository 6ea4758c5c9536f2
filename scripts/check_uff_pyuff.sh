#!/bin/sh
# UFF 58 files written by stickslip (ASCII and binary, real and complex, even and uneven, single
# and double) read back by pyuff 2.5.8. Needs python3 with venv and network access to PyPI.
set -eu
cd "$(dirname "$0")/.."
venv="${PYUFF_VENV:-target/pyuff-venv}"
out="$PWD/target/uff-pyuff-check"
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install --quiet 'pyuff==2.5.8'
rm -rf "$out" && mkdir -p "$out"
STICKSLIP_UFF_OUT="$out" cargo test --quiet -p stickslip-io --test uff_roundtrip written_files
"$venv/bin/python" scripts/check_uff_pyuff.py "$out"
