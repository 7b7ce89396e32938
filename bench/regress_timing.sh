#!/usr/bin/env bash
# bench/regress_timing.sh - CPU time of every scene of the regression corpus
# (tests/check_regress.c) with the library of another revision and with this
# tree's, measured in the same run: scene by scene the two runners take turns,
# ROUNDS times, and each scene keeps its smallest CPU time per version. Prints a table with the
# ratio new/old per scene and the total.
#
#   bench/regress_timing.sh [OLD_REV] [ROUNDS]     (defaults: 45abb07, 5)
#   ODHS_TIMING=instructions bench/regress_timing.sh [OLD_REV]
#
# CPU time on a shared virtual machine scatters by 10-30 % per scene even as
# the smallest of several runs; the second form counts the instructions each
# scene executes instead (valgrind --tool=callgrind, about 50 times slower,
# one round): deterministic, so a difference of 0.1 % is real.
#
# The old revision is checked out in a temporary git worktree and built there
# with this tree's tests/check_regress.c and tests/data (the corpus uses only
# the public API). Run it from the top of the repository on a quiet machine.
set -euo pipefail
old=${1:-45abb07}
if [ "${ODHS_TIMING:-cpu}" = instructions ] && ! command -v valgrind >/dev/null; then
    echo "regress_timing: ODHS_TIMING=instructions needs valgrind (Debian: apt-get install valgrind)" >&2
    exit 2
fi
rounds=${2:-5}
top=$(pwd)
work=$(mktemp -d)
trap 'git -C "$top" worktree remove --force "$work/old" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT

git worktree add --detach "$work/old" "$old" >/dev/null 2>&1
# the old tree runs only the corpus suite: its own suites are not built
mkdir -p "$work/old/tests.keep"
mv "$work/old"/tests/check_*.c "$work/old/tests.keep/"
cp tests/check_main.c tests/check_regress.c "$work/old/tests/"
cp -R tests/data "$work/old/tests/"
make -C "$work/old" -s -j2 tests >/dev/null
make -s -j2 tests >/dev/null

ir() { # ir DIR LABEL SCENE: one scene under callgrind, a "label scene instructions" line
    local n
    n=$(cd "$1" && CK_RUN_SUITE=regress CK_RUN_CASE="$3" CK_FORK=no OPENBLAS_NUM_THREADS=1 \
        valgrind --tool=callgrind --callgrind-out-file=/dev/null ./build/tests/run_tests 2>&1 >/dev/null |
        sed -n 's/.*Collected : \([0-9]*\).*/\1/p') || true
    echo "$2 $3 $n"
}
run() { # run DIR LABEL SCENE: one scene, a "label scene cpu" line
    # the old revision fails the scenes whose recorded results changed since:
    # only the timings count here
    (cd "$1" && CK_RUN_SUITE=regress CK_RUN_CASE="$3" CK_FORK=no OPENBLAS_NUM_THREADS=1 \
        ./build/tests/run_tests 2>&1 >/dev/null || true) | awk -v v="$2" '/^\[regress\]/ { print v, $2, $3 }'
}
scenes=$(CK_RUN_SUITE=regress CK_FORK=no OPENBLAS_NUM_THREADS=1 ./build/tests/run_tests 2>&1 >/dev/null |
         awk '/^\[regress\]/ { print $2 }')
# scene by scene, the two versions one after the other (a drift of the
# machine's speed then hits both alike), the order of the pair alternating
unit="s"
if [ "${ODHS_TIMING:-cpu}" = instructions ]; then
    unit="Ir"
    rounds=1
    for s in $scenes; do ir "$work/old" old "$s"; ir "$top" new "$s"; done > "$work/times.txt"
else
for r in $(seq 1 "$rounds"); do
    for s in $scenes; do
        if [ $((r % 2)) -eq 1 ]; then run "$work/old" old "$s"; run "$top" new "$s";
        else run "$top" new "$s"; run "$work/old" old "$s"; fi
    done
done > "$work/times.txt"
fi

cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)
echo "# regression corpus, cost per scene, $old against $(git rev-parse --short HEAD)$(git diff --quiet || echo '+changes')"
if [ "$unit" = Ir ]; then
    echo "# machine: $cpu, $(nproc) CPUs; instructions executed per scene (callgrind), one run each"
else
    echo "# machine: $cpu, $(nproc) CPUs; $rounds rounds, scene by scene in turns, smallest CPU time per scene and version"
fi
awk -v unit="$unit" '
    { k = $1 SUBSEP $2; if (!(k in t) || $3 < t[k]) t[k] = $3; if ($1 == "new" && !($2 in seen)) { seen[$2] = 1; order[++n] = $2 } }
    END {
        printf "%-26s %14s %14s %8s\n", "scene", "old " unit, "new " unit, "new/old"
        worst = 0
        for (i = 1; i <= n; ++i) {
            s = order[i]; o = t["old" SUBSEP s]; w = t["new" SUBSEP s]
            printf "%-26s %14.6g %14.6g %8.4f\n", s, o, w, (o > 0 ? w / o : 0)
            to += o; tw += w
            if ((unit == "Ir" || o >= 0.05) && w / o > worst) { worst = w / o; ws = s }
        }
        printf "%-26s %14.6g %14.6g %8.4f\n", "total", to, tw, tw / to
        printf "# largest ratio%s: %.4f (%s)\n", unit == "Ir" ? "" : " among scenes of >= 0.05 s", worst, ws
    }' "$work/times.txt"
