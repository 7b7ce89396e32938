"""Build script of the ``odhs._cffi`` extension (cffi, API mode).

The C declarations given to cffi (the *cdef*) are generated from the public
headers of the libodhs being built against, at build time, so that the
bindings follow additions to the C API without a hand-written copy: every
function, type, enum constant and integer macro of ``odhs.h`` is declared.
The extension is then compiled by the system C compiler with ``#include
<odhs.h>`` and linked with ``-lodhs``, so a signature that disagrees with the
header is a compile error, not a crash.

Where the library is found, first match wins:

1. ``ODHS_INCLUDE_DIR`` and ``ODHS_LIB_DIR`` in the environment;
2. ``pkg-config odhs`` (honours ``PKG_CONFIG_PATH``; ``make python`` points it
   at the staged install ``build/stage``);
3. the build tree around this directory (``../include``, ``../lib`` after
   ``make``).

The extension gets an RPATH to the library directory, so neither
``LD_LIBRARY_PATH`` nor ``ldconfig`` is needed to import it.

Used three ways:

* by setuptools (``setup.py``: ``cffi_modules=["odhs_build.py:ffibuilder"]``)
  for ``pip install ./python``;
* as a script, ``python3 odhs_build.py [--outdir DIR]``, which compiles the
  extension into ``odhs/`` next to this file (``make python``), so that
  ``PYTHONPATH=python`` imports the package;
* ``python3 odhs_build.py --print-cdef`` prints the generated declarations.
"""

import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

# ---------------------------------------------------------------------------
# Locating the library
# ---------------------------------------------------------------------------


class LibraryNotFound(RuntimeError):
    """libodhs (headers and shared library) could not be located."""


def _pkg_config(*args):
    exe = os.environ.get("PKG_CONFIG", "pkg-config")
    try:
        out = subprocess.run([exe, *args, "odhs"], check=True, capture_output=True, text=True)
    except (OSError, subprocess.CalledProcessError):
        return None
    return out.stdout.strip()


def find_odhs():
    """Where libodhs is: a dict with include_dir, lib_dir, cflags (-I...),
    libs (-L... -lodhs), version and how it was found ("env", "pkg-config",
    "build tree"). Raises LibraryNotFound."""
    inc, libdir = os.environ.get("ODHS_INCLUDE_DIR"), os.environ.get("ODHS_LIB_DIR")
    if inc and libdir:
        return {"include_dir": inc, "lib_dir": libdir, "how": "ODHS_INCLUDE_DIR/ODHS_LIB_DIR"}
    if _pkg_config("--exists") is not None:
        inc = _pkg_config("--variable=includedir")
        libdir = _pkg_config("--variable=libdir")
        if inc and libdir and os.path.exists(os.path.join(inc, "odhs.h")):
            return {"include_dir": inc, "lib_dir": libdir, "how": "pkg-config",
                    "version": _pkg_config("--modversion")}
    root = os.path.dirname(HERE)
    inc, libdir = os.path.join(root, "include"), os.path.join(root, "lib")
    if os.path.exists(os.path.join(inc, "odhs.h")) and os.path.exists(os.path.join(libdir, "libodhs.so")):
        return {"include_dir": inc, "lib_dir": libdir, "how": "build tree"}
    raise LibraryNotFound(
        "libodhs not found: install it (make install) and make `pkg-config odhs` find it "
        "(PKG_CONFIG_PATH), or set ODHS_INCLUDE_DIR and ODHS_LIB_DIR, or build the tree "
        "around python/ with `make` (then `make python` builds the module)")


def header_version(include_dir):
    """ODHS_VERSION_MAJOR.MINOR.PATCH parsed from common.h."""
    text = open(os.path.join(include_dir, "odhs", "common.h"), encoding="utf-8").read()
    parts = []
    for key in ("MAJOR", "MINOR", "PATCH"):
        m = re.search(r"#\s*define\s+ODHS_VERSION_%s\s+(\d+)" % key, text)
        if not m:
            raise LibraryNotFound("cannot parse ODHS_VERSION_%s in %s/odhs/common.h" % (key, include_dir))
        parts.append(m.group(1))
    return ".".join(parts)


# ---------------------------------------------------------------------------
# cdef generation from the headers
# ---------------------------------------------------------------------------


class HeaderError(ValueError):
    """A header uses a construct the generator does not know how to bind."""


_COMMENT = re.compile(r"/\*.*?\*/|//[^\n]*", re.S)
_DIRECTIVE = re.compile(r"#\s*(\w+)\s*(.*)$")
_INT_EXPR = re.compile(r"^[\sA-Za-z0-9_()+\-*/|&<>~]*$")


def _logical_lines(text):
    """Comments removed (replaced by a blank, keeping line structure where
    possible), backslash continuations joined."""
    text = _COMMENT.sub(lambda m: " " if "\n" not in m.group(0) else "\n" * m.group(0).count("\n"), text)
    return text.replace("\\\n", " ").split("\n")


def generate_cdef(include_dir, umbrella="odhs.h"):
    """The cffi cdef for ``#include <umbrella>``: the declarations of every
    header it includes (in preprocessor order, each once), with ODHS_API,
    comments and preprocessor lines removed, C++ guards dropped, and integer
    object-like macros turned into ``#define NAME ...`` (their value comes
    from the compiler). Conditional blocks other than include guards, C++
    guards and blocks that only define macros are refused (HeaderError): the
    generator would not know which branch applies."""
    out = []
    seen = set()

    def process(relpath):
        path = os.path.normpath(os.path.join(include_dir, relpath))
        if path in seen:
            return
        seen.add(path)
        lines = _logical_lines(open(path, encoding="utf-8").read())
        stack = []  # per open conditional: "guard", "cplusplus" or "macros"
        guard = None
        for lineno, line in enumerate(lines, 1):
            s = line.strip()
            where = "%s:%d" % (relpath, lineno)
            skipping = "cplusplus" in stack
            macros_only = "macros" in stack
            if s.startswith("#"):
                m = _DIRECTIVE.match(s)
                if not m:
                    continue  # a null directive
                d, rest = m.group(1), m.group(2).strip()
                if d in ("ifdef", "ifndef", "if"):
                    if rest == "__cplusplus" and d == "ifdef":
                        stack.append("cplusplus")
                    elif d == "ifndef" and guard is None and not stack and re.fullmatch(r"ODHS\w*_H", rest):
                        guard = rest
                        stack.append("guard")
                    else:
                        stack.append("macros")
                elif d in ("elif", "else"):
                    if not stack or stack[-1] not in ("cplusplus", "macros"):
                        raise HeaderError("%s: #%s of a conditional that is not understood" % (where, d))
                elif d == "endif":
                    if not stack:
                        raise HeaderError("%s: unbalanced #endif" % where)
                    stack.pop()
                elif d == "include":
                    if skipping:
                        continue
                    if macros_only:
                        raise HeaderError("%s: #include inside a conditional block" % where)
                    q = re.match(r'"([^"]+)"', rest)
                    if q:
                        process(q.group(1))
                    # <stddef.h>, <stdint.h>: cffi knows size_t, uint64_t, ...
                elif d == "define":
                    if skipping or macros_only:
                        continue
                    dm = re.match(r"(\w+)(\(?)\s*(.*)$", rest)
                    name, funclike, value = dm.group(1), dm.group(2), dm.group(3).strip()
                    if funclike or name == guard or not value or name == "ODHS_API":
                        continue
                    if '"' in value or "#" in value:
                        continue  # string macros (ODHS_VERSION_STRING): see odhs.version()
                    if not _INT_EXPR.match(value):
                        raise HeaderError("%s: macro %s = %s is not an integer expression" % (where, name, value))
                    out.append("#define %s ..." % name)
                elif d in ("undef", "pragma", "error", "warning"):
                    if not (skipping or macros_only):
                        raise HeaderError("%s: #%s is not supported by the cdef generator" % (where, d))
                else:
                    raise HeaderError("%s: unknown directive #%s" % (where, d))
                continue
            if skipping or not s:
                continue
            if macros_only:
                raise HeaderError("%s: declaration inside a conditional block: %s" % (where, s))
            out.append(re.sub(r"\bODHS_API\b\s*", "", line).rstrip())
        if stack:
            raise HeaderError("%s: unterminated conditional" % relpath)

    process(umbrella)
    return "\n".join(out) + "\n"


# Python callbacks (extern "Python": no run-time code generation, and the
# fastest route cffi has back into Python).
CALLBACKS_CDEF = """
extern "Python" int _odhs_py_event(const odhs_event *ev, void *ctx);
extern "Python" int _odhs_py_force(double t, const odhs_system *sys, double *F, void *ctx);
extern "Python" int _odhs_py_pair(size_t i, size_t j, const double *rij, double gap, void *ctx);
extern "Python" int _odhs_py_solver_create(void **state);
extern "Python" void _odhs_py_solver_destroy(void *state);
extern "Python" int _odhs_py_solver_setup(void *state, const odhs_network *net);
extern "Python" int _odhs_py_solver_solve(void *state, const odhs_network *net, const double *b, double *x);
extern "Python" int _odhs_py_solver_set_param(void *state, const char *key, double value);
extern "Python" int _odhs_py_solver_get_stat(void *state, const char *key, double *value);
extern "Python" int _odhs_py_solver_solve_ls(void *state, const odhs_network *net, const double *g, double *x);
"""

MODULE = "odhs._cffi"


def make_ffibuilder(where=None):
    """A cffi.FFI ready to compile the extension against the library found by
    find_odhs() (or the given dict)."""
    import cffi

    where = where or find_odhs()
    inc, libdir = where["include_dir"], where["lib_dir"]
    ffi = cffi.FFI()
    ffi.cdef(generate_cdef(inc) + CALLBACKS_CDEF)
    ffi.set_source(
        MODULE,
        "#include <odhs.h>\n"
        "/* the header version this module was compiled against */\n"
        "static const char odhs_py_header_version[] = ODHS_VERSION_STRING;\n",
        include_dirs=[inc],
        library_dirs=[libdir],
        runtime_library_dirs=[libdir],
        libraries=["odhs"],
        extra_compile_args=["-std=c11", "-O2"],
    )
    # the header version string, readable from Python
    ffi.cdef("static const char odhs_py_header_version[];")
    return ffi


# setuptools' cffi_modules entry point: cffi executes this file with
# __name__ == "__cffi__" and takes `ffibuilder` (imported as a module, e.g. by
# the tests, it builds nothing)
if __name__ == "__cffi__":
    try:
        ffibuilder = make_ffibuilder()
    except LibraryNotFound as e:  # a clear message for pip users
        sys.stderr.write("odhs: %s\n" % e)
        raise


def main(argv):
    import argparse
    import glob
    import tempfile

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--outdir", default=os.path.join(HERE, "odhs"),
                    help="where the compiled module goes (default: the package directory)")
    ap.add_argument("--tmpdir", default=None, help="where the generated C file and objects go")
    ap.add_argument("--print-cdef", action="store_true", help="print the generated cdef and exit")
    args = ap.parse_args(argv)
    import importlib.util

    if importlib.util.find_spec("cffi") is None:
        sys.stderr.write("odhs_build: %s has no cffi (Debian: apt-get install python3-cffi python3-dev, or "
                         "make deps)\n" % sys.executable)
        return 1
    try:
        where = find_odhs()
    except LibraryNotFound as e:
        sys.stderr.write("odhs_build: %s\n" % e)
        return 1
    if args.print_cdef:
        sys.stdout.write(generate_cdef(where["include_dir"]))
        return 0
    ffi = make_ffibuilder(where)
    tmp = args.tmpdir or tempfile.mkdtemp(prefix="odhs-cffi-")
    os.makedirs(tmp, exist_ok=True)
    so = ffi.compile(tmpdir=tmp, verbose=False)
    os.makedirs(args.outdir, exist_ok=True)
    for old in glob.glob(os.path.join(args.outdir, "_cffi.*.so")) + glob.glob(os.path.join(args.outdir, "_cffi.so")):
        os.remove(old)
    dest = os.path.join(args.outdir, os.path.basename(so))
    shutil.copy2(so, dest)
    if not args.tmpdir:
        shutil.rmtree(tmp, ignore_errors=True)
    print("odhs_build: %s (libodhs %s from %s: %s, %s)" % (
        dest, header_version(where["include_dir"]), where["how"], where["include_dir"], where["lib_dir"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
