"""The build: every public function of the library is bound, the cdef
generator follows the headers (and refuses what it cannot bind), the loaded
library is the one the module was compiled for, and the package installs
with pip into a virtual environment (no network) and works there."""

import os
import re
import shutil
import subprocess
import sys

import pytest

import odhs
from odhs._core import lib

from conftest import PYDIR, ROOT

sys.path.insert(0, PYDIR)
import odhs_build  # noqa: E402


def header_functions(include_dir):
    names = set()
    for fn in os.listdir(os.path.join(include_dir, "odhs")):
        text = open(os.path.join(include_dir, "odhs", fn), encoding="utf-8").read()
        names |= set(re.findall(r"ODHS_API\s+[^;]*?\b(odhs_\w+)\s*[;(]", text))
    return names


def test_every_exported_symbol_is_bound():
    path = odhs.library_path()
    assert path and "libodhs" in os.path.basename(path)
    nm = subprocess.run(["nm", "-D", "--defined-only", path], capture_output=True, text=True, check=True)
    exported = {line.split()[-1] for line in nm.stdout.splitlines() if re.search(r" odhs_\w+$", line)}
    assert len(exported) > 200
    bound = set(dir(lib))
    missing = sorted(exported - bound)
    assert not missing, "exported by %s but not bound: %s" % (path, missing)
    # and every ODHS_API declaration of the headers (functions and tables)
    where = odhs_build.find_odhs()
    declared = header_functions(where["include_dir"])
    assert declared and not sorted(declared - bound)
    assert declared == exported


def test_versions_agree():
    assert odhs.version() == odhs.header_version() == odhs.__version__
    assert odhs.version_number() == lib.ODHS_VERSION_NUMBER
    ver = open(os.path.join(ROOT, "include", "odhs", "common.h")).read()
    major = re.search(r"ODHS_VERSION_MAJOR (\d+)", ver).group(1)
    assert odhs.version().startswith(major + ".")


def test_cdef_generator(tmp_path):
    cdef = odhs_build.generate_cdef(os.path.join(ROOT, "include"))
    assert "ODHS_API" not in cdef and "extern \"C\"" not in cdef and "/*" not in cdef
    assert "#define ODHS_SOLVER_TYPE_VERSION ..." in cdef
    assert "int odhs_stepper_step_ex(odhs_stepper *st, odhs_step_info *info);" in cdef
    # each header once, in include order (composite.h after stepper.h's types)
    assert cdef.count("typedef struct odhs_stepper odhs_stepper;") == 1
    assert cdef.index("typedef struct odhs_stepper odhs_stepper;") < cdef.index("odhs_stepper_add_bond")
    # a conditional declaration is refused: the generator cannot pick a branch
    inc = tmp_path / "inc"
    (inc / "odhs").mkdir(parents=True)
    (inc / "odhs.h").write_text('#include "odhs/a.h"\n')
    (inc / "odhs" / "a.h").write_text("#ifndef ODHS_A_H\n#define ODHS_A_H\n#ifdef FEATURE\nint odhs_x(void);\n"
                                      "#endif\n#endif\n")
    with pytest.raises(odhs_build.HeaderError, match="conditional"):
        odhs_build.generate_cdef(str(inc))
    (inc / "odhs" / "a.h").write_text("#ifndef ODHS_A_H\n#define ODHS_A_H\n#define ODHS_X \"text\"\n"
                                      "#define ODHS_N (1u << 3)\nODHS_API int odhs_x(int a, /* c */ int b);\n"
                                      "#endif\n")
    assert odhs_build.generate_cdef(str(inc)).split("\n")[:2] == ["#define ODHS_N ...", "int odhs_x(int a,   int b);"]


def test_pip_install_into_a_venv(tmp_path):
    """pip install --no-build-isolation --no-index ./python into a venv made
    with --system-site-packages (Debian's cffi, numpy), against the staged
    install found with pkg-config; then import it outside the tree."""
    stage = os.environ.get("ODHS_STAGE", os.path.join(ROOT, "build", "stage"))
    if not os.path.exists(os.path.join(stage, "lib", "pkgconfig", "odhs.pc")):
        msg = "no staged install in %s (make stage)" % stage
        if os.environ.get("ODHS_REQUIRE_EXAMPLES") == "1":
            pytest.fail(msg)
        pytest.skip(msg)
    src = tmp_path / "src"
    shutil.copytree(PYDIR, src, ignore=shutil.ignore_patterns("_cffi*.so", "build", "*.egg-info", "__pycache__",
                                                              "tests", "bench", "examples", ".pytest_cache"))
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", "--without-pip", str(venv)], check=True)
    py = str(venv / "bin" / "python")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PIP_INDEX_URL")}
    env["PKG_CONFIG_PATH"] = os.path.join(stage, "lib", "pkgconfig")
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    r = subprocess.run([py, "-m", "pip", "install", "--no-build-isolation", "--no-index", "-q", str(src)],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    prog = ("import odhs, os\n"
            "s = odhs.System(2, 64); s.set_radii_bidisperse(0.5, 1.4, 0.03, 7); s.place_random(0.45, 7)\n"
            "st = odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver('auto'))\n"
            "rc = st.run_until_strain(0.5)\n"
            "print(odhs.__file__)\n"
            "print(odhs.library_path())\n"
            "print('%s: sigma = %g  p = %g  z = %g' % (odhs.strerror(rc), st.shear_stress, st.pressure,"
            " st.coordination))\n")
    env.pop("PKG_CONFIG_PATH")
    r = subprocess.run([py, "-c", prog], capture_output=True, text=True, env=env, cwd=str(tmp_path))
    assert r.returncode == 0, r.stderr
    where, libpath, line = r.stdout.strip().split("\n")
    assert where.startswith(str(venv))  # the installed package, not the tree
    assert os.path.realpath(libpath).startswith(os.path.realpath(stage))  # found through its RPATH
    assert line == "success: sigma = 0.0183684  p = 0.025222  z = 0.5"


def test_every_public_name_is_documented():
    """Every public class, function, method and property of odhs has a
    docstring."""
    import inspect

    missing = []
    for name in odhs.__all__:
        obj = getattr(odhs, name)
        if not (inspect.isclass(obj) or inspect.isfunction(obj)):
            continue
        if not inspect.getdoc(obj):
            missing.append(name)
        if not inspect.isclass(obj) or issubclass(obj, (tuple, int)) and not issubclass(obj, odhs.Status):
            continue  # records (named tuples) and enums: their fields are data
        for attr, member in vars(obj).items():
            if attr.startswith("_"):
                continue
            if inspect.isfunction(member) or isinstance(member, (property, classmethod, staticmethod)):
                doc = member.__doc__ if not isinstance(member, (classmethod, staticmethod)) else \
                    member.__func__.__doc__
                if not doc:
                    missing.append("%s.%s" % (name, attr))
    assert not missing, "no docstring: %s" % missing


def test_package_names_only_bound_functions():
    """Every lib.<name> the package uses exists (a typo would fail only when
    its method is called)."""
    used = set()
    pkg = os.path.join(PYDIR, "odhs")
    for fn in os.listdir(pkg):
        if fn.endswith(".py"):
            used |= set(re.findall(r"\blib\.(\w+)", open(os.path.join(pkg, fn), encoding="utf-8").read()))
    assert len(used) > 200
    assert not sorted(used - set(dir(lib)))
