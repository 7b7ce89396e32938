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
[ "$(wc -l < "$tmp/s.csv")" -eq 4 ] && pass=$((pass + 1)) || { echo "FAIL: shear_flow series rows"; fail=$((fail + 1)); }
expect 0 "shear_flow at fixed pressure" -- "$bin/shear_flow" --in "$tmp/s.xyz" --strain 0.01 --pressure 5 \
    --series "$tmp/p.csv"
expect_in p.csv "^strain,shear_stress,pressure,z,events,phi,kappa$" "shear_flow --pressure series has phi and kappa"
expect 0 "shear_flow --pressure 1000 with the default cg (auto rescues it)" -- "$bin/shear_flow" --n 48 \
    --pressure 1000 --strain 0.02
expect_in out "phi          kappa" "shear_flow --pressure table has phi and kappa"
[ "$(awk -F, 'NR > 1 && NF != 7' "$tmp/p.csv" | wc -l)" -eq 0 ] && pass=$((pass + 1)) || { echo "FAIL: shear_flow --pressure rows have 7 fields"; fail=$((fail + 1)); }
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
[ "$(wc -l < "$tmp/o.csv")" -eq 10 ] && pass=$((pass + 1)) || { echo "FAIL: shear_flow --oscillate series rows"; fail=$((fail + 1)); }
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
grep -q "^# libodhs contacts" "$tmp/j.con" && pass=$((pass + 1)) || { echo "FAIL: jam_packing contacts"; fail=$((fail + 1)); }
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
expect_in out "usage: sweep_mpi" "sweep_serial --help prints usage"
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
    expect_in out "^  --solver NAME  *linear solver: cg, dense, cholmod, cholmod-pcg, spqr$" "$prog --solver reads as in the other examples"
    expect_in out "^  --out FILE.xyz  *write the final configuration (extended XYZ)$" "$prog --out reads as in the other examples"
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
expect_in err "(default cholmod when built in, else cg)" "sweep_serial usage after a bad solver shows the default"
echo "examples-cli: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
