#!/usr/bin/env bash
# Link a test program against libodhs in every documented way, run it, and
# check how it was linked (make check-link, make pkgconfig-test).
#
#   bash tests/link_check.sh STAGE PROGRAM [DOC...]
#
# STAGE is a staged install (make stage: STAGE/lib/pkgconfig/odhs.pc,
# STAGE/lib/libodhs.{a,so}); PROGRAM a C file using libodhs (the Makefile's
# TEST_STANDALONE). Run from the source tree (the source-tree link line uses
# lib/libodhs.a and `make -s print-libs`).
#
# The link lines are
#  - every line of a ```sh block of each DOC (make check-link: README.md and
#    docs/guide.md) that starts with `cc ` or `gcc ` (a line ending in a
#    backslash continues on the next one), with its first *.c word replaced
#    by PROGRAM and a trailing `# comment` removed;
#  - the three pkg-config links, in case a document loses one, with
#    $LINK_CHECK_CFLAGS (the Makefile's CONSUMER_CFLAGS: warnings as errors,
#    so the public headers stay clean): shared; static archive (pkg-config
#    --static, -lodhs replaced by -l:libodhs.a); fully static (cc -static).
# Each runs with PKG_CONFIG_PATH=STAGE/lib/pkgconfig in a shell without the
# caller's make variables, gets `-o FILE` appended, and the program must exit
# 0 (LD_LIBRARY_PATH=STAGE/lib, as the doc lines have no rpath). The kind of
# link is read from the line: `-static` fully static (no dynamic section at
# all), `libodhs.a` the static archive (no NEEDED libodhs), otherwise shared
# (NEEDED libodhs.so.MAJOR). A fully static link is skipped, with the reason,
# when a static library it needs is missing (odhs.pc's static_missing, or a
# -l flag of `pkg-config --static --libs odhs` without its .a, or libc.a).
# Exit status 1 when a link or run fails, or a DOC has no link line.
set -u
if [ $# -lt 2 ]; then
    echo "usage: $0 STAGE PROGRAM [DOC...]" >&2
    exit 2
fi
stage=$(cd "$1" && pwd) || exit 2
prog=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
shift 2
cc=${CC:-cc}
cflags=${LINK_CHECK_CFLAGS:-}
out=${LINK_CHECK_DIR:-build/link-check}

# A user's shell: no make variables (a `make -s print-libs` inside a line must
# not join the caller's jobserver or print directories), only the stage.
unset MAKEFLAGS MFLAGS MAKELEVEL MAKEOVERRIDES GNUMAKEFLAGS
export PKG_CONFIG_PATH=$stage/lib/pkgconfig
if ! pkg-config --exists odhs; then
    echo "link-check: no odhs.pc in $PKG_CONFIG_PATH (run make stage)"
    exit 1
fi
rm -rf "$out" && mkdir -p "$out" || exit 1
out=$(cd "$out" && pwd)
libdir=$(pkg-config --variable=libdir odhs)
soname=$(readelf -d "$libdir/libodhs.so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')

pass=0 fail=0 skip=0
n=0
declare -A seen=()

# Why a fully static link cannot work here ("" when it can): static
# libraries that are missing.
static_missing() {
    local missing dirs f lib a d found
    missing=$(pkg-config --variable=static_missing odhs)
    dirs=$(pkg-config --static --libs-only-L odhs | sed 's/-L//g')
    for f in $(pkg-config --static --libs-only-l odhs) -lc; do
        lib=${f#-l}
        [ "$lib" = odhs ] && continue
        a=lib$lib.a found=
        for d in $dirs; do
            [ -e "$d/$a" ] && found=1 && break
        done
        [ -n "$found" ] || [ "$("$cc" -print-file-name="$a")" != "$a" ] || missing="$missing -l$lib"
    done
    # each name once
    echo "$missing" | tr ' ' '\n' | awk 'NF && !seen[$0]++' | tr '\n' ' ' | sed 's/ $//'
}
missing_static=$(static_missing)

# check_line ORIGIN LINE: link PROGRAM with LINE, run it, check the result.
check_line() {
    local origin=$1 line=$2 cmd kind exe log dyn
    local re='(^|[[:space:]])([^[:space:]]+\.c)([[:space:]]|$)'
    # a trailing comment goes; the first *.c word is the program
    cmd=$(printf '%s\n' "$line" | sed -E 's/[[:space:]]+#[^'\''"]*$//')
    if [[ $cmd =~ $re ]]; then
        cmd=${cmd/"${BASH_REMATCH[2]}"/$(printf '%q' "$prog")}
    else
        echo "FAIL [$origin] no *.c file in: $line"
        fail=$((fail + 1))
        return 0
    fi
    if [ -n "${seen[$cmd]:-}" ]; then
        return 0                        # the same line from a document
    fi
    seen[$cmd]=1
    n=$((n + 1))
    exe=$out/prog$n log=$out/prog$n.log
    if printf '%s\n' "$cmd" | grep -Eq '(^|[[:space:]])-static([[:space:]]|$)'; then
        kind="fully static"
    elif printf '%s\n' "$cmd" | grep -q 'libodhs\.a'; then
        kind="static libodhs.a"
    else
        kind="shared libodhs.so"
    fi
    printf '%s\n' "$origin: $line" > "$log"
    if [ "$kind" = "fully static" ] && [ -n "$missing_static" ]; then
        echo "SKIPPED [$origin] $kind: no static library (.a) for: $missing_static"
        case " $missing_static " in
        *" -lmetis "*)
            echo "        (Debian 12's libmetis-dev has no libmetis.a: METIS built from source, or" \
                 "make SUITESPARSE=0, links fully statically)" ;;
        esac
        skip=$((skip + 1))
        return 0
    fi
    if ! bash -c "$cmd -o \"\$1\"" link "$exe" >> "$log" 2>&1; then
        echo "FAIL [$origin] $kind: link failed: $cmd"
        grep -v 'statically linked applications requires at runtime' "$log" | sed -n '2,11p'
        fail=$((fail + 1))
        return 0
    fi
    if ! LD_LIBRARY_PATH=$stage/lib "$exe" >> "$log" 2>&1; then
        echo "FAIL [$origin] $kind: the program exits non-zero: $cmd"
        sed -n '2,11p' "$log"
        fail=$((fail + 1))
        return 0
    fi
    dyn=$(readelf -d "$exe" 2>&1)
    case $kind in
    "fully static")
        if ! printf '%s\n' "$dyn" | grep -q 'There is no dynamic section' ||
           ! file "$exe" | grep -q 'statically linked'; then
            echo "FAIL [$origin] $kind: not statically linked: $(file -b "$exe")"
            fail=$((fail + 1))
            return 0
        fi ;;
    "static libodhs.a")
        if printf '%s\n' "$dyn" | grep -q 'NEEDED.*libodhs'; then
            echo "FAIL [$origin] $kind: the program needs libodhs.so: $cmd"
            fail=$((fail + 1))
            return 0
        fi ;;
    *)
        if ! printf '%s\n' "$dyn" | grep -q "NEEDED.*\[$soname\]"; then
            echo "FAIL [$origin] $kind: the program does not need $soname: $cmd"
            fail=$((fail + 1))
            return 0
        fi ;;
    esac
    echo "ok   [$origin] $kind: $line"
    pass=$((pass + 1))
}

# The link lines of the documents: "FILE:LINE<TAB>line" records.
doc_lines() {
    awk '
        function strip_bs(t) { sub(/[[:space:]]*\\$/, "", t); return t }
        /^```sh[[:space:]]*$/ { insh = 1; next }
        /^```/                { insh = 0; next }
        !insh                 { next }
        cont != "" {                      # continuation of a link line
            t = $0; sub(/^[[:space:]]+/, "", t); cont = cont " " strip_bs(t)
            if ($0 !~ /\\$/) { print start "\t" cont; cont = "" }
            next
        }
        /^(cc|gcc)[[:space:]]/ {
            if ($0 ~ /\\$/) { start = FILENAME ":" FNR; cont = strip_bs($0) }
            else print FILENAME ":" FNR "\t" $0
        }
    ' "$1"
}

for doc in "$@"; do
    found=0
    while IFS=$'\t' read -r origin line; do
        found=1
        check_line "$origin" "$line"
    done < <(doc_lines "$doc")
    if [ "$found" -eq 0 ]; then
        echo "FAIL [$doc] no link line (a line starting with cc or gcc in a \`\`\`sh block)"
        fail=$((fail + 1))
    fi
done

# The pkg-config links, should a document lose one (skipped when a document
# had the same line).
cc_line="$cc${cflags:+ $cflags}"
check_line "pkg-config" "$cc_line prog.c \$(pkg-config --cflags --libs odhs) -lm"
check_line "pkg-config" "$cc_line prog.c \$(pkg-config --cflags odhs) \$(pkg-config --static --libs odhs | sed 's/-lodhs /-l:libodhs.a /') -lm"
check_line "pkg-config" "$cc_line -static prog.c \$(pkg-config --static --cflags --libs odhs) -lm"

echo "link-check: $pass passed, $fail failed, $skip skipped (logs and programs: $out)"
[ "$fail" -eq 0 ]
