#!/usr/bin/env bash
# The paper's shaker test (Sections 2.4 and 5.1), done on the model and processed as the real
# one: swept-sine time integration of the Harmony study at the four test levels (10 Hz/s, and
# 1 Hz/s over 180-250 Hz where friction acts), written as UFF 58 records of what the test
# system recorded (the shaker's drive signal and noisy accelerations, low-passed and sampled
# as a data acquisition system does); then stickslip's own measurement chain: harmonics and
# FRFs by `extract`, the force level identified at 100 Hz by Eq. 1 against the 70 N record,
# and `compare` against the harmonic balance, which becomes the "Test comparison" section of
# the run's report. See docs/harmony.md, "Virtual test".
#
#   bash examples/harmony/virtual-test.sh [OUT]        (default OUT: out/harmony-virtual-test)
#
# STUDY=path/to/study.toml selects another study (e.g. a coarser refinement).
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${1:-out/harmony-virtual-test}
STUDY=${STUDY:-examples/harmony/study.toml}
cargo build --release --quiet
S=target/release/stickslip
mkdir -p "$OUT"

# The harmonic balance at the same levels (the study's own band, 300 -> 170 Hz), with its
# report, to which `compare` adds the test comparison at the end.
[ -f "$OUT/hbm/report.html" ] || $S run "$STUDY" --out "$OUT/hbm"

# The test: 90 -> 300 Hz (100 Hz is where Eq. 1 identifies the force), 128 steps per period at
# 300 Hz (a step of 26 us), records at 9.6 kHz; HHT alpha = -0.05 damps the stiff joints' kHz
# modes that stick-slip excites (their period is a few steps), sensor noise 0.01 m/s^2 RMS.
$S timesim "$STUDY" --out "$OUT/test" --levels 70,1070,1875,2910 \
    --band 90,300 --sweep-rate 10 --slow-band 180,250 --slow-rate 1 \
    --steps-per-period 128 --record-every 4 --alpha -0.05 \
    --uff --accel-noise 0.01

# Processing, as for measured records: the 70 N record is the calibration of Eq. 1.
$S extract "$OUT/test/sweep_70N.uff" --reference drive --cycles-per-block 4 --skip-cycles 2 \
    --out "$OUT/calibration"
$S extract "$OUT"/test/sweep_*N.uff --reference drive --cycles-per-block 4 --skip-cycles 2 \
    --calibration "$OUT/calibration/sweep_70N_harmonics.csv" --calibration-level 70 \
    --identify-at 100 --identify-channel body_top --out "$OUT/extract"
$S compare --measured "$OUT"/extract/sweep_*N_frf.csv --simulated "$OUT/hbm" --out "$OUT/compare"
echo "open $OUT/hbm/report.html: the model, the harmonic balance and its test comparison"
