"""The same runs in C and in Python give the same numbers: the README's
twenty-line program (examples/minimal.c) and examples/shear_flow in 2D and
3D, bit for bit (the built-in scene rebuilt in Python exactly as
examples/cli.h's cli_scene and cli_compressed_scene build it, and a run
from the same --in file)."""

import math
import os
import re

import numpy as np

import odhs
from odhs._core import ffi, lib

from conftest import ROOT, run_c


def readme_in_python():
    """README.md's "Twenty lines of C", line by line in Python."""
    sys = odhs.System(2, 64)                            # 64 discs in 2D
    sys.set_radii_bidisperse(0.5, 1.4, 0.03, 7)         # 50:50, ratio 1.4
    sys.place_random(0.45, 7)                           # RSA at phi = 0.45
    drv = odhs.Driver()
    drv.shear_rate = 1.0                                # Lees-Edwards shear
    solver = odhs.Solver("auto")                        # automatic choice
    st = odhs.Stepper(sys, drv, solver)
    rc = st.run_until_strain(0.5)
    sigma, p, z = st.shear_stress, st.pressure, st.coordination
    line = "%s: sigma = %g  p = %g  z = %g" % (odhs.strerror(rc), sigma, p, z)
    return line, (sigma, p, z)


def readme_raw_c_calls():
    """The same program as raw C calls through cffi (no wrapper code)."""
    sys, drv = ffi.new("odhs_system **"), ffi.new("odhs_driver **")
    solver, st = ffi.new("odhs_solver **"), ffi.new("odhs_stepper **")
    assert lib.odhs_system_create(2, 64, sys) == 0
    lib.odhs_system_set_radii_bidisperse(sys[0], 0.5, 1.4, 0.03, 7)
    lib.odhs_system_place_random(sys[0], 0.45, 7)
    lib.odhs_driver_create(drv)
    lib.odhs_driver_set_shear_rate(drv[0], 1.0)
    lib.odhs_solver_create_by_name(b"auto", solver)
    lib.odhs_stepper_create(sys[0], drv[0], solver[0], st)
    rc = lib.odhs_stepper_run_until_strain(st[0], 0.5)
    v = ffi.new("double[3]")
    lib.odhs_stepper_shear_stress(st[0], v + 0)
    lib.odhs_stepper_pressure(st[0], v + 1)
    lib.odhs_stepper_coordination(st[0], v + 2)
    out = (v[0], v[1], v[2])
    lib.odhs_stepper_destroy(st[0])
    lib.odhs_solver_destroy(solver[0])
    lib.odhs_driver_destroy(drv[0])
    lib.odhs_system_destroy(sys[0])
    return rc, out


def test_readme_program_identical(example):
    line, numbers = readme_in_python()
    c_out = run_c([example("minimal")]).strip()
    assert line == c_out
    rc, raw = readme_raw_c_calls()
    assert rc == 0
    assert numbers == raw  # bit for bit, not only to %g
    # and the output the README shows under the program
    readme = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    m = re.search(r"<!-- docs-test: output of the program above -->\s*```text\n(.*?)\n```", readme, re.S)
    assert m and m.group(1).strip() == line


# --- examples/shear_flow --------------------------------------------------------

SERIES_FMT = "%.10g,%.10g,%.10g,%.6f,%d,%.10g,%.10g,%.10g,%d,%d,%.10g"


def cli_scene(dim, n, seed, phi_max):
    """examples/cli.h cli_scene."""
    phi0 = 0.45 if dim == 2 else 0.30
    if phi_max < phi0:
        phi0 = phi_max
    sys = odhs.System(dim, n)
    sys.set_radii_bidisperse(0.5, 1.4, 0.03, seed)
    sys.place_random(phi0, seed + 1)
    return sys


def cli_compressed_scene(dim, n, phi, seed, solver):
    """examples/cli.h cli_compressed_scene: cli_scene, then event-driven
    compression to phi with the run's solver and a drift correction."""
    phi0 = 0.45 if dim == 2 else 0.3
    if phi < phi0:
        phi0 = phi
    sys = cli_scene(dim, n, seed, phi)
    if phi > phi0:
        with odhs.Driver(compression_rate=1.0) as drv, odhs.Stepper(sys, drv, solver) as st:
            st.dt = 1e-3
            assert st.run_until_packing_fraction(phi) == odhs.Status.OK
            assert st.correct() >= 0
    return sys


def shear_flow_python(sys, solver, strain, every, dt=1e-3, integrator="heun", tol=1e-6):
    """examples/shear_flow.c's fixed-volume run (main and run_strain): the
    series rows as the C program formats them, and the stepper."""
    drv = odhs.Driver()
    drv.shear_rate = 1.0
    st = odhs.Stepper(sys, drv, solver)
    st.dt = dt
    st.integrator = integrator
    st.tolerance = tol
    st.reset()
    rows = []
    g0 = st.strain
    nout = math.ceil(strain / every - 1e-9)
    for k in range(nout + 1):
        target = g0 + min(k * every, strain)
        if k > 0:
            assert st.run_until_strain(target) == odhs.Status.OK
        g, t = st.strain, st.time
        c = st.counts
        rows.append(SERIES_FMT % (g - g0, st.shear_stress, st.pressure, st.coordination, c.collisions + c.openings,
                                  sys.packing_fraction, st.kappa, t, c.collisions, c.openings, st.dissipation))
    return rows, st


def read_series(path):
    with open(path) as f:
        return [line.rstrip("\n") for line in f if line.strip() and not line.startswith(("#", "strain"))]


def compare_final(xyz_path, sys):
    c = odhs.read_xyz(xyz_path)  # 17 digits: a bit-exact round trip
    assert c.n == sys.n and c.dim == sys.dim
    assert np.array_equal(c.positions, sys.positions)
    assert np.array_equal(c.radii, sys.radii)
    assert np.array_equal(c.box, sys.box)
    assert c.strain == sys.strain


def _shear_flow_case(example, tmp_path, dim, n, seed, phi, strain, every):
    csv, out = str(tmp_path / "c.csv"), str(tmp_path / "c.xyz")
    run_c([example("shear_flow"), "--n", str(n), "--dim", str(dim), "--seed", str(seed), "--phi", repr(phi),
           "--strain", repr(strain), "--every", repr(every), "--series", csv, "--out", out, "--quiet"])
    solver = odhs.Solver("auto")
    sys = cli_compressed_scene(dim, n, phi, seed, solver)
    rows, st = shear_flow_python(sys, solver, strain, every)
    assert rows == read_series(csv)
    compare_final(out, sys)
    return st


def test_shear_flow_2d_bit_identical(example, tmp_path):
    st = _shear_flow_case(example, tmp_path, dim=2, n=48, seed=3, phi=0.8, strain=0.06, every=0.02)
    assert st.counts.collisions > 10  # a run with events, not a trivial one


def test_shear_flow_3d_bit_identical(example, tmp_path):
    st = _shear_flow_case(example, tmp_path, dim=3, n=40, seed=5, phi=0.5, strain=0.04, every=0.02)
    assert st.counts.collisions > 5


def test_shear_flow_same_input_file(example, tmp_path):
    """Both start from a file Python wrote (--in), with the paper's scheme."""
    start = str(tmp_path / "start.xyz")
    scene = cli_scene(2, 32, 11, 1.0)
    scene.write_xyz(start)
    csv, out = str(tmp_path / "c.csv"), str(tmp_path / "c.xyz")
    run_c([example("shear_flow"), "--in", start, "--strain", "0.05", "--every", "0.025", "--integrator", "euler",
           "--solver", "cg", "--series", csv, "--out", out, "--quiet"])
    sys = odhs.read_xyz(start)
    rows, st = shear_flow_python(sys, odhs.Solver("cg"), 0.05, 0.025, integrator="euler")
    assert rows == read_series(csv)
    compare_final(out, sys)
