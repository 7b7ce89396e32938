"""Arrays in and out: shape, dtype and values against the C accessors called
directly through cffi, copies (never views of library memory), out=
arguments and the zero-copy views a solver backend receives."""

import numpy as np
import pytest

import odhs
from odhs._core import ffi, lib


@pytest.fixture(scope="module")
def run():
    s = odhs.System(2, 40)
    s.set_radii_bidisperse(0.5, 1.4, 0.03, 2)
    s.place_random(0.5, 3)
    st = odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver("auto"))
    st.run_until_strain(0.3)
    return s, st


def c_doubles(fn, ptr, n):
    buf = ffi.new("double[]", n)
    assert fn(ptr, buf) == 0
    return np.array([buf[k] for k in range(n)])


def test_system_arrays(run):
    s, st = run
    n, d = s.n, s.dim
    x = s.positions
    assert x.shape == (n, d) and x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable
    assert np.array_equal(x.ravel(), c_doubles(lib.odhs_system_get_positions, s._p, n * d))
    r = s.radii
    assert r.shape == (n,) and r.dtype == np.float64
    assert np.array_equal(r, c_doubles(lib.odhs_system_get_radii, s._p, n))
    L = s.box
    assert L.shape == (d,) and np.array_equal(L, c_doubles(lib.odhs_system_get_box, s._p, d))
    # a copy: changing it changes nothing in the library
    x[0, 0] += 1.0
    assert not np.array_equal(s.positions, x)
    # out=
    buf = np.empty((n, d))
    assert s.get_positions(out=buf) is buf and np.array_equal(buf, s.positions)
    with pytest.raises(ValueError):
        s.get_positions(out=np.empty((n, d), dtype=np.float32))
    with pytest.raises(ValueError):
        s.get_positions(out=np.empty((n, d))[:, ::-1])
    assert s.species[:2] == ["S", "L"]


def test_setters_accept_array_likes(run):
    s, _ = run
    c = s.clone()
    x = c.positions
    c.positions = x.ravel().tolist()  # flat list
    assert np.array_equal(c.positions, x)
    c.positions = np.asfortranarray(x)  # any layout: copied contiguous
    assert np.array_equal(c.positions, x)
    c.radii = list(c.radii)
    c2 = odhs.System.from_arrays(s.box, s.radii, s.positions, strain=s.strain)
    assert np.array_equal(c2.positions, s.positions) and c2.strain == s.strain


def test_stepper_arrays(run):
    s, st = run
    n, d = s.n, s.dim
    for name, cfn in (("velocities", lib.odhs_stepper_velocities),
                      ("nonaffine_velocities", lib.odhs_stepper_nonaffine_velocities),
                      ("external_forces", lib.odhs_stepper_external_forces)):
        a = getattr(st, name)()
        assert a.shape == (n, d) and a.dtype == np.float64
        assert np.array_equal(a.ravel(), c_doubles(cfn, st._p, n * d)), name
    sig = st.stress
    assert sig.shape == (d, d) and np.array_equal(sig.ravel(), c_doubles(lib.odhs_stepper_stress, st._p, d * d))
    assert sig[0, 1] == st.shear_stress
    assert st.pressure == pytest.approx(-np.trace(sig) / d)
    # velocity of the affine flow: V - U = gammadot y xhat
    V, U = st.velocities(), st.nonaffine_velocities()
    np.testing.assert_allclose((V - U)[:, 0], s.positions[:, 1], rtol=1e-12, atol=1e-12)


def test_contacts_against_network_accessors(run):
    s, st = run
    c = st.contacts()
    nc = len(c.i)
    assert nc == st.network.count > 0
    assert c.i.dtype == np.uintp and c.j.dtype == np.uintp and c.kind.dtype == np.intc
    assert c.force.dtype == np.float64 and c.gap.dtype == np.float64
    assert all(a.shape == (nc,) for a in c)
    net = odhs._core.lib.odhs_stepper_network(st._p)
    f = c_doubles(lib.odhs_network_get_forces, net, nc)
    g = c_doubles(lib.odhs_network_get_gaps, net, nc)
    pi, pj, pk = ffi.new("size_t *"), ffi.new("size_t *"), ffi.new("int *")
    for k in range(nc):
        assert lib.odhs_network_get_contact(net, k, pi, pj, pk) == 0
        assert (c.i[k], c.j[k], c.kind[k]) == (pi[0], pj[0], pk[0])
    assert np.array_equal(c.force, f) and np.array_equal(c.gap, g)
    assert np.all(c.force >= 0) and np.all(np.abs(c.gap) < 1e-9)
    # the Network view gives the same
    i, j, kind = st.network.contacts()
    assert np.array_equal(i, c.i) and np.array_equal(j, c.j) and np.array_equal(kind, c.kind)
    assert np.array_equal(st.network.forces, c.force)
    nrm = st.network.normals
    assert nrm.shape == (nc, 2)
    np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, rtol=1e-14)
    # force balance: S^T f + F_ext = xi0^-1 (V - V_aff) with no external forces
    np.testing.assert_allclose(st.contact_forces(), st.nonaffine_velocities(), atol=1e-9)
    # z
    assert st.coordination == pytest.approx(2 * nc / s.n)


def test_network_operator_shapes(run):
    s, st = run
    net = st.network
    n, d, nc = s.n, s.dim, net.count
    rowptr, col, val = net.S_csr()
    assert rowptr.shape == (nc + 1,) and col.shape == val.shape == (net.nnz,) == (2 * d * nc,)
    S = net.S_dense()
    v = np.random.default_rng(1).normal(size=(n, d))
    np.testing.assert_allclose(net.apply_S(v), S @ v.ravel(), atol=1e-12)
    f = np.random.default_rng(2).normal(size=nc)
    np.testing.assert_allclose(net.apply_ST(f).ravel(), S.T @ f, atol=1e-12)
    np.testing.assert_allclose(net.apply_N(f), S @ S.T @ f, atol=1e-12)
    con = net.constrained()
    assert con.in_subset.dtype == bool and con.in_subset.shape == (n,)
    assert net.rattlers().shape == (n,)


def test_backend_gets_zero_copy_views(run):
    s, st = run
    seen = {}

    class Probe(odhs.SolverBackend):
        name = "probe"

        def solve(self, network, b, x):
            seen["b"] = (b.shape, b.dtype, b.flags.writeable, b.flags.owndata)
            seen["x"] = (x.shape, x.flags.writeable, x.flags.owndata)
            S = network.S_dense()
            x[:] = np.linalg.solve(S @ S.T, b)

    net = st.network
    b = np.ones(net.count)
    odhs.Solver(Probe()).solve(net, b)
    nc = net.count
    assert seen["b"] == ((nc,), np.float64, False, False)  # a read-only view, not a copy
    assert seen["x"] == ((nc,), True, False)


def test_network_build_by_hand(run):
    s, _ = run
    net = odhs.Network(s)
    net.detect(s, 0.2)
    assert len(net) == net.count > 0
    i, j, _ = net.contacts()
    assert (int(i[0]), int(j[0])) in net and net.find(i[0], j[0]) == 0
    k = net.count
    net.remove(i[0], j[0])
    assert net.count == k - 1 and net.find(i[0], j[0]) is None
    net.set_forces(np.arange(net.count, dtype=float))
    assert np.array_equal(net.forces, np.arange(net.count))
    net.clear()
    assert net.count == 0 and net.contacts()[0].shape == (0,)


def test_step_ex_and_the_remaining_getters(run):
    s, st = run
    st2 = odhs.Stepper(s.clone(), odhs.Driver(shear_rate=1.0, mobility=2.0), odhs.Solver("auto"),
                       integrator="euler", dt=2e-3, correction_interval=5)
    assert st2.settings == (odhs.Integrator.EULER, 2e-3, 1e-6, 5)
    st2.tolerance = 1e-7
    st2.set_contact_tolerance(1e-8)
    st2.reset()
    n0 = st2.counts
    for _ in range(20):
        status, info = st2.step_ex()
        assert status == odhs.Status.OK and info.advanced and not info.driver_change
        assert info.time_end == st2.time and info.strain_end == st2.strain
        assert info.time_end > info.time_start
    n1 = st2.counts
    assert n1.steps - n0.steps == 20
    assert st2.adaptive_stats.rejected == 0 and st2.rewire_count >= 0
    assert st2.power == pytest.approx(st2.dissipation, rel=1e-6)
    assert st2.driver.mobility == 2.0 and st2.driver.time_unit(st2.system) == pytest.approx(1.0)
    st2.driver.set_kappa_max(50.0)
    st2.driver.jamming_pressure = 10.0
    assert st2.driver.jamming_pressure == 10.0
    assert st2.feature_work("pressure") == 0
    st2.driver.set_time_unit(0.5)
    assert st2.driver.time_unit(st2.system) == 0.5
    st2.driver.clear_time_unit()
    assert st2.errors.contact_gap < 1e-6
    assert st2.solver.last_backend[0] in {i.name for i in odhs.available_solvers()} | {"lsq-svd", "lsq-pcg", "lsq-cg"}
    st2.solver.set_check_tolerance(1e-6)
    st2.solver.set_refinement(2)
    net = odhs.Network(s)
    net.detect(s, 0.0)
    net.add_bond(0, 1, 2.0)
    k = net.find(0, 1)
    assert net.rest_length(k, s) == 2.0 and net.contact(k)[2] == odhs.ContactKind.PERMANENT
    assert net.coordination == pytest.approx(2 * net.count / s.n)


def test_batched_integrator(run):
    """The batched integrator from Python: its default tolerance, its
    counters, no overlap and power balance after its steps."""
    s, _ = run
    st = odhs.Stepper(s.clone(), odhs.Driver(shear_rate=1.0), odhs.Solver("dense"), integrator="batched", dt=1e-2)
    assert st.settings.integrator == odhs.Integrator.BATCHED and st.tolerance == 1e-3
    assert st.batched_stats == (0, 0, 0)
    st.run_until_strain(0.05)
    b = st.batched_stats
    assert b.batched_steps > 0 and b.solves >= b.batched_steps
    c = st.correction_stats  # a correction after every step
    assert c.corrections >= b.batched_steps and c.passes >= 1 and c.closed >= 0
    assert st.errors.overlap <= 1e-12
    assert st.power == pytest.approx(st.dissipation, rel=1e-9)
