#!/usr/bin/env bash
# check-mpi: the tiny campaign examples/campaigns/tiny.csv run by sweep_mpi on
# 2 MPI ranks, killed (SIGKILL of every rank) once some runs are done and
# others are half-way with a checkpoint, then re-launched; every per-run file
# (series, final configuration, result), runs.csv, summary.csv and the plots
# must equal, byte for byte, those of an uninterrupted serial run
# (sweep_serial, the same source built without MPI). Also: a finished
# campaign re-launched does nothing and gives the same summary, a different
# campaign in the same directory is refused, and more ranks than runs works.
# Usage: tests/campaign_mpi.sh BINDIR   (run by `make check-mpi`)
set -u
bin=${1:-build/examples}
campaign=examples/campaigns/tiny.csv
work=build/check-mpi
rm -rf "$work"; mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OPENBLAS_NUM_THREADS=1
mpirun=(mpirun --oversubscribe --allow-run-as-root)
fail=0 pass=0
ok() { pass=$((pass + 1)); echo "  ok: $*"; }
bad() { fail=$((fail + 1)); echo "  FAIL: $*"; }
SECONDS=0
# children PID: the processes whose parent is PID (the ranks mpirun started)
children() { cat /proc/[0-9]*/stat 2>/dev/null |
    awk -v p="$1" '{ pid = $1; sub(/^.*\) /, ""); if ($2 == p) print pid }'; }

echo "== serial reference run (sweep_serial)"
"$bin/sweep_serial" --campaign "$campaign" --out "$work/serial" --quiet > "$work/serial.out" 2> "$work/serial.err"
rc=$?
[ $rc -eq 3 ] && ok "serial run exits 3 (complete, one run failed as planned)" || { bad "serial run exit $rc"; tail "$work/serial.err"; }

echo "== MPI run on 2 ranks, killed mid-way"
"${mpirun[@]}" -np 2 "$bin/sweep_mpi" --campaign "$campaign" --out "$work/mpi" > "$work/mpi1.out" 2> "$work/mpi1.err" &
mpirun_pid=$!
# Kill point: at least 2 runs finished and a checkpoint of a run that is far
# from its end (under 50 of its 61 series rows written: at least 0.1 of strain,
# a few hundred milliseconds, still to go), so that the run is certainly
# unfinished when the kill lands. Polled every 20 ms: the window is about half
# a second wide on a 2-core machine.
killed=0 ranks=
for _ in $(seq 1 3000); do
    sleep 0.02
    kill -0 $mpirun_pid 2>/dev/null || break
    # re-read until both ranks are there: mpirun may start them one at a time,
    # and a list read between the two would never reach the kill below
    [ "$(echo $ranks | wc -w)" -eq 2 ] || ranks=$(children $mpirun_pid)
    nres=$(ls "$work"/mpi/runs/*/result.csv 2>/dev/null | wc -l)
    early=0
    for ck in "$work"/mpi/runs/*/checkpoint.odhs; do
        [ -e "$ck" ] || continue
        rows=$(wc -l < "${ck%checkpoint.odhs}series.csv" 2>/dev/null || echo 999)
        [ "$rows" -lt 50 ] && early=1
    done
    if [ "$nres" -ge 2 ] && [ $early -eq 1 ] && [ "$(echo $ranks | wc -w)" -eq 2 ]; then
        nck=$(ls "$work"/mpi/runs/*/checkpoint.odhs 2>/dev/null | wc -l)
        echo "  killing ranks (pids $(echo $ranks)) with SIGKILL: $nres results, $nck checkpoints on disk"
        for p in $ranks; do kill -KILL "$p" 2>/dev/null; done
        killed=1
        break
    fi
done
wait $mpirun_pid; rc=$?
[ $killed -eq 1 ] && ok "killed mid-way (mpirun exit $rc)" \
    || bad "the campaign ended before the kill point (exit $rc; last poll: $nres results, early checkpoint $early, ranks '$(echo $ranks)')"
nres=$(ls "$work"/mpi/runs/*/result.csv 2>/dev/null | wc -l)
nck=$(ls "$work"/mpi/runs/*/checkpoint.odhs 2>/dev/null | wc -l)
nruns=$(grep -c '^[0-9]' "$campaign")
[ "$nres" -lt "$nruns" ] && [ "$nck" -ge 1 ] && ok "after the kill: $nres of $nruns results, $nck checkpoint(s)" \
    || bad "after the kill: $nres of $nruns results, $nck checkpoints"

# A kill can also land in the middle of a series row: append a torn row to
# every unfinished series, which the resume must cut away with the rows
# written after the checkpoint.
for ck in "$work"/mpi/runs/*/checkpoint.odhs; do
    [ -e "$ck" ] || continue
    f="${ck%checkpoint.odhs}series.csv"
    echo "  $(basename "$(dirname "$f")"): $(($(wc -l < "$f") - 1)) series rows at the kill, plus a torn row appended"
    printf '0.123456,9.87' >> "$f"
done

echo "== MPI run on 2 ranks, re-launched"
"${mpirun[@]}" -np 2 "$bin/sweep_mpi" --campaign "$campaign" --out "$work/mpi" > "$work/mpi2.out" 2> "$work/mpi2.err"
rc=$?
[ $rc -eq 3 ] && ok "resumed run exits 3" || { bad "resumed run exit $rc"; tail "$work/mpi2.err"; }
grep -q "already done" "$work/mpi2.err" && ok "$(grep -o '[0-9]* runs, [0-9]* already done, [0-9]* to do' "$work/mpi2.err")"
nresumed=$(grep -c "resuming from its checkpoint" "$work/mpi2.err")
[ "$nresumed" -ge 1 ] && ok "$nresumed run(s) resumed from a checkpoint" || bad "no run resumed from a checkpoint"
grep "resuming from its checkpoint" "$work/mpi2.err" | sed 's/^/    /'
grep -q "rank 1" "$work"/mpi/runs/*/timing.txt && grep -q "rank 0" "$work"/mpi/runs/*/timing.txt \
    && ok "both ranks ran runs" || bad "runs were not spread over both ranks"
ls "$work"/mpi/runs/*/checkpoint.odhs >/dev/null 2>&1 && bad "checkpoints left after completion" || ok "no checkpoint left"

echo "== killed + resumed MPI campaign against the serial one, byte for byte"
ndiff=0 nfiles=0
for f in runs.csv summary.csv eta_phi.svg z_phi.svg campaign.txt $(cd "$work/serial" && ls runs/*/series.csv runs/*/final.xyz runs/*/result.csv); do
    nfiles=$((nfiles + 1))
    cmp -s "$work/serial/$f" "$work/mpi/$f" || { echo "    differs: $f"; ndiff=$((ndiff + 1)); }
done
[ $ndiff -eq 0 ] && ok "$nfiles files identical" || bad "$ndiff of $nfiles files differ"
grep -q '^6,.*,failed,.*jammed' "$work/mpi/runs.csv" && ok "the run beyond jamming is recorded as failed with its reason" \
    || bad "runs.csv does not record run 6 as failed"
[ "$(grep -c ',ok,' "$work/mpi/runs.csv")" -eq $((nruns - 1)) ] && ok "the other $((nruns - 1)) runs are ok" \
    || bad "not all other runs are ok"

echo "== a finished campaign re-launched does nothing"
cp "$work/mpi/summary.csv" "$work/summary.before"
"${mpirun[@]}" -np 2 "$bin/sweep_mpi" --campaign "$campaign" --out "$work/mpi" > /dev/null 2> "$work/mpi3.err"
grep -q "$nruns already done, 0 to do" "$work/mpi3.err" && cmp -s "$work/summary.before" "$work/mpi/summary.csv" \
    && ok "nothing re-run, same summary" || bad "a finished campaign was re-run or changed"

echo "== a different campaign in the same directory is refused"
"${mpirun[@]}" -np 2 "$bin/sweep_mpi" --campaign "$campaign" --out "$work/mpi" --transient 0.3 > /dev/null 2> "$work/mpi4.err"
rc=$?
[ $rc -ne 0 ] && grep -q "holds a different campaign" "$work/mpi4.err" && ok "refused (exit $rc)" || bad "not refused (exit $rc)"

echo "== more ranks (3) than runs (1)"
printf 'n,phi,seed,strain\n64,0.7,1,0.3\n' > "$work/one.csv"
"${mpirun[@]}" -np 3 "$bin/sweep_mpi" --campaign "$work/one.csv" --out "$work/one" > /dev/null 2> "$work/one.err"
rc=$?
[ $rc -eq 0 ] && grep -q '^0,volume.*,ok,' "$work/one/runs.csv" && ok "done (exit 0)" || { bad "exit $rc"; tail "$work/one.err"; }

echo "campaign-mpi: $pass passed, $fail failed (${SECONDS} s)"
[ $fail -eq 0 ]
