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
for prog in shear_flow compress; do
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
expect 0 "shear_flow at fixed pressure" -- "$bin/shear_flow" --in "$tmp/s.xyz" --strain 0.01 --pressure 5
expect 0 "shear_flow 3D built-in" -- "$bin/shear_flow" --dim 3 --n 32 --phi 0.4 --strain 0.01
expect 0 "shear_flow dense solver" -- "$bin/shear_flow" --n 32 --phi 0.6 --strain 0.01 --solver dense
expect 0 "shear_flow adaptive" -- "$bin/shear_flow" --n 32 --phi 0.6 --strain 0.01 --integrator heun --tol 1e-8
expect 2 "shear_flow bad integrator" -- "$bin/shear_flow" --integrator rk9
expect 2 "shear_flow bad tol" -- "$bin/shear_flow" --tol 2
expect 0 "jam_packing help" -- "$bin/jam_packing" --help
expect 2 "jam_packing bad protocol" -- "$bin/jam_packing" --protocol squash
expect 0 "jam_packing compress" -- "$bin/jam_packing" --n 32 --svg "$tmp/j.svg" --contacts "$tmp/j.con" --out "$tmp/j.xyz"
expect_in out "jammed                 yes" "jam_packing certifies a jammed packing"
head -c 4 "$tmp/j.svg" | grep -q "<svg" && pass=$((pass + 1)) || { echo "FAIL: jam_packing svg"; fail=$((fail + 1)); }
grep -q "^# libodhs contacts" "$tmp/j.con" && pass=$((pass + 1)) || { echo "FAIL: jam_packing contacts"; fail=$((fail + 1)); }
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
echo "examples-cli: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
