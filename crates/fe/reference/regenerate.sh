#!/bin/sh
# Regenerate the CalculiX reference outputs of this folder (needs python3 and CalculiX 2.20:
# `apt-get install calculix-ccx`). For each deck written by make_decks.py:
#   NAME.freq           the frequencies CalculiX finds (mode, Hz), from its .dat file;
#   NAME.sti/.mas/.dof  its stiffness and mass matrices and their DOF list, from a copy of the deck
#                       with *FREQUENCY, SOLVER=MATRIXSTORAGE (1-based upper triangle, node.direction).
# `cargo test -p stickslip-fe --test assembly_calculix` compares stickslip with these files;
# `regenerate.sh --check` also re-runs CalculiX and fails if its frequencies changed.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
cd "$here"
python3 make_decks.py
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
for inp in *.inp; do
    name=${inp%.inp}
    cp "$inp" "$work/$name.inp"
    (cd "$work" && ccx "$name" > "$name.log" 2>&1) || { echo "ccx failed on $inp, see its log:"; cat "$work/$name.log"; exit 1; }
    # The eigenvalue table: after its header, lines "mode eigenvalue rad/time cycles/time imaginary".
    awk '/E I G E N V A L U E   O U T P U T/ {table = 1; next}
         table && NF == 5 && $1 ~ /^[0-9]+$/ {printf "%s %s\n", $1, $4}
         table && /P A R T I C I P A T I O N/ {exit}' "$work/$name.dat" > "$work/$name.freq"
    if [ ! -s "$work/$name.freq" ]; then echo "no frequencies in $name.dat"; exit 1; fi
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
exit $status
