#!/bin/sh
# Regenerate the CalculiX reference outputs of this folder (needs python3 and CalculiX 2.20:
# `apt-get install calculix-ccx`). For each deck written by make_decks.py:
#   NAME.freq           the frequencies CalculiX finds (mode, Hz), from its .dat file;
#   NAME.sti/.mas/.dof  its stiffness and mass matrices and their DOF list, from a copy of the deck
#                       with *FREQUENCY, SOLVER=MATRIXSTORAGE (1-based upper triangle, node.direction);
#   harmony_coarse.freq the frequencies of the Harmony deck tests/harmony_deck.rs writes.
# `cargo test -p stickslip-fe --test assembly_calculix` compares stickslip with these files;
# `regenerate.sh --check` also re-runs CalculiX and fails if its frequencies changed.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
cd "$here"
python3 make_decks.py
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
# The eigenvalue table of $work/NAME.dat as $work/NAME.freq: after its header, lines
# "mode eigenvalue rad/time cycles/time imaginary".
frequencies() {
    awk '/E I G E N V A L U E   O U T P U T/ {table = 1; next}
         table && NF == 5 && $1 ~ /^[0-9]+$/ {printf "%s %s\n", $1, $4}
         table && /P A R T I C I P A T I O N/ {exit}' "$work/$1.dat" > "$work/$1.freq"
    if [ ! -s "$work/$1.freq" ]; then echo "no frequencies in $1.dat"; exit 1; fi
}
for inp in *.inp; do
    name=${inp%.inp}
    cp "$inp" "$work/$name.inp"
    (cd "$work" && ccx "$name" > "$name.log" 2>&1) || { echo "ccx failed on $inp, see its log:"; cat "$work/$name.log"; exit 1; }
    frequencies "$name"
    if [ "${1:-}" = "--check" ] && ! cmp -s "$work/$name.freq" "$name.freq"; then
        echo "$name: CalculiX frequencies differ from the committed ones"; status=1
    fi
    sed 's/^\*FREQUENCY.*/*FREQUENCY, SOLVER=MATRIXSTORAGE/' "$inp" > "$work/${name}_m.inp"
    (cd "$work" && ccx "${name}_m" > "${name}_m.log" 2>&1)
    if [ "${1:-}" != "--check" ]; then
        (echo "# mode frequency_hz (CalculiX 2.20, $name.inp)"; cat "$work/$name.freq") > "$name.freq"
        for ext in sti mas dof; do cp "$work/${name}_m.$ext" "$name.$ext"; done
    fi
done
# The Harmony deck (refinement 0.5, with the screws as rigid bodies with rotation nodes) is
# written by its test: harmony_coarse.freq holds CalculiX's modes of it (about a minute).
harmony="$here/../../../target/tmp/harmony_coarse.inp"
if [ -f "$harmony" ]; then
    cp "$harmony" "$work/harmony_coarse.inp"
    (cd "$work" && ccx harmony_coarse > harmony_coarse.log 2>&1) || { echo "ccx failed on $harmony"; exit 1; }
    frequencies harmony_coarse
    if [ "${1:-}" = "--check" ]; then
        grep -v '^#' harmony_coarse.freq | cmp -s - "$work/harmony_coarse.freq" || { echo "harmony_coarse: CalculiX frequencies differ"; status=1; }
    else
        (head -n 1 harmony_coarse.freq; cat "$work/harmony_coarse.freq") > "$work/h.freq" && mv "$work/h.freq" harmony_coarse.freq
    fi
else
    echo "skipped harmony_coarse.freq: run 'cargo test --release -p stickslip-fe --test harmony_deck' first"
fi
exit $status
