#!/usr/bin/env python3
"""The documentation's programs, commands and printed outputs, checked.

Usage: docs_samples.py STAGE EXAMPLES DOC...   (run by tests/docs_samples.sh)

STAGE is a staged install (build/stage), EXAMPLES the directory of the
example programs built against it (build/examples). Exit status 0 when every
check passes, 1 otherwise (each failure says which document, block and line,
and what was expected against what was printed).

What is checked
---------------
* Every ```c block is a complete program: compiled with
  `cc -std=c11 -Wall -Wextra -Werror` and the staged pkg-config flags only,
  then run (OPENBLAS_NUM_THREADS=1, in a scratch directory); it must exit 0.
* Its standard output is compared with the block marked, right after the
  program (no other code block in between), by the comment
      <!-- docs-test: output of the program above -->
  A program that prints without such a block fails, unless it is marked
      <!-- docs-test: output not shown: REASON -->
  (then it is still compiled and run, and the reason is listed).
* A ```text (or bare ```) block whose first line starts with "$ " shows
  commands and what they print; every such block is run and compared, unless
  it is preceded by <!-- docs-test: not checked: REASON -->. In a program's
  output block, the lines from the first "$ " line on are commands run after
  the program, in the same scratch directory. Commands run with bash from
  that directory, with PATH = EXAMPLES:/usr/bin:$PATH (so `shear_flow` is the
  example built against the stage), stdin from /dev/null, and must exit 0.
  A command's expected lines that start with "NAME: ", NAME being the
  command's program (the first word), are compared with its standard error,
  the others with its standard output, each stream in order.
* The guide's statement "compiled and run against version X.Y.Z" must name
  the staged version (ODHS_VERSION_* in the staged odhs/common.h, and the
  pkg-config module version).

How lines are compared
----------------------
* Whitespace is normalised: lines are split into whitespace-separated
  tokens; trailing empty lines are ignored.
* Numbers (an optional sign, digits with an optional decimal point and
  exponent) are compared as numbers, the text around them exactly.
  Integers (no point, no exponent) must be equal; other numbers must agree to
  a relative tolerance of 1e-6 (|a - b| <= 1e-6 max(|a|, |b|)), so -0.000 and
  +0.000 agree. The printed digits are what is compared: a number printed
  with four digits must print the same four digits.
* A line consisting of "..." tokens only (an elision in the document) stands
  for any number of lines, zero included. The lines before the first elision
  are matched at the start of the output, those after the last one at its
  end, and those between two elisions at their first match in between.

Per-block options, as comments right before the block (each needs a reason):
    <!-- docs-test: mask "REGEX" REASON -->  replace what REGEX (Python re)
        matches by <masked> in expected and printed lines before comparing;
        for fields that are not reproducible (elapsed seconds). A mask that
        matches no expected line is an error.
    <!-- docs-test: drop "REGEX" REASON -->  remove printed lines that REGEX
        matches (progress lines printed on a wall-clock schedule).
    <!-- docs-test: rtol X REASON -->  a relative tolerance other than 1e-6.
    <!-- docs-test: needs COMMAND -->  run the block only when COMMAND (bash,
        same PATH) succeeds; otherwise it is reported as skipped.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

RTOL = 1e-6
TIMEOUT = 120.0  # seconds per program or command; a shown run should take < 20 s
SLOW = 20.0

NUM = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
DIRECTIVE = re.compile(r"^<!--\s*docs-test:\s*(.*?)\s*-->\s*$")
FENCE_OPEN = re.compile(r"^```(\w*)\s*$")
QUOTED = re.compile(r'^(mask|drop)\s+"((?:[^"\\]|\\.)*)"\s*(.*)$')


class DocError(Exception):
    pass


# ---------------------------------------------------------------- parsing


class Block:
    """A fenced block: lang, lines (with their document line numbers)."""

    def __init__(self, doc, lang, start):
        self.doc, self.lang, self.start = doc, lang, start
        self.lines = []  # (lineno, text)
        self.options = []  # (lineno, directive text)


class Program:
    def __init__(self, block):
        self.block = block
        self.output = None  # Block with the expected output
        self.not_shown = None  # reason


def parse(doc):
    """Programs and command blocks of one Markdown file."""
    with open(doc, encoding="utf-8") as f:
        text = f.read().split("\n")
    programs, commands, errors = [], [], []
    pending = []  # (lineno, directive) before the next fence
    last_fence = None  # the last closed Block
    cur = None
    for k, line in enumerate(text, 1):
        if cur is not None:
            if line.rstrip() == "```":
                close(cur, pending, last_fence, programs, commands, errors)
                last_fence, cur, pending = cur, None, []
            else:
                cur.lines.append((k, line))
            continue
        m = FENCE_OPEN.match(line)
        if m:
            cur = Block(doc, m.group(1), k)
            continue
        m = DIRECTIVE.match(line)
        if m:
            d = m.group(1)
            if d.startswith("output not shown:"):
                prog = programs[-1] if programs and last_fence is programs[-1].block else None
                reason = d[len("output not shown:"):].strip()
                if prog is None or not reason:
                    errors.append(f"{doc}:{k}: 'output not shown' needs a reason and must follow a ```c block")
                elif prog.output or prog.not_shown:
                    errors.append(f"{doc}:{k}: the program at line {prog.block.start} already has an output marker")
                else:
                    prog.not_shown = reason
            else:
                pending.append((k, d))
            continue
        if "docs-test" in line and "<!--" in line:
            errors.append(f"{doc}:{k}: a docs-test comment must be a line of its own: <!-- docs-test: ... -->")
        if line.strip() and pending:
            errors.append(f"{doc}:{pending[0][0]}: docs-test comment not followed by a code block")
            pending = []
    if cur is not None:
        errors.append(f"{doc}:{cur.start}: code block not closed")
    if pending:
        errors.append(f"{doc}:{pending[0][0]}: docs-test comment not followed by a code block")
    return programs, commands, errors


def close(block, pending, last_fence, programs, commands, errors):
    doc = block.doc
    kinds = [d for _, d in pending]
    if block.lang == "c":
        if pending:
            errors.append(f"{doc}:{pending[0][0]}: docs-test comment before a ```c block")
        programs.append(Program(block))
        return
    is_output = "output of the program above" in kinds
    block.options = [(k, d) for k, d in pending if d != "output of the program above"]
    if is_output:
        prog = programs[-1] if programs and last_fence is programs[-1].block else None
        if block.lang not in ("", "text"):
            errors.append(f"{doc}:{block.start}: an output block must be ```text or ```")
        elif prog is None:
            errors.append(f"{doc}:{block.start}: 'output of the program above' does not follow a ```c block")
        elif prog.output or prog.not_shown:
            errors.append(f"{doc}:{block.start}: the program at line {prog.block.start} already has an output")
        else:
            prog.output = block
        return
    first = next((t for _, t in block.lines if t.strip()), "")
    if block.lang in ("", "text") and first.startswith("$ "):
        commands.append(block)
    elif block.options:
        errors.append(f"{doc}:{block.options[0][0]}: docs-test options on a block that is not checked")


def block_options(block):
    """(rtol, masks, drops, needs, not_checked) of a block's directives."""
    rtol, masks, drops, needs, skip = RTOL, [], [], None, None
    for k, d in block.options:
        where = f"{block.doc}:{k}"
        m = QUOTED.match(d)
        if m:
            kind, rx, reason = m.groups()
            if not reason:
                raise DocError(f"{where}: '{kind}' needs a reason after the pattern")
            try:
                pat = re.compile(rx.replace('\\"', '"'))
            except re.error as e:
                raise DocError(f"{where}: bad pattern {rx!r}: {e}")
            (masks if kind == "mask" else drops).append((k, pat, reason))
        elif d.startswith("rtol "):
            parts = d.split(None, 2)
            if len(parts) < 3:
                raise DocError(f"{where}: 'rtol X REASON' needs a reason")
            rtol = float(parts[1])
        elif d.startswith("needs "):
            needs = d[len("needs "):].strip()
        elif d.startswith("not checked:") and d[len("not checked:"):].strip():
            skip = d[len("not checked:"):].strip()
        else:
            raise DocError(f"{where}: unknown docs-test directive {d!r}")
    for k, pat in unused_masks(block, masks):
        raise DocError(f"{block.doc}:{k}: mask {pat.pattern!r} matches no line of the block")
    return rtol, masks, drops, needs, skip


# ---------------------------------------------------------------- comparing


def is_elision(text):
    toks = text.split()
    return bool(toks) and all(t == "..." for t in toks)


def split_numbers(tok):
    nums = NUM.findall(tok)
    return NUM.sub("#", tok), nums


def num_equal(a, b, rtol):
    if not re.search(r"[.eE]", a) and not re.search(r"[.eE]", b):
        return int(a) == int(b)
    x, y = float(a), float(b)
    return x == y or abs(x - y) <= rtol * max(abs(x), abs(y))


def line_diff(exp, got, rtol):
    """None when the lines agree, else a short reason."""
    te, tg = exp.split(), got.split()
    if len(te) != len(tg):
        return f"{len(te)} fields expected, {len(tg)} printed"
    for a, b in zip(te, tg):
        sa, na = split_numbers(a)
        sb, nb = split_numbers(b)
        if sa != sb or len(na) != len(nb):
            return f"{a!r} expected, {b!r} printed"
        for x, y in zip(na, nb):
            if not num_equal(x, y, rtol):
                return f"number {x} expected, {y} printed"
    return None


def trim(lines):
    while lines and not lines[-1][1].strip():
        lines = lines[:-1]
    return lines


def compare(expected, got, rtol, anchor):
    """expected: [(lineno, text)], got: [text]; anchor: the line number to name
    when the block shows no line. Returns a list of failures (lineno, expected
    text, printed text or None, reason); empty on success."""
    expected, got = trim(expected), [g for _, g in trim([(0, g) for g in got])]
    segs, seg = [], []
    for e in expected:
        if is_elision(e[1]):
            segs.append(seg)
            seg = []
        else:
            seg.append(e)
    segs.append(seg)
    fails = []
    if len(segs) == 1:
        for i, (k, e) in enumerate(expected):
            g = got[i] if i < len(got) else None
            why = "missing line" if g is None else line_diff(e, g, rtol)
            if why:
                fails.append((k, e, g, why))
        if len(got) > len(expected):
            fails.append((expected[-1][0] if expected else anchor, "(no more lines)", got[len(expected)],
                          f"{len(got) - len(expected)} more lines printed"))
        return fails
    head, tail, mids = segs[0], segs[-1], segs[1:-1]
    if len(head) + len(tail) + sum(map(len, mids)) > len(got):
        k = expected[0][0]
        return [(k, "(the block)", None, f"{len(got)} lines printed, fewer than the "
                 f"{len(head) + len(tail) + sum(map(len, mids))} shown outside the elisions")]
    for i, (k, e) in enumerate(head):
        why = line_diff(e, got[i], rtol)
        if why:
            fails.append((k, e, got[i], why))
    off = len(got) - len(tail)
    for i, (k, e) in enumerate(tail):
        why = line_diff(e, got[off + i], rtol)
        if why:
            fails.append((k, e, got[off + i], why))
    pos = len(head)
    for seg in mids:
        if not seg:
            continue
        for p in range(pos, off - len(seg) + 1):
            if all(line_diff(e, got[p + i], rtol) is None for i, (_, e) in enumerate(seg)):
                pos = p + len(seg)
                break
        else:
            fails.append((seg[0][0], seg[0][1], None, "not found between the elisions"))
    return fails


def apply_masks(lines, masks):
    out = []
    for k, t in lines:
        for _, pat, _ in masks:
            t = pat.sub("<masked>", t)
        out.append((k, t))
    return out


def unused_masks(block, masks):
    """the masks that match no line of the block (stale masks are errors)"""
    return [(k, pat) for k, pat, _ in masks if not any(pat.search(t) for _, t in block.lines)]


# ---------------------------------------------------------------- running


class Runner:
    def __init__(self, stage, examples):
        self.stage = os.path.abspath(stage)
        self.examples = os.path.abspath(examples)
        self.env = dict(os.environ, OPENBLAS_NUM_THREADS="1", LC_ALL="C",
                        PATH=f"{self.examples}:/usr/bin:{os.environ.get('PATH', '')}")
        pc = dict(self.env, PKG_CONFIG_PATH=os.path.join(self.stage, "lib", "pkgconfig"))
        r = subprocess.run(["pkg-config", "--cflags", "--libs", "odhs"], env=pc, capture_output=True, text=True)
        if r.returncode:
            raise DocError(f"pkg-config finds no odhs in {stage}: {r.stderr.strip()}")
        self.flags = r.stdout.split()
        self.modversion = subprocess.run(["pkg-config", "--modversion", "odhs"], env=pc, capture_output=True,
                                         text=True).stdout.strip()
        self.tmp = tempfile.mkdtemp(prefix="docs_samples.")
        self.fails = self.passes = self.skips = 0
        self.notes = []

    def fail(self, where, msg):
        self.fails += 1
        print(f"FAIL: {where}: {msg}")

    def run(self, argv, cwd, shell=False):
        t0 = time.time()
        try:
            r = subprocess.run(argv, cwd=cwd, env=self.env, shell=shell, executable="/bin/bash" if shell else None,
                               stdin=subprocess.DEVNULL, capture_output=True, timeout=TIMEOUT)
            rc, out, err = r.returncode, r.stdout.decode(errors="replace"), r.stderr.decode(errors="replace")
        except subprocess.TimeoutExpired:
            rc, out, err = None, "", ""
        return rc, out, err, time.time() - t0

    def report(self, where, fails, what):
        self.fail(where, f"{what} differs from the document ({len(fails)} line{'s' if len(fails) > 1 else ''})")
        for k, e, g, why in fails[:6]:
            print(f"  line {k}: {why}")
            print(f"    expected: {e.strip()}")
            print(f"    printed:  {g.strip() if g is not None else '(nothing)'}")
        if len(fails) > 6:
            print(f"  ... and {len(fails) - 6} more")

    def program(self, n, prog):
        b = prog.block
        where = f"{b.doc}:{b.start} (program)"
        d = os.path.join(self.tmp, f"p{n}")
        os.mkdir(d)
        src, exe = os.path.join(d, "prog.c"), os.path.join(d, "prog")
        with open(src, "w") as f:
            f.write("\n".join(t for _, t in b.lines) + "\n")
        cc = ["cc", "-std=c11", "-Wall", "-Wextra", "-Werror", src] + self.flags + \
             ["-lm", f"-Wl,-rpath,{os.path.join(self.stage, 'lib')}", "-o", exe]
        r = subprocess.run(cc, capture_output=True, text=True, env=self.env)
        if r.returncode:
            self.fail(where, "does not compile:\n  " + "\n  ".join(r.stderr.splitlines()[:5]))
            return
        opts = block_options(prog.output) if prog.output else (RTOL, [], [], None, None)
        if prog.output and opts[3] and not self.needs(where, opts[3], d):
            return
        rc, out, err, dt = self.run([exe], d)
        if rc != 0:
            why = "timed out" if rc is None else f"exits with status {rc}"
            self.fail(where, why + ("\n  " + "\n  ".join(err.splitlines()[:5]) if err else ""))
            return
        if prog.output is None:
            if prog.not_shown:
                self.notes.append(f"{where}: output not compared ({prog.not_shown})")
            elif out.strip():
                n = len(out.splitlines())
                self.fail(where, f"prints {n} line{'s' if n > 1 else ''} but no block is marked "
                          "'<!-- docs-test: output of the program above -->' (or 'output not shown: REASON')")
                return
            self.ok(where, dt)
            return
        segs = split_commands(prog.output)
        if self.compare(f"{prog.output.doc}:{prog.output.start} (output of the program at line {b.start})",
                        prog.output.start, segs[0][1], out, opts, "its output"):
            total = dt + self.commands(prog.output, segs[1:], d, opts)
            if total >= 0:
                self.ok(where, total)

    def needs(self, where, cmd, cwd):
        rc, _, _, _ = self.run(cmd, cwd, shell=True)
        if rc != 0:
            self.skips += 1
            print(f"skipped: {where}: needs `{cmd}`, which fails here")
            return False
        return True

    def command_block(self, n, block):
        where = f"{block.doc}:{block.start} (commands)"
        opts = block_options(block)
        if opts[4]:
            self.notes.append(f"{where}: not checked ({opts[4]})")
            return
        d = os.path.join(self.tmp, f"c{n}")
        os.mkdir(d)
        if opts[3] and not self.needs(where, opts[3], d):
            return
        segs = split_commands(block)
        if segs[0][1]:
            self.fail(where, "lines before the first command")
            return
        t = self.commands(block, segs[1:], d, opts)
        if t >= 0:
            self.ok(where, t)

    def commands(self, block, segs, cwd, opts):
        """Run the commands of a block; their total time, or -1 after a failure."""
        total = 0.0
        for (k, cmd), lines in segs:
            where = f"{block.doc}:{k} `{cmd[:60]}{'...' if len(cmd) > 60 else ''}`"
            rc, out, err, dt = self.run(cmd, cwd, shell=True)
            total += dt
            if dt > SLOW:
                self.notes.append(f"{where}: took {dt:.0f} s (over {SLOW:.0f} s: shorten it)")
            if rc != 0:
                why = "timed out" if rc is None else f"exits with status {rc}"
                self.fail(where, why + ("\n  " + "\n  ".join(err.splitlines()[-5:]) if err else ""))
                return -1
            prog = os.path.basename(cmd.split()[0]) + ": "
            exp_err = [(n, t) for n, t in lines if t.lstrip().startswith(prog)]
            exp_out = [(n, t) for n, t in lines if not t.lstrip().startswith(prog)]
            ok = self.compare(where, k, exp_out, out, opts, "standard output") and \
                self.compare(where, k, exp_err, err, opts, "standard error")
            if not ok:
                return -1
        return total

    def compare(self, where, anchor, expected, printed, opts, what):
        rtol, masks, drops = opts[:3]
        got = [g for g in printed.split("\n") if not any(p.search(g) for _, p, _ in drops)]
        exp = apply_masks(expected, masks)
        got = [t for _, t in apply_masks([(0, g) for g in got], masks)]
        fails = compare(exp, got, rtol, anchor)
        if fails:
            self.report(where, fails, what)
            return False
        return True

    def ok(self, where, dt):
        self.passes += 1
        print(f"ok: {where} ({dt:.1f} s)")


def split_commands(block):
    """[(None, lines before the first command), ((lineno, command), lines)...]"""
    segs = [(None, [])]
    for k, t in block.lines:
        if t.startswith("$ "):
            segs.append(((k, t[2:].strip()), []))
        else:
            segs[-1][1].append((k, t))
    return segs


def check_version(runner, docs):
    hdr = os.path.join(runner.stage, "include", "odhs", "common.h")
    with open(hdr, encoding="utf-8") as f:
        h = f.read()
    parts = [re.search(rf"#define\s+ODHS_VERSION_{p}\s+(\d+)", h) for p in ("MAJOR", "MINOR", "PATCH")]
    if not all(parts):
        raise DocError(f"{hdr}: no ODHS_VERSION_MAJOR/MINOR/PATCH")
    version = ".".join(m.group(1) for m in parts)
    if runner.modversion != version:
        runner.fail("pkg-config", f"odhs.pc says version {runner.modversion}, odhs/common.h {version}")
    for doc in docs:
        with open(doc, encoding="utf-8") as f:
            for k, line in enumerate(f, 1):
                m = re.search(r"compiled and run against version (\S+?)\.?(\s|$)", line)
                if m:
                    if m.group(1) != version:
                        runner.fail(f"{doc}:{k}", f"says the programs were run against version {m.group(1)}; "
                                    f"the staged library is {version}")
                    else:
                        runner.passes += 1
                        print(f"ok: {doc}:{k} (version {version})")
                    break
            else:
                if os.path.basename(doc) == "guide.md":
                    runner.fail(doc, "no statement 'compiled and run against version X.Y.Z'")


def main(argv):
    if len(argv) < 4:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    t0 = time.time()
    try:
        runner = Runner(argv[1], argv[2])
    except DocError as e:
        print(f"FAIL: {e}")
        return 1
    try:
        check_version(runner, argv[3:])
        n = 0
        for doc in argv[3:]:
            programs, commands, errors = parse(doc)
            for e in errors:
                runner.fail(e, "malformed docs-test markup")
            for p in programs:
                n += 1
                try:
                    runner.program(n, p)
                except DocError as e:
                    runner.fail(e, "malformed docs-test markup")
            for b in commands:
                n += 1
                try:
                    runner.command_block(n, b)
                except DocError as e:
                    runner.fail(e, "malformed docs-test markup")
    finally:
        shutil.rmtree(runner.tmp, ignore_errors=True)
    for note in runner.notes:
        print(f"note: {note}")
    print(f"docs-samples: {runner.passes} passed, {runner.fails} failed, {runner.skips} skipped "
          f"({time.time() - t0:.0f} s)")
    return 0 if runner.fails == 0 and runner.passes > 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
