#!/bin/sh
# Side-by-side of the reduction benchmark and CalculiX 2.20 (Debian package calculix-ccx) on the
# same clamped tet10 slabs: writes the decks, runs both under /usr/bin/time -v, prints the wall
# time, CPU time and peak memory of each. Usage: calculix_side_by_side.sh [30k|280k|all] [DIR]
set -eu
size=${1:-30k}
dir=${2:-$(mktemp -d)}
cd "$(dirname "$0")/../../.."
cargo bench -p stickslip-fe --bench reduction --no-run
bench=$(ls -t target/release/deps/reduction-* | grep -v '\.d$' | head -1)
/usr/bin/time -v "$bench" "$size" --repeat 1 --inp "$dir" > "$dir/stickslip.md" 2> "$dir/stickslip.time"
cat "$dir/stickslip.md"
for deck in "$dir"/slab_*.inp; do
    job=$(basename "$deck" .inp)
    (cd "$dir" && /usr/bin/time -v ccx -i "$job" > "$job.log" 2> "$job.time")
    echo "CalculiX $job (10 modes):"
    grep -E "Elapsed|User time|Maximum resident" "$dir/$job.time"
    grep -A6 "E I G E N" "$dir/$job.dat" | tail -1
done
echo "stickslip (whole benchmark process):"
grep -E "Elapsed|User time|Maximum resident" "$dir/stickslip.time"
