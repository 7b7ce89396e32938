#!/usr/bin/env bash
# Every ```c block of docs/guide.md and README.md is a complete program: build
# each against the staged install with pkg-config only, and run it.
set -u
stage=${1:-build/stage}
pc="PKG_CONFIG_PATH=$stage/lib/pkgconfig"
flags=$(env "$pc" pkg-config --cflags --libs odhs)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0
for doc in README.md docs/guide.md; do
    awk -v dir="$tmp" -v base="$(basename "$doc" .md)" \
        '/^```c$/{f=1; n++; fn=dir "/" base "_" n ".c"; next} /^```$/{f=0} f{print > fn}' "$doc"
done
for src in "$tmp"/*.c; do
    [ -e "$src" ] || continue
    exe=${src%.c}
    if ! cc -std=c11 -Wall -Wextra -Werror "$src" $flags -lm -Wl,-rpath,"$(cd "$stage/lib" && pwd)" \
            -o "$exe" 2>"$tmp/err"; then
        echo "FAIL: $(basename "$src") does not compile:"; head -5 "$tmp/err"; fail=$((fail + 1)); continue
    fi
    if ! "$exe" >/dev/null 2>"$tmp/err"; then
        echo "FAIL: $(basename "$src") exits non-zero:"; head -5 "$tmp/err"; fail=$((fail + 1)); continue
    fi
    pass=$((pass + 1))
done
echo "docs-samples: $pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -gt 0 ]
