#!/usr/bin/env bash
# Command-line contract of the examples (part of the public contract):
# --help exits 0, bad arguments print usage and exit 2, unreadable input
# exits 1 with the reason, and a short pipeline compress -> shear_flow works
# with --out/--in/--series. Run by `make examples`.
set -u
bin=${1:-build/examples}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0 pass=0
expect() { # expect CODE DESCRIPTION -- command...
    local want=$1 what=$2; shift 3
    "$@" >"$tmp/out" 2>"$tmp/err"
    local got=$?
    if [ "$got" -eq "$want" ]; then pass=$((pass + 1))
    else echo "FAIL: $what: exit $got, expected $want"; sed 's/^/  | /' "$tmp/err" | tail -5; fail=$((fail + 1)); fi
}
expect_in() { # expect_in FILE PATTERN DESCRIPTION
    if grep -q -- "$2" "$tmp/$1"; then pass=$((pass + 1)); else echo "FAIL: $3"; fail=$((fail + 1)); fi
}
# data rows of a series file (the header and the "# units" comment left out)
rows() { grep -v '^#' "$tmp/$1" | tail -n +2 | wc -l; }
for prog in shear_flow compress self_propulsion; do
    expect 0 "$prog --help" -- "$bin/$prog" --help
    expect_in out "usage: $prog" "$prog --help prints usage"
    expect 2 "$prog unknown option" -- "$bin/$prog" --no-such-option
    expect_in err "usage: $prog" "$prog prints usage on a bad option"
    expect 2 "$prog missing value" -- "$bin/$prog" --n
    expect 2 "$prog garbage number" -- "$bin/$prog" --dt abc
    expect 2 "$prog negative dt" -- "$bin/$prog" --dt -1
    expect 2 "$prog bad dim" -- "$bin/$prog" --dim 4
    expect 2 "$prog unknown solver" -- "$bin/$prog" --solver nonsense
    expect 1 "$prog unreadable input" -- "$bin/$prog" --in "$tmp/does-not-exist.xyz"
    expect_in err "does-not-exist.xyz" "$prog names the unreadable file"
    printf '3\nnot an xyz file\n' > "$tmp/bad.xyz"
    expect 1 "$prog malformed input" -- "$bin/$prog" --in "$tmp/bad.xyz"
    expect_in err "line" "$prog names the bad line"
done
expect 0 "compress to phi 0.7" -- "$bin/compress" --n 64 --phi 0.7 --out "$tmp/c.xyz" --series "$tmp/c.csv"
expect_in c.csv "^phi,pressure,z,events" "compress writes its series header"
expect 0 "shear_flow from a file" -- "$bin/shear_flow" --in "$tmp/c.xyz" --strain 0.02 --every 0.01 \
    --out "$tmp/s.xyz" --series "$tmp/s.csv"
expect_in s.csv "^strain,shear_stress,pressure,z,events" "shear_flow writes its series header"
[ "$(rows s.csv)" -eq 3 ] && pass=$((pass + 1)) || { echo "FAIL: shear_flow series rows"; fail=$((fail + 1)); }
expect 0 "shear_flow at fixed pressure" -- "$bin/shear_flow" --in "$tmp/s.xyz" --strain 0.01 --pressure 5 \
    --series "$tmp/p.csv"
expect_in p.csv "^strain,shear_stress,pressure,z,events,phi,kappa,time,collisions,openings,dissipation$" \
    "shear_flow --pressure series has phi and kappa"
expect_in p.csv "^# units: " "shear_flow series states its units in a comment line"
expect 0 "shear_flow --pressure 1000 with cg (auto rescues it)" -- "$bin/shear_flow" --n 48 \
    --pressure 1000 --strain 0.02 --solver cg --integrator euler
expect_in out "phi          kappa" "shear_flow --pressure table has phi and kappa"
[ "$(grep -v '^#' "$tmp/p.csv" | awk -F, 'NF != 11' | wc -l)" -eq 0 ] && pass=$((pass + 1)) || { echo "FAIL: shear_flow --pressure rows have 11 fields"; fail=$((fail + 1)); }
expect 0 "shear_flow svg" -- "$bin/shear_flow" --n 32 --phi 0.6 --strain 0.01 --svg "$tmp/s.svg"
head -c 4 "$tmp/s.svg" | grep -q "<svg" && pass=$((pass + 1)) || { echo "FAIL: shear_flow svg"; fail=$((fail + 1)); }
grep -q "<line" "$tmp/s.svg" && pass=$((pass + 1)) || { echo "FAIL: shear_flow svg has no force lines"; fail=$((fail + 1)); }
expect 0 "shear_flow 3D built-in" -- "$bin/shear_flow" --dim 3 --n 32 --phi 0.4 --strain 0.01
expect 0 "shear_flow dense solver" -- "$bin/shear_flow" --n 32 --phi 0.6 --strain 0.01 --solver dense
expect 0 "shear_flow adaptive" -- "$bin/shear_flow" --n 32 --phi 0.6 --strain 0.01 --integrator heun --tol 1e-8
expect 2 "shear_flow bad integrator" -- "$bin/shear_flow" --integrator rk9
expect 2 "shear_flow bad tol" -- "$bin/shear_flow" --tol 2
# oscillatory shear (--oscillate A,T[,SHAPE]): series, stroboscopic file, bad values
expect 0 "shear_flow oscillate" -- "$bin/shear_flow" --in "$tmp/c.xyz" --oscillate 0.05,1,triangle --cycles 2 --solver dense \
    --per-cycle 4 --integrator heun --series "$tmp/o.csv" --strobe "$tmp/strobe.csv"
expect_in o.csv "^time,strain,shear_stress,pressure,z,events" "shear_flow --oscillate writes its series header"
[ "$(rows o.csv)" -eq 9 ] && pass=$((pass + 1)) || { echo "FAIL: shear_flow --oscillate series rows"; fail=$((fail + 1)); }
expect_in strobe.csv "^cycle,strobe_rms,from_start,events" "shear_flow --strobe header"
[ "$(wc -l < "$tmp/strobe.csv")" -eq 3 ] && pass=$((pass + 1)) || { echo "FAIL: shear_flow --strobe rows"; fail=$((fail + 1)); }
expect_in out "^# cycle 2: stroboscopic rms displacement" "shear_flow --oscillate reports the stroboscopic displacement"
expect 0 "shear_flow oscillate sine" -- "$bin/shear_flow" --n 32 --phi 0.6 --oscillate 0.05,2 --cycles 1 --per-cycle 4 --solver dense
for bad in 0.1 0,1 0.1,-1 0.1,1,square 0.1,1,sine,x nan,1; do
    expect 2 "shear_flow --oscillate $bad" -- "$bin/shear_flow" --oscillate "$bad"
done
expect 2 "shear_flow --oscillate with --pressure" -- "$bin/shear_flow" --oscillate 0.1,1 --pressure 5
expect 2 "shear_flow bad --cycles" -- "$bin/shear_flow" --oscillate 0.1,1 --cycles 0
expect 0 "self_propulsion built-in" -- "$bin/self_propulsion" --n 64 --time 2 --every 1 --series "$tmp/p.csv" \
    --svg "$tmp/p.svg" --out "$tmp/p.xyz"
expect_in p.csv "^time,mean_speed,pressure,z,collisions,openings" "self_propulsion writes its series header"
[ "$(wc -l < "$tmp/p.csv")" -eq 4 ] && pass=$((pass + 1)) || { echo "FAIL: self_propulsion series rows"; fail=$((fail + 1)); }
head -c 4 "$tmp/p.svg" | grep -q "<svg" && pass=$((pass + 1)) || { echo "FAIL: self_propulsion svg"; fail=$((fail + 1)); }
grep -q 'marker-end="url(#head)"' "$tmp/p.svg" && pass=$((pass + 1)) || { echo "FAIL: self_propulsion svg arrows"; fail=$((fail + 1)); }
expect 0 "self_propulsion from a file" -- "$bin/self_propulsion" --in "$tmp/p.xyz" --time 0.5 --tmax 2
expect 0 "self_propulsion 3D" -- "$bin/self_propulsion" --dim 3 --n 32 --phi 0.3 --time 0.5
expect 2 "self_propulsion bad tmax" -- "$bin/self_propulsion" --tmax 0
expect 2 "self_propulsion bad time" -- "$bin/self_propulsion" --time -1
expect 2 "self_propulsion bad phi" -- "$bin/self_propulsion" --phi 1.5
expect 0 "jam_packing help" -- "$bin/jam_packing" --help
expect 2 "jam_packing bad protocol" -- "$bin/jam_packing" --protocol squash
expect 0 "jam_packing compress" -- "$bin/jam_packing" --n 32 --svg "$tmp/j.svg" --contacts "$tmp/j.con" --out "$tmp/j.xyz"
expect_in out "jammed                 yes" "jam_packing certifies a jammed packing"
head -c 4 "$tmp/j.svg" | grep -q "<svg" && pass=$((pass + 1)) || { echo "FAIL: jam_packing svg"; fail=$((fail + 1)); }
# a jammed packing sheared at fixed volume stops at once: exit 3 with the reason
expect 3 "shear_flow on a jammed packing stops early" -- "$bin/shear_flow" --in "$tmp/j.xyz" --strain 0.1 --solver dense
expect_in err "^shear_flow: stopped at strain" "shear_flow says why it stopped, on a line of its own"
expect 2 "jam_packing negative --jam-pressure" -- "$bin/jam_packing" --jam-pressure -1
# the fast route (--method lp): certified, or a clear refusal from a library built without CLP
"$bin/jam_packing" --n 64 --method lp --contacts "$tmp/jlp.con" >"$tmp/out" 2>"$tmp/err"
got=$?
if grep -q "built without an LP solver" "$tmp/err"; then
    echo "examples-cli: jam_packing --method lp skipped: the library has no LP solver (CLP)"
elif [ "$got" -eq 0 ] && grep -q "^certified              yes" "$tmp/out" && grep -q "linear programmes" "$tmp/err" \
    && [ "$(wc -l < "$tmp/jlp.con")" -gt 64 ]; then
    pass=$((pass + 1))
else
    echo "FAIL: jam_packing --method lp: exit $got"; sed 's/^/  | /' "$tmp/err" | tail -5; fail=$((fail + 1))
fi
expect 2 "jam_packing --method lp refuses a protocol without a compression stage" -- \
    "$bin/jam_packing" --method lp --protocol pressure
expect_in err "compress and shear only" "jam_packing says which protocols --method lp takes"
expect 2 "jam_packing --trust beyond half a diameter" -- "$bin/jam_packing" --method lp --trust 0.7
expect 2 "jam_packing --end-game takes batched or own" -- "$bin/jam_packing" --method lp --end-game fast
# the quench start (--method quench+lp): certified, in 2D and 3D and with the shear protocol
for args in "--n 64" "--n 64 --dim 3" "--n 64 --protocol shear" "--n 64 --quench-phi 0.84" "--n 64 --end-game own"; do
    # shellcheck disable=SC2086
    "$bin/jam_packing" $args --method quench+lp >"$tmp/out" 2>"$tmp/err"
    got=$?
    if grep -q "built without an LP solver" "$tmp/err"; then
        echo "examples-cli: jam_packing --method quench+lp skipped: the library has no LP solver (CLP)"
    elif [ "$got" -eq 0 ] && grep -q "^certified              yes" "$tmp/out" \
        && grep -q "quench: [1-9][0-9]* FIRE iterations, [0-9]* rescalings; the chain started at phi = 0\.[5-8]" "$tmp/err"; then
        pass=$((pass + 1))
    else
        echo "FAIL: jam_packing $args --method quench+lp: exit $got"; sed 's/^/  | /' "$tmp/err" | tail -5
        fail=$((fail + 1))
    fi
done
expect 2 "jam_packing --quench-phi at 1" -- "$bin/jam_packing" --method quench+lp --quench-phi 1
expect 2 "jam_packing --method quench+lp refuses the pressure protocol" -- \
    "$bin/jam_packing" --method quench+lp --protocol pressure
expect_in err "quench+lp replaces an isotropic compression" "jam_packing says why"
expect 2 "jam_packing bad method" -- "$bin/jam_packing" --method simplex
head -1 "$tmp/j.con" | grep -q "^i,j,kind,force,gap$" && [ "$(awk -F, 'NR > 1 && NF != 5' "$tmp/j.con" | wc -l)" -eq 0 ] \
    && pass=$((pass + 1)) || { echo "FAIL: jam_packing contacts CSV"; fail=$((fail + 1)); }
expect 0 "composite help" -- "$bin/composite" --help
expect_in out "usage: composite" "composite --help prints usage"
expect 2 "composite bad beads" -- "$bin/composite" --beads 5
expect 2 "composite unknown option" -- "$bin/composite" --no-such-option
expect 0 "composite dimers" -- "$bin/composite" --bodies 20 --beads 2 --phi 0.5 --strain 0.05 --every 0.05 \
    --series "$tmp/cp.csv" --svg "$tmp/cp.svg" --out "$tmp/cp.xyz"
expect_in cp.csv "^strain,shear_stress,pressure,z,events,bond_error" "composite writes its series header"
head -c 4 "$tmp/cp.svg" | grep -q "<svg" && pass=$((pass + 1)) || { echo "FAIL: composite svg"; fail=$((fail + 1)); }
# rigid bodies: the bond error column stays at round-off
awk -F, 'NR > 1 && $6 > 1e-12 { bad = 1 } END { exit bad }' "$tmp/cp.csv" && pass=$((pass + 1)) || { echo "FAIL: composite bond error"; fail=$((fail + 1)); }
expect 0 "hopper help" -- "$bin/hopper" --help
expect_in out "usage: hopper" "hopper --help prints usage"
expect 2 "hopper bad outlet" -- "$bin/hopper" --outlet 0.5
expect 0 "hopper short run" -- "$bin/hopper" --n 40 --time 6 --every 2 --series "$tmp/h.csv" --svg "$tmp/h.svg"
expect_in h.csv "^time,discharged,mean_speed,z,events" "hopper writes its series header"
expect_in out "^clogged: " "hopper reports whether the outlet clogged"
head -c 4 "$tmp/h.svg" | grep -q "<svg" && pass=$((pass + 1)) || { echo "FAIL: hopper svg"; fail=$((fail + 1)); }
# sweep_serial: examples/mpi/sweep_mpi.c built without MPI (its MPI twin is
# exercised by make check-mpi)
expect 0 "sweep_serial help" -- "$bin/sweep_serial" --help
expect_in out "usage: sweep_serial" "sweep_serial --help prints usage"
expect 2 "sweep_serial unknown option" -- "$bin/sweep_serial" --no-such-option
expect 2 "sweep_serial missing value" -- "$bin/sweep_serial" --out
expect 2 "sweep_serial bad every" -- "$bin/sweep_serial" --every -1
expect 2 "sweep_serial unknown solver" -- "$bin/sweep_serial" --solver nonsense
expect 1 "sweep_serial unreadable campaign" -- "$bin/sweep_serial" --campaign "$tmp/does-not-exist.csv" --out "$tmp/sw"
expect_in err "does-not-exist.csv" "sweep_serial names the unreadable campaign"
printf 'n,phi,seed,strain\n64,1.5,1,0.3\n' > "$tmp/badphi.csv"
expect 2 "sweep_serial phi out of range" -- "$bin/sweep_serial" --campaign "$tmp/badphi.csv" --out "$tmp/sw"
expect_in err "line 2: bad value '1.5' for phi" "sweep_serial names the bad line and field"
printf 'n,phi,colour\n' > "$tmp/badcol.csv"
expect 2 "sweep_serial unknown column" -- "$bin/sweep_serial" --campaign "$tmp/badcol.csv" --out "$tmp/sw"
printf 'n,phi,seed,strain\n64,0.7,1,0.1\n' > "$tmp/short.csv"
expect 2 "sweep_serial strain within the transient" -- "$bin/sweep_serial" --campaign "$tmp/short.csv" --out "$tmp/sw"
expect 0 "sweep_serial built-in campaign" -- "$bin/sweep_serial" --out "$tmp/sw" --quiet
[ "$(grep -c ',ok,' "$tmp/sw/runs.csv")" -eq 4 ] && [ -s "$tmp/sw/eta_phi.svg" ] && pass=$((pass + 1)) \
    || { echo "FAIL: sweep_serial built-in campaign results"; fail=$((fail + 1)); }
expect 0 "softcore_shear help" -- "$bin/softcore_shear" --help
expect_in out "usage: softcore_shear" "softcore_shear --help prints usage"
expect 2 "softcore_shear unknown option" -- "$bin/softcore_shear" --no-such-option
expect 2 "softcore_shear bad model" -- "$bin/softcore_shear" --model hard
expect 2 "softcore_shear bad rate" -- "$bin/softcore_shear" --rate -1
expect 1 "softcore_shear unreadable input" -- "$bin/softcore_shear" --in "$tmp/does-not-exist.xyz"
expect 0 "softcore_shear rd0 from a file" -- "$bin/softcore_shear" --in "$tmp/c.xyz" --strain 0.002 --every 0.001 \
    --series "$tmp/sc.csv" --out "$tmp/sc.xyz"
expect_in sc.csv "^strain,shear_stress,pressure,energy,z,max_overlap" "softcore_shear writes its series header"
[ "$(wc -l < "$tmp/sc.csv")" -eq 4 ] && pass=$((pass + 1)) || { echo "FAIL: softcore_shear series rows"; fail=$((fail + 1)); }
for m in cd0 qs-sd qs-fire qs-cg rd cd cdn cdt; do
    expect 0 "softcore_shear --model $m" -- "$bin/softcore_shear" --in "$tmp/c.xyz" --model $m --rate 1e-3 \
        --dgamma 1e-3 --strain 0.002 --every 0.001
done
expect 0 "softcore_shear 3D hertzian adaptive" -- "$bin/softcore_shear" --dim 3 --n 32 --phi 0.4 --alpha 2.5 \
    --integrator adaptive --strain 0.002 --every 0.001 --rate 1e-3
# the shared option table (examples/cli.h): -h is --help, the usage fits in
# 80 columns, shows the defaults (not values given before --help), names a
# bad value, and the common options read the same in every example
for prog in shear_flow compress self_propulsion composite hopper jam_packing softcore_shear sweep_serial; do
    expect 0 "$prog -h" -- "$bin/$prog" -h
    expect_in out "^usage: " "$prog -h prints usage"
    awk 'length($0) > 80 { bad = 1 } END { exit bad }' "$tmp/out" && pass=$((pass + 1)) \
        || { echo "FAIL: $prog usage wider than 80 columns"; fail=$((fail + 1)); }
    expect_in out "^  --help  *this message$" "$prog usage lists --help"
done
for prog in shear_flow compress self_propulsion composite hopper jam_packing; do
    "$bin/$prog" --help > "$tmp/out"
    expect_in out "^  --seed S  *random seed (default 1)$" "$prog --seed reads as in the other examples"
    expect_in out "^  --solver NAME  *linear solver: auto (a direct" \
        "$prog --solver reads as in the other examples"
    grep -A4 -- "--solver NAME" "$tmp/out" | grep -q "(default auto)$" && pass=$((pass + 1)) \
        || { echo "FAIL: $prog --solver defaults to auto"; fail=$((fail + 1)); }
    expect_in out "^  --out FILE.xyz  *write the final configuration (extended XYZ; a LAMMPS" \
        "$prog --out reads as in the other examples"
done
for prog in shear_flow compress self_propulsion jam_packing softcore_shear; do
    "$bin/$prog" --help > "$tmp/out"
    expect_in out "^  --n N  *built-in scene: number of particles (default 256)$" "$prog --n reads as in the other examples"
    expect_in out "^  --dim D  *built-in scene: dimension 2 or 3 (default 2)$" "$prog --dim reads as in the other examples"
done
expect 0 "shear_flow values before --help" -- "$bin/shear_flow" --n 5 --dim 3 --help
expect_in out "number of particles (default 256)" "shear_flow --help shows the default, not the value given"
expect 2 "shear_flow bad dt names it" -- "$bin/shear_flow" --dt abc
expect_in err "^shear_flow: bad value for --dt: abc$" "shear_flow names the bad value"
expect 2 "compress unknown option with a value" -- "$bin/compress" --colour red
expect_in err "^compress: unknown option --colour$" "compress names the unknown option"
expect 2 "jam_packing missing value" -- "$bin/jam_packing" --seed
expect_in err "^jam_packing: unknown option or missing value: --seed$" "jam_packing names the option without a value"
expect 2 "softcore_shear bad integrator" -- "$bin/softcore_shear" --integrator heun
expect 2 "sweep_serial unknown solver usage" -- "$bin/sweep_serial" --solver nonsense
expect_in err "(default cholmod when$" "sweep_serial usage after a bad solver shows the default"
# ---- what users look at (issue 20): library defaults, trajectories, files
# for other tools, plots, progress lines
py=$(command -v /usr/bin/python3 || command -v python3)
check_py() { # check_py DESCRIPTION ARGS...: 0 pass, 77 skipped (said why), else fail
    local what=$1; shift
    if [ -z "$py" ]; then echo "skipped: $what: no python3"; return; fi
    "$py" "$(dirname "$0")/outputs_check.py" "$@" > "$tmp/py" 2>&1
    local got=$?
    if [ "$got" -eq 0 ]; then pass=$((pass + 1))
    elif [ "$got" -eq 77 ]; then echo "skipped: $what: $(cat "$tmp/py")"
    else echo "FAIL: $what"; sed 's/^/  | /' "$tmp/py" | tail -5; fail=$((fail + 1)); fi
}
for s in 1 2 3; do
    expect 0 "shear_flow defaults --n 100 --phi 0.82 --strain 2 --seed $s" -- "$bin/shear_flow" --n 100 --phi 0.82 \
        --strain 2 --every 0.005 --seed $s
done
expect_in err "heun, solver auto" "shear_flow runs the library's defaults (heun, auto)"
grep -q $'\r' "$tmp/err" && { echo "FAIL: progress lines end in CR when stderr is a file"; fail=$((fail + 1)); } \
    || pass=$((pass + 1))
expect 0 "shear_flow --quiet" -- "$bin/shear_flow" --n 32 --phi 0.6 --strain 0.01 --quiet
[ -s "$tmp/err" ] && { echo "FAIL: shear_flow --quiet writes to stderr"; fail=$((fail + 1)); } || pass=$((pass + 1))
expect 0 "shear_flow paper mode" -- "$bin/shear_flow" --n 32 --phi 0.6 --strain 0.01 --integrator euler --solver cg
expect_in err "euler, solver cg" "shear_flow paper mode is one option away"
# a trajectory never changes the run: the final state is bit-identical
expect 0 "shear_flow without --traj" -- "$bin/shear_flow" --n 64 --strain 0.1 --every 0.01 --out "$tmp/a.xyz"
expect 0 "shear_flow with --traj" -- "$bin/shear_flow" --n 64 --strain 0.1 --every 0.01 --out "$tmp/b.xyz" \
    --traj "$tmp/t.xyz" --traj-every 0.02 --traj-contacts "$tmp/t.bonds" --contacts "$tmp/t.csv" \
    --plot "$tmp/plot.svg" --series "$tmp/t_series.csv"
cmp -s "$tmp/a.xyz" "$tmp/b.xyz" && pass=$((pass + 1)) || { echo "FAIL: --traj changed the run"; fail=$((fail + 1)); }
[ "$(grep -c '^64$' "$tmp/t.xyz")" -eq 6 ] && pass=$((pass + 1)) || { echo "FAIL: --traj frame count"; fail=$((fail + 1)); }
[ "$(grep -c '^ITEM: ENTRIES index batom1 batom2 kind force gap$' "$tmp/t.bonds")" -eq 6 ] && pass=$((pass + 1)) \
    || { echo "FAIL: --traj-contacts frame count"; fail=$((fail + 1)); }
check_py "trajectory read by ASE" traj "$tmp/t.xyz" 6 64
check_py "contacts CSV read by numpy" csv "$tmp/t.csv" "$(($(wc -l < "$tmp/t.csv") - 1))"
check_py "--plot: 3 lines of 11 points" svg "$tmp/plot.svg" 11 3
expect 0 "shear_flow reads a trajectory (its first frame)" -- "$bin/shear_flow" --in "$tmp/t.xyz" --strain 0.01
expect 0 "shear_flow --traj LAMMPS dump" -- "$bin/shear_flow" --n 64 --strain 0.02 --traj "$tmp/t.lammpstrj" \
    --quiet --out "$tmp/c.xyz.tmp"
[ "$(grep -c '^ITEM: ATOMS id type radius x y z vx vy vz ux uy uz fx fy fz$' "$tmp/t.lammpstrj")" -eq 3 ] \
    && pass=$((pass + 1)) || { echo "FAIL: LAMMPS dump frames"; fail=$((fail + 1)); }
expect 0 "shear_flow --pressure --plot" -- "$bin/shear_flow" --n 32 --strain 0.02 --pressure 10 --plot "$tmp/pp.svg"
check_py "--plot under pressure: 5 lines of 3 points" svg "$tmp/pp.svg" 3 5
expect 2 "shear_flow --traj of no known format" -- "$bin/shear_flow" --n 32 --traj "$tmp/t.txt"
expect 2 "shear_flow bad --traj-every" -- "$bin/shear_flow" --traj-every 0
expect 1 "shear_flow unwritable --traj" -- "$bin/shear_flow" --n 32 --traj "$tmp/no/such/dir/t.xyz"
expect 1 "shear_flow unwritable --plot" -- "$bin/shear_flow" --n 32 --strain 0.01 --plot "$tmp/no/such/dir/p.svg"
# LAMMPS data files: --out writes one, --in reads it (and LAMMPS's own, when lmp is installed)
expect 0 "shear_flow --out LAMMPS data" -- "$bin/shear_flow" --n 64 --strain 0.05 --out "$tmp/s.data"
expect_in s.data "^Atoms # sphere" "the data file has atom_style sphere atoms"
expect 0 "shear_flow --in LAMMPS data" -- "$bin/shear_flow" --in "$tmp/s.data" --strain 0.01
if command -v lmp > /dev/null; then
    printf 'units lj\ndimension 2\natom_style sphere\nboundary p p p\nread_data %s\nwrite_data %s\n' \
        "$tmp/s.data" "$tmp/lmp.data" > "$tmp/in.lmp"
    expect 0 "lmp reads and writes the data file" -- lmp -log none -screen none -in "$tmp/in.lmp"
    expect 0 "shear_flow --in a data file LAMMPS wrote" -- "$bin/shear_flow" --in "$tmp/lmp.data" --strain 0.01
else
    echo "skipped: lmp (Debian lammps) not installed: LAMMPS reading our data file not checked"
fi
cp "$tmp/t.csv" "$tmp/bad.data"
expect 1 "shear_flow malformed data file" -- "$bin/shear_flow" --in "$tmp/bad.data"
expect_in err "line" "shear_flow names the bad line of a data file"
expect 1 "shear_flow missing data file" -- "$bin/shear_flow" --in "$tmp/missing.data"
expect 0 "jam_packing --traj" -- "$bin/jam_packing" --n 32 --traj "$tmp/j.xyz" --traj-every 0.05 --out "$tmp/j1.xyz" \
    --quiet
expect 0 "jam_packing without --traj" -- "$bin/jam_packing" --n 32 --out "$tmp/j2.xyz" --quiet
cmp -s "$tmp/j1.xyz" "$tmp/j2.xyz" && pass=$((pass + 1)) || { echo "FAIL: jam_packing --traj changed the run"; fail=$((fail + 1)); }
[ "$(grep -c Lattice "$tmp/j.xyz")" -ge 3 ] && pass=$((pass + 1)) || { echo "FAIL: jam_packing --traj frames"; fail=$((fail + 1)); }
# the other examples: the same options, and a trajectory that never changes the run
declare -A args=(
    [compress]="--n 48 --phi 0.7 --traj-every 0.05"
    [composite]="--bodies 20 --beads 2 --phi 0.5 --strain 0.05 --every 0.01 --traj-every 0.02"
    [hopper]="--n 40 --time 4 --every 1 --traj-every 2"
    [self_propulsion]="--n 48 --time 1 --every 0.25 --traj-every 0.5"
)
for prog in compress composite hopper self_propulsion; do
    # shellcheck disable=SC2086
    expect 0 "$prog without --traj" -- "$bin/$prog" ${args[$prog]} --out "$tmp/$prog.a.xyz" --quiet
    [ -s "$tmp/err" ] && { echo "FAIL: $prog --quiet writes to stderr"; fail=$((fail + 1)); } || pass=$((pass + 1))
    # shellcheck disable=SC2086
    expect 0 "$prog with --traj" -- "$bin/$prog" ${args[$prog]} --out "$tmp/$prog.b.xyz" --traj "$tmp/$prog.t.xyz" \
        --traj-contacts "$tmp/$prog.t.bonds" --series "$tmp/$prog.csv" --plot "$tmp/$prog.svg"
    # --plot: one panel per series column after the first, with a point per row
    check_py "$prog --plot" svg "$tmp/$prog.svg" "$(rows "$prog.csv")" \
        "$(($(head -1 "$tmp/$prog.csv" | tr ',' '\n' | wc -l) - 1))"
    cmp -s "$tmp/$prog.a.xyz" "$tmp/$prog.b.xyz" && pass=$((pass + 1)) \
        || { echo "FAIL: $prog --traj changed the run"; fail=$((fail + 1)); }
    [ "$(grep -c Lattice "$tmp/$prog.t.xyz")" -ge 2 ] && [ "$(grep -c '^ITEM: TIMESTEP' "$tmp/$prog.t.bonds")" -ge 2 ] \
        && pass=$((pass + 1)) || { echo "FAIL: $prog trajectory frames"; fail=$((fail + 1)); }
    expect_in err "heun, solver auto" "$prog runs the library's defaults (heun, auto)"
    grep -q $'\r' "$tmp/err" && { echo "FAIL: $prog progress ends in CR in a file"; fail=$((fail + 1)); } \
        || pass=$((pass + 1))
    # shellcheck disable=SC2086
    expect 0 "$prog paper mode" -- "$bin/$prog" ${args[$prog]} --integrator euler --solver cg --quiet
    expect 2 "$prog bad --traj-every" -- "$bin/$prog" --traj-every -1
    expect 0 "$prog --help" -- "$bin/$prog" --help
    expect_in out "paper mode" "$prog --help names paper mode"
    expect_in out "^  --traj FILE" "$prog --help lists --traj"
    expect_in out "^  --quiet" "$prog --help lists --quiet"
done
expect 0 "softcore_shear --quiet" -- "$bin/softcore_shear" --n 32 --phi 0.6 --strain 0.002 --every 0.001 --quiet \
    --out "$tmp/sc.data"
[ -s "$tmp/err" ] && { echo "FAIL: softcore_shear --quiet writes to stderr"; fail=$((fail + 1)); } || pass=$((pass + 1))
expect_in sc.data "^Atoms # sphere" "softcore_shear --out writes a LAMMPS data file"
expect 0 "minimal --help" -- "$bin/minimal" --help
expect_in out "^usage: " "minimal --help prints usage"
expect 2 "minimal bad option" -- "$bin/minimal" --n 5
# collapse: synthetic flow curves with phi_J = 0.8433, y = 1.1, z nu = 3.5
# (1 % noise, fixed): the fit recovers them within 3 errors, draws the plot
expect 0 "collapse help" -- "$bin/collapse" --help
expect_in out "usage: collapse" "collapse --help prints usage"
expect 2 "collapse without --data" -- "$bin/collapse"
expect 2 "collapse bad --guess" -- "$bin/collapse" --data x.csv --guess 0.8
expect 2 "collapse bad --degree" -- "$bin/collapse" --data x.csv --degree 9
expect 1 "collapse missing file" -- "$bin/collapse" --data "$tmp/no-such.csv"
awk 'BEGIN { srand(5); print "phi,rate,shear_stress"
    split("1e-7 1e-6 1e-5 1e-4", r, " ")
    for (a = 1; a <= 4; ++a) for (b = 0; b <= 10; ++b) {
        phi = 0.83 + 0.003 * b; x = (phi - 0.8433) / r[a] ^ (1 / 3.5)
        g = 0.3 + 1.2 * x - 0.1 * x * x + 0.02 * x * x * x
        noise = 0.01 * ((b * 7 + a * 3) % 11 - 5) / 5
        printf "%.4f,%s,%.10g\n", phi, r[a], r[a] ^ (1.1 / 3.5) * exp(g) * (1 + noise) } }' > "$tmp/flow.csv"
expect 0 "collapse synthetic" -- "$bin/collapse" --data "$tmp/flow.csv" --guess 0.84,1,3 --plot "$tmp/col.svg" --quiet
awk '/^phi_J/ { ok1 = ($3 - 0.8433)^2 <= 9 * $5^2 } /^y / { ok2 = ($3 - 1.1)^2 <= 9 * $5^2 }
     /^z nu/ { ok3 = ($4 - 3.5)^2 <= 9 * $6^2 } END { exit !(ok1 && ok2 && ok3) }' "$tmp/out" \
    && pass=$((pass + 1)) || { echo "FAIL: collapse recovers phi_J, y, z nu"; sed 's/^/  | /' "$tmp/out"; fail=$((fail + 1)); }
[ "$(grep -c '<circle\|<rect\|<path\|<polygon' "$tmp/col.svg")" -gt 44 ] && pass=$((pass + 1)) \
    || { echo "FAIL: collapse plot"; fail=$((fail + 1)); }
# errors: a relative column (2 %) and the same as absolute errors with
# --err-absolute give the same fit; read as relative, the absolute column
# (values ~1e-2, errors ~1e-4) weighs the points differently
awk -F, 'NR == 1 { print $0 ",shear_stress_err"; next } { print $0 ",0.02" }' "$tmp/flow.csv" > "$tmp/flow_rel.csv"
awk -F, 'NR == 1 { print $0 ",shear_stress_err"; next } { printf "%s,%.10g\n", $0, 0.02 * $3 }' "$tmp/flow.csv" > "$tmp/flow_abs.csv"
expect 0 "collapse relative errors" -- "$bin/collapse" --data "$tmp/flow_rel.csv" --guess 0.84,1,3
cp "$tmp/out" "$tmp/out_rel"
expect 0 "collapse --err-absolute" -- "$bin/collapse" --data "$tmp/flow_abs.csv" --guess 0.84,1,3 --err-absolute
cmp -s <(grep -v "^collapse:" "$tmp/out_rel") <(grep -v "^collapse:" "$tmp/out") && pass=$((pass + 1)) \
    || { echo "FAIL: collapse --err-absolute differs from the relative column"; diff "$tmp/out_rel" "$tmp/out"; fail=$((fail + 1)); }
expect 0 "collapse absolute column read as relative" -- "$bin/collapse" --data "$tmp/flow_abs.csv" --guess 0.84,1,3
cmp -s <(grep -v "^collapse:" "$tmp/out_rel") <(grep -v "^collapse:" "$tmp/out") && { echo "FAIL: collapse ignores the error column"; fail=$((fail + 1)); } \
    || pass=$((pass + 1))
echo "examples-cli: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
