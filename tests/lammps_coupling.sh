#!/usr/bin/env bash
# examples/lammps_coupling (libodhs advancing atoms that LAMMPS owns, through
# LAMMPS's C library interface) against shear_flow from the same start, in 2D
# and 3D, at fixed volume and pressure, across a flip of the Lees-Edwards
# tilt; its command line; LAMMPS reading its dump back. Run by `make
# examples` (skipped, with the reason, when lammps_coupling was not built).
#
# Agreement demanded of lammps_coupling against shear_flow (default
# --sync-tol 1e-12):
#  - series: the 11 columns of shear_flow's --series; counts (events,
#    collisions, openings) exactly, every other number to a relative 1e-9
#    (the numbers are written with 10 digits; in practice the rows are the
#    same text, which the summary line reports);
#  - final configuration written by the library (--out): the same file, byte
#    for byte (the library never takes LAMMPS's positions, so its run is
#    shear_flow's);
#  - final positions held by LAMMPS (its write_data, its dump's last frame,
#    and LAMMPS's read_dump of that frame): within 1e-12 mean diameters of
#    shear_flow's, modulo the sheared periodic lattice (LAMMPS's remapping
#    into its triclinic box costs a few ulps: measured ~2e-15).
set -u
bin=${1:-build/examples}
if [ ! -x "$bin/lammps_coupling" ]; then
    echo "lammps-coupling: SKIPPED: $bin/lammps_coupling was not built (no LAMMPS headers; apt-get install liblammps-dev, or make deps)"
    exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OPENBLAS_NUM_THREADS=1
# the program's temporary directories (its LAMMPS log, its data file) go here
export TMPDIR=$tmp/tmpdir
mkdir "$TMPDIR"
fail=0 pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }
expect() { # expect CODE DESCRIPTION -- command...
    local want=$1 what=$2; shift 3
    "$@" >"$tmp/out" 2>"$tmp/err"
    local got=$?
    if [ "$got" -eq "$want" ]; then ok
    else bad "$what: exit $got, expected $want"; sed 's/^/  | /' "$tmp/err" | tail -5; fi
}
expect_in() { # expect_in FILE PATTERN DESCRIPTION
    if grep -q -- "$2" "$tmp/$1"; then ok; else bad "$3"; fi
}

# series_diff A B: compare the first 11 columns of two --series files (the
# header and comment lines must match too); prints "rows identical|differ
# maxrel=X count_mismatches=K"; exit 1 beyond the tolerances above
series_diff() {
    awk -F, -v OFS=, '
        function rel(a, b) { return (a == b) ? 0 : (a - b < 0 ? b - a : a - b) / ((a < 0 ? -a : a) > (b < 0 ? -b : b) ? (a < 0 ? -a : a) : (b < 0 ? -b : b)) }
        FNR == 1 { file++ }
        /^#/ { next }
        { row = ""; for (k = 1; k <= 11; ++k) row = row (k > 1 ? "," : "") $k }
        file == 1 { a[FNR] = row; na = FNR; next }
        { b[FNR] = row; nb = FNR }
        END {
            if (na != nb) { print "row counts " na " and " nb; exit 1 }
            same = 1; maxrel = 0; cnt = 0; hdr = 0
            for (r = 1; r <= na; ++r) {
                if (a[r] != b[r]) same = 0
                if (r == 1) { if (a[r] != b[r]) hdr = 1; continue }
                split(a[r], x, ","); split(b[r], y, ",")
                for (k = 1; k <= 11; ++k) {
                    if (k == 5 || k == 9 || k == 10) { if (x[k] != y[k]) cnt++; continue }
                    e = rel(x[k] + 0, y[k] + 0); if (e > maxrel) maxrel = e
                }
            }
            printf "rows %s maxrel=%.3g count_mismatches=%d\n", same ? "identical" : "differ", maxrel, cnt
            exit (hdr || cnt || maxrel > 1e-9)
        }' "$1" "$2"
}

# pos_diff REF OTHER: the largest distance between the atoms of REF (a data
# file; its box and tilt give the lattice) and of OTHER (a data file, or a
# dump: its last frame), by atom id, modulo the lattice, in mean diameters;
# prints "maxdist=X"; exit 1 beyond 1e-12 (or when an atom is missing)
pos_diff() {
    awk '
        FNR == 1 { file++; atoms = 0; frame = 0 }
        file == 1 && / xlo xhi/ { xlo = $1; Lx = $2 - $1 }
        file == 1 && / ylo yhi/ { ylo = $1; Ly = $2 - $1 }
        file == 1 && / zlo zhi/ { zlo = $1; Lz = $2 - $1 }
        file == 1 && / xy xz yz/ { xy = $1 }
        /^Atoms/ { atoms = 1; next }
        /^(Velocities|Masses|Bonds)/ { atoms = 0 }
        /^ITEM: ATOMS/ { atoms = 2; frame++; next }
        /^ITEM:/ { atoms = 0 }
        atoms == 1 && NF >= 7 && $1 ~ /^[0-9]+$/ {
            if (file == 1) { x[$1] = $5; y[$1] = $6; z[$1] = $7; d += $3; n++ }
            else { X[$1] = $5; Y[$1] = $6; Z[$1] = $7; m[$1] = 1 }
        }
        atoms == 2 && NF >= 6 { X[$1] = $4; Y[$1] = $5; Z[$1] = $6; m[$1] = 1 }
        function rint(v) { return v < 0 ? -int(-v + 0.5) : int(v + 0.5) }
        END {
            worst = 0
            for (i in x) {
                if (!(i in m)) { print "atom " i " missing"; exit 1 }
                dx = X[i] - x[i]; dy = Y[i] - y[i]; dz = Z[i] - z[i]
                ny = rint(dy / Ly); dy -= ny * Ly; dx -= ny * xy
                dx -= rint(dx / Lx) * Lx; dz -= rint(dz / Lz) * Lz
                s = sqrt(dx * dx + dy * dy + dz * dz); if (s > worst) worst = s
            }
            worst /= d / n
            printf "maxdist=%.3g\n", worst
            exit !(worst <= 1e-12)
        }' "$1" "$2"
}

check_series() { # check_series WHAT LC.csv SF.csv
    if series_diff "$2" "$3" > "$tmp/sd"; then ok; echo "  $1: series $(cat "$tmp/sd")"
    else bad "$1: series differ from shear_flow's: $(cat "$tmp/sd")"; fi
}
check_pos() { # check_pos WHAT REF OTHER
    if pos_diff "$2" "$3" > "$tmp/pd"; then ok; echo "  $1: $(cat "$tmp/pd") mean diameters"
    else bad "$1: positions differ: $(cat "$tmp/pd")"; fi
}
# the columns lammps_coupling adds: sync at round-off, nothing adopted, and
# LAMMPS's packing fraction equal to the library's
check_extra() { # check_extra WHAT LC.csv
    if awk -F, '/^#/ || NR == 1 { next }
                { if (!($14 <= 1e-12) || $15 != 0) exit 1
                  e = $12 - $6; if (e < 0) e = -e; if (!(e <= 1e-12 * $6)) exit 1 }' "$2"; then ok
    else bad "$1: sync, adopted or lmp_phi columns"; fi
}

# ---- the command line ---------------------------------------------------------
lc=$bin/lammps_coupling
sf=$bin/shear_flow
expect 0 "--help" -- "$lc" --help
expect_in out "^usage: lammps_coupling" "--help prints the usage"
expect_in out "^  --quiet" "--help lists --quiet"
expect_in out "paper mode" "--help names paper mode"
expect 2 "unknown option" -- "$lc" --no-such-option
expect_in err "usage: lammps_coupling" "usage after a bad option"
expect 2 "missing value" -- "$lc" --dump
expect 2 "negative --sync-tol" -- "$lc" --sync-tol -1
expect 2 "unknown solver" -- "$lc" --solver nonsense
expect 2 "a dump name LAMMPS cannot take" -- "$lc" --n 16 --phi 0.5 --dump "$tmp/a b.dump"
expect 1 "unreadable input" -- "$lc" --in "$tmp/does-not-exist.data"
expect_in err "does-not-exist.data" "names the unreadable file"
expect 1 "unreadable --lammps-input" -- "$lc" --n 16 --phi 0.5 --strain 0.01 --lammps-input "$tmp/none.in"
printf 'no_such_lammps_command 1 2 3\n' > "$tmp/bad.in"
expect 1 "an error in LAMMPS" -- "$lc" --n 16 --phi 0.5 --strain 0.01 --lammps-input "$tmp/bad.in"
expect_in err "LAMMPS ended the program in the command: (the commands of" "a LAMMPS error names the commands"
expect_in err "LAMMPS said: ERROR: Unknown command" "a LAMMPS error gives LAMMPS's message"
# (only ours: an MPI library may keep its own session directory there)
[ -z "$(ls "$TMPDIR" | grep '^lammps_coupling\.')" ] && ok || bad "temporary directory left behind after a LAMMPS error"

# ---- 2D: from a sheared start, against shear_flow ---------------------------------
expect 0 "2D start" -- "$sf" --n 64 --strain 0.05 --out "$tmp/s2.data" --quiet
expect 0 "shear_flow 2D" -- "$sf" --in "$tmp/s2.data" --strain 0.1 --series "$tmp/sf2.csv" --out "$tmp/sf2.data"
expect 0 "lammps_coupling 2D" -- "$lc" --in "$tmp/s2.data" --strain 0.1 --series "$tmp/lc2.csv" \
    --out "$tmp/lc2.data" --dump "$tmp/lc2.dump" --write-data "$tmp/lw2.data" --lammps-log "$tmp/lc2.log"
expect_in err "heun, solver auto" "runs the library's defaults (heun, auto)"
expect_in err "taken from LAMMPS 0 times" "the library never took LAMMPS's positions"
expect_in out "lmp_dv_rms" "the table has LAMMPS's columns"
check_series "2D" "$tmp/lc2.csv" "$tmp/sf2.csv"
check_extra "2D" "$tmp/lc2.csv"
cmp -s "$tmp/lc2.data" "$tmp/sf2.data" && ok || bad "2D: --out differs from shear_flow's"
check_pos "2D: LAMMPS's write_data" "$tmp/sf2.data" "$tmp/lw2.data"
check_pos "2D: LAMMPS's dump, last frame" "$tmp/sf2.data" "$tmp/lc2.dump"
[ "$(grep -c '^ITEM: TIMESTEP' "$tmp/lc2.dump")" -eq 11 ] && ok || bad "2D: dump frames"
[ "$(grep -A1 '^ITEM: TIME$' "$tmp/lc2.dump" | tail -1)" = "0.1" ] && ok || bad "2D: the dump's last TIME is the strain"
grep -q '^ITEM: ATOMS id type radius x y z vx vy vz$' "$tmp/lc2.dump" && ok || bad "2D: dump columns"
grep -q '^read_data ' "$tmp/lc2.log" && grep -q 'v_odhs_phi' "$tmp/lc2.log" && ok || bad "2D: --lammps-log"
if command -v lmp > /dev/null; then
    printf 'units lj\ndimension 2\natom_style sphere\nboundary p p p\nread_data %s\nread_dump %s 10 x y box yes\nwrite_data %s\n' \
        "$tmp/s2.data" "$tmp/lc2.dump" "$tmp/rd2.data" > "$tmp/rd.in"
    expect 0 "lmp reads the dump back (read_dump)" -- lmp -log none -screen none -in "$tmp/rd.in"
    check_pos "2D: lmp's read_dump of the last frame" "$tmp/sf2.data" "$tmp/rd2.data"
else
    echo "skipped: lmp (Debian lammps) not installed: LAMMPS reading the dump back not checked"
fi
expect 0 "shear_flow reads LAMMPS's write_data" -- "$sf" --in "$tmp/lw2.data" --strain 0.01 --quiet

# ---- 3D ------------------------------------------------------------------------------
expect 0 "3D start" -- "$sf" --dim 3 --n 64 --phi 0.55 --strain 0.02 --out "$tmp/s3.data" --quiet
expect 0 "shear_flow 3D" -- "$sf" --in "$tmp/s3.data" --strain 0.05 --series "$tmp/sf3.csv" --out "$tmp/sf3.data"
expect 0 "lammps_coupling 3D" -- "$lc" --in "$tmp/s3.data" --strain 0.05 --series "$tmp/lc3.csv" \
    --out "$tmp/lc3.data" --dump "$tmp/lc3.dump" --write-data "$tmp/lw3.data" --quiet
[ -s "$tmp/err" ] && bad "--quiet writes to stderr" || ok
check_series "3D" "$tmp/lc3.csv" "$tmp/sf3.csv"
check_extra "3D" "$tmp/lc3.csv"
cmp -s "$tmp/lc3.data" "$tmp/sf3.data" && ok || bad "3D: --out differs from shear_flow's"
check_pos "3D: LAMMPS's write_data" "$tmp/sf3.data" "$tmp/lw3.data"
check_pos "3D: LAMMPS's dump, last frame" "$tmp/sf3.data" "$tmp/lc3.dump"

# ---- the built-in scene (LAMMPS reads it from a temporary data file) -------------------
expect 0 "shear_flow built-in" -- "$sf" --n 64 --strain 0.03 --series "$tmp/sfb.csv" --out "$tmp/sfb.xyz" --quiet
expect 0 "lammps_coupling built-in" -- "$lc" --n 64 --strain 0.03 --series "$tmp/lcb.csv" --out "$tmp/lcb.xyz" --quiet
check_series "built-in scene" "$tmp/lcb.csv" "$tmp/sfb.csv"
cmp -s "$tmp/lcb.xyz" "$tmp/sfb.xyz" && ok || bad "built-in: --out differs from shear_flow's"
# an extended XYZ start (LAMMPS reads the library's data file of it)
expect 0 "lammps_coupling from an XYZ file" -- "$lc" --in "$tmp/sfb.xyz" --strain 0.01 --quiet

# ---- across a flip of the tilt (the cell strain passes 1/2: xy jumps by -Lx) ---------
expect 0 "start at strain 0.49" -- "$sf" --in "$tmp/s2.data" --strain 0.44 --out "$tmp/s49.data" --quiet
expect 0 "shear_flow across the flip" -- "$sf" --in "$tmp/s49.data" --strain 0.03 --every 0.005 \
    --series "$tmp/sff.csv" --out "$tmp/sff.data"
expect 0 "lammps_coupling across the flip" -- "$lc" --in "$tmp/s49.data" --strain 0.03 --every 0.005 \
    --series "$tmp/lcf.csv" --out "$tmp/lcf.data" --write-data "$tmp/lwf.data" --lammps-log "$tmp/lcf.log"
grep -q '^change_box all xy final -' "$tmp/lcf.log" && ok || bad "flip: LAMMPS's tilt did not flip"
check_series "flip" "$tmp/lcf.csv" "$tmp/sff.csv"
cmp -s "$tmp/lcf.data" "$tmp/sff.data" && ok || bad "flip: --out differs from shear_flow's"
check_pos "flip: LAMMPS's write_data" "$tmp/sff.data" "$tmp/lwf.data"

# ---- fixed pressure (LAMMPS's box edges follow the library's) --------------------------
expect 0 "shear_flow --pressure" -- "$sf" --in "$tmp/s2.data" --strain 0.05 --pressure 5 \
    --series "$tmp/sfp.csv" --out "$tmp/sfp.data" --quiet
expect 0 "lammps_coupling --pressure" -- "$lc" --in "$tmp/s2.data" --strain 0.05 --pressure 5 \
    --series "$tmp/lcp.csv" --out "$tmp/lcp.data" --write-data "$tmp/lwp.data"
expect_in out "phi          kappa    lmp_phi" "--pressure table has phi and kappa"
check_series "pressure" "$tmp/lcp.csv" "$tmp/sfp.csv"
check_extra "pressure" "$tmp/lcp.csv"
cmp -s "$tmp/lcp.data" "$tmp/sfp.data" && ok || bad "pressure: --out differs from shear_flow's"
check_pos "pressure: LAMMPS's write_data" "$tmp/sfp.data" "$tmp/lwp.data"

# ---- LAMMPS moves the atoms: the library takes them --------------------------------------
# a uniform translation (the flow is invariant under it): taken once, at the
# start; the run then matches shear_flow's (only to round-off: the library
# restarted from translated positions)
printf 'displace_atoms all move 0.25 0 0 units box\ndump extra all atom 1 %s\n' "$tmp/extra.dump" > "$tmp/disp.in"
expect 0 "LAMMPS displaces the atoms" -- "$lc" --in "$tmp/s2.data" --strain 0.05 --lammps-input "$tmp/disp.in" \
    --series "$tmp/lcd.csv"
expect_in err "taken from LAMMPS 1 times" "the library took LAMMPS's displaced positions once"
[ "$(awk -F, '/^#/ || NR == 1 { next } { s += $15 } END { print s }' "$tmp/lcd.csv")" = 1 ] && ok \
    || bad "displaced: adopted column"
[ "$(grep -c '^ITEM: TIMESTEP' "$tmp/extra.dump")" -eq 6 ] && ok || bad "--lammps-input's own dump"
expect 0 "shear_flow, for the displaced run" -- "$sf" --in "$tmp/s2.data" --strain 0.05 --series "$tmp/sfd.csv" --quiet
echo "  displaced start (informative): $(series_diff "$tmp/lcd.csv" "$tmp/sfd.csv")"
# what the library cannot take: deleted atoms, atoms moved into overlap
printf 'group one id 1\ndelete_atoms group one\n' > "$tmp/del.in"
expect 1 "LAMMPS deletes an atom" -- "$lc" --in "$tmp/s2.data" --strain 0.01 --lammps-input "$tmp/del.in"
expect_in err "atoms cannot be created or deleted" "a deleted atom is refused, with the reason"
printf 'set atom 1 x 0.0 y 0.0\nset atom 2 x 0.1 y 0.0\n' > "$tmp/ov.in"
expect 1 "LAMMPS moves atoms into overlap" -- "$lc" --in "$tmp/s2.data" --strain 0.01 --lammps-input "$tmp/ov.in"
expect_in err "cannot take LAMMPS's positions: particles 0 and 1 overlap" "an overlap is refused, with the pair"
# --sync-tol 0: LAMMPS's round-off copies are taken at every output (the
# contact network restarted each time): informative, the run must only work
expect 0 "--sync-tol 0" -- "$lc" --in "$tmp/s2.data" --strain 0.1 --sync-tol 0 --series "$tmp/lc0.csv"
expect_in err "taken from LAMMPS 11 times" "--sync-tol 0 takes LAMMPS's positions at every output"
echo "  --sync-tol 0 (informative): $(series_diff "$tmp/lc0.csv" "$tmp/sf2.csv")"

[ -z "$(ls "$TMPDIR" | grep '^lammps_coupling\.')" ] && ok || bad "temporary directories left behind"
echo "lammps-coupling: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
