"""The analysis calls (odhs.analysis over analysis.h) against the C results
and analytic cases: series statistics of an AR(1) process, a histogram,
a power-law exponent, backbone forces and gaps of a jammed packing against
its certificate, g_y of a cosine field on a lattice, a scaling collapse of
synthetic flow curves, and errors raised with their messages."""

import numpy as np
import pytest

import odhs
from odhs import analysis


def test_series_stats_ar1():
    rng = np.random.default_rng(1)
    p, n = 0.9, 1 << 16
    e = rng.standard_normal(n)
    x = np.empty(n)
    x[0] = e[0] / np.sqrt(1 - p * p)
    for t in range(1, n):
        x[t] = p * x[t - 1] + e[t]
    s = analysis.series_stats(x)
    tau = 0.5 * (1 + p) / (1 - p)
    assert s.n == n and s.plateau
    assert abs(s.tau_int / tau - 1) < 0.15
    assert abs(s.mean - x.mean()) < 1e-12 and abs(s.variance - x.var(ddof=1)) < 1e-9
    rho = analysis.autocorrelation(x, 5)
    assert rho.shape == (6,) and rho[0] == 1.0 and abs(rho[1] - p) < 0.02


def test_histogram_and_power_law():
    rng = np.random.default_rng(2)
    x = rng.random(100000) ** (1 / 1.4)  # p(x) = 1.4 x^0.4 on (0, 1]
    h = analysis.histogram(x, 0.0, 1.0, 10)
    assert h.edges.shape == (11,) and h.density.shape == (10,) and h.counts.dtype == np.uint64
    assert h.outside == 0 and int(h.counts.sum()) == x.size
    assert abs(np.sum(h.density * np.diff(h.edges)) - 1) < 1e-12
    pl = analysis.power_law_exponent(x, 0.5)
    assert abs(pl.exponent - 0.4) < 4 * pl.error and pl.used == int(np.sum(x <= 0.5))
    with pytest.raises(odhs.InvalidError) as e:
        analysis.histogram(x, 1.0, 1.0, 4)
    assert "range" in e.value.message


def test_backbone_and_gaps_of_a_jammed_packing():
    s = odhs.System(2, 64)
    s.set_radii_bidisperse(0.5, 1.4, 0.0, 5)
    s.place_random(0.5, 5)
    st = odhs.Stepper(s, odhs.Driver(compression_rate=1.0), odhs.Solver("cholmod"))
    rc = st.run_until_packing_fraction(0.9)
    assert rc == odhs.Status.JAMMED
    cert = st.certificate()
    f = analysis.backbone_forces(st.network)
    assert f.shape == (cert.n_contacts_backbone,) and np.all(f > 0)
    g = analysis.packing_gaps(s, st.network, 0.2)
    assert len(g.i) == len(g.gap) > 0 and np.all(g.i < g.j) and np.all(g.gap <= 0.2)
    assert set(np.unique(g.role)) <= {0, 1, 2}


def test_velocity_correlation_cosine():
    nx, ny = 16, 8
    s = odhs.System(2, nx * ny)
    xy = np.array([[b + 0.5, a + 0.5] for a in range(ny) for b in range(nx)])
    s.set_configuration([nx, ny], 0.0, np.full(nx * ny, 0.3), xy)
    v = np.zeros_like(xy)
    v[:, 1] = np.cos(2 * np.pi * xy[:, 0] / nx)
    g, pairs = analysis.velocity_correlation(s, v, 0.5, 9)
    assert np.isnan(g[8]) and pairs[8] == 0
    assert np.allclose(g[:8], np.cos(2 * np.pi * np.arange(8) / nx), atol=1e-12)
    x, gmin = analysis.correlation_minimum((np.arange(10) + 0.5 - 3.3) ** 2 - 0.2)
    assert abs(x - 3.3) < 1e-12 and abs(gmin + 0.2) < 1e-12


def test_collapse_fit():
    rng = np.random.default_rng(7)
    phi = np.tile(0.83 + 0.003 * np.arange(11), 4)
    rate = np.repeat([1e-7, 1e-6, 1e-5, 1e-4], 11)
    x = (phi - 0.8433) / rate ** (1 / 3.5)
    val = rate ** (1.1 / 3.5) * np.exp(0.3 + 1.2 * x - 0.1 * x ** 2 + 0.02 * x ** 3) * (1 + 0.01 *
                                                                                         rng.standard_normal(44))
    c = analysis.collapse_fit(phi, rate, val, np.full(44, 0.01), degree=3, guess=(0.84, 1.0, 3.0))
    assert abs(c.phi_j - 0.8433) < 3.5 * c.phi_j_err and abs(c.y - 1.1) < 3.5 * c.y_err
    assert abs(c.znu - 3.5) < 3.5 * c.znu_err and c.coef.shape == (4,) and c.dof == 44 - 7
    with pytest.raises(odhs.EmptyError) as e:
        analysis.collapse_fit(phi[:11], rate[:11], val[:11])
    assert "same rate" in e.value.message


def test_event_split_and_pre_event_stress():
    # the synthetic sawtooth of the C test
    before = np.array([9.9, 9.8, 9.7, 10.6, 12.5, 12.4, 12.8, 12.7, 15.6])
    after = np.array([9.9, 9.8, 10.7, 12.6, 12.5, 12.9, 12.8, 15.7, 15.6])
    ev = [0, 0, 1, 1, 0, 0, 0, 1, 0]
    jumps, drops = analysis.event_split(before, after, ev)
    assert np.allclose(jumps, [1, 2, 3]) and np.allclose(drops, [0.1, 0.4 - 0.5])
    with pytest.raises(odhs.Error):
        analysis.event_split(before, after[:3], ev)
    # a sheared packing: a collision without openings never lowers sigma_xy
    s = odhs.System(2, 64)
    s.set_radii_bidisperse(0.5, 1.4, 0.0, 3)
    s.place_random(0.45, 3)
    d = odhs.Driver(compression_rate=1.0)
    st = odhs.Stepper(s, d, odhs.Solver("cholmod"))
    st.run_until_packing_fraction(0.80)
    d.compression_rate = 0.0
    d.shear_rate = 1.0
    with pytest.raises(odhs.StateError):
        st.pre_event_stress()
    st.set_pre_event_stress(True)
    rows = []
    for _ in range(200):
        _, info = st.step_ex()
        if not info.advanced:  # a driver change applied, no motion: no record
            continue
        rows.append((st.pre_event_stress()[0, 1], st.stress[0, 1], info.collisions, info.openings))
    b, a, c, o = (np.array(x) for x in zip(*rows))
    jumps, _ = analysis.event_split(b, a, (c > 0) & (o == 0))
    assert jumps.size > 5 and jumps.min() > -1e-9 * a.max()


def test_jam_lp_certified():
    # the fast route (odhs_stepper_jam_lp): certified, as jam_packing --method lp
    s = odhs.System(2, 64)
    s.set_radii_bidisperse(0.5, 1.4, 0.03, 7)
    s.place_random(0.45, 8)
    d = odhs.Driver(shear_rate=1.0)
    st = odhs.Stepper(s, d, odhs.Solver("dense"))
    with pytest.raises(odhs.StateError):
        st.jam_lp()
    d.shear_rate = 0.0
    d.compression_rate = 1.0
    with pytest.raises(odhs.InvalidError):
        st.jam_lp(trust=0.9)
    try:
        status, rep = st.jam_lp()
    except odhs.NotInstalledError:
        pytest.skip("libodhs built without CLP")
    assert status == odhs.Status.JAMMED
    c = st.certificate()
    assert c.jammed and c.isostatic and c.force_balance < 1e-12 and c.gap_error < 1e-13 and c.overlap <= 1e-14
    assert c.min_force > 0 and rep.n_lps >= 3 and abs(rep.phi_lp - c.phi) < 1e-9 and rep.growth_last < 1e-12
    assert rep.quench_iterations == 0 and rep.quench_steps == 0 and abs(rep.phi_start - 0.45) < 1e-9


def test_jam_lp_quench_certified():
    # the quench start (since 0.2.10): as jam_packing --method quench+lp
    s = odhs.System(2, 64)
    s.set_radii_bidisperse(0.5, 1.4, 0.03, 7)
    s.place_random(0.45, 8)
    st = odhs.Stepper(s, odhs.Driver(compression_rate=1.0), odhs.Solver("dense"))
    with pytest.raises(odhs.InvalidError):
        st.jam_lp(quench=True, quench_phi=1.5)
    try:
        status, rep = st.jam_lp(quench=True)
    except odhs.NotInstalledError:
        pytest.skip("libodhs built without CLP")
    assert status == odhs.Status.JAMMED
    c = st.certificate()
    assert c.jammed and c.isostatic and c.force_balance < 1e-12 and c.gap_error < 1e-13 and c.overlap <= 1e-14
    assert c.min_force > 0 and rep.quench_iterations > 0 and 0.7 < rep.phi_start < 0.86 and rep.phi_start < c.phi
    # since 0.2.11 the quench is rescaled toward phi_J before the chain starts; since 0.2.24
    # to a mean overlap of 3e-6 (at most 20 rescalings), and the chain starts within 1e-4
    assert 1 <= rep.quench_steps <= 20 and rep.phi_start > c.phi - 1e-4


def test_jam_lp_batched_end_game():
    # since 0.2.22 the end game steps with the batched integrator where the chain leaves the
    # packing unjammed (a chain stopped at tol 1e-6: 2D N = 256, seed 5; seed 4 up to 0.2.23,
    # which the closer quench start of 0.2.24 leaves jammed at the reset), and puts the
    # stepper's settings back; own_integrator=True steps with the stepper's own integrator
    out = []
    for own in (False, True):
        s = odhs.System(2, 256)
        s.set_radii_bidisperse(0.5, 1.4, 0.03, 5)
        s.place_random(0.45, 6)
        st = odhs.Stepper(s, odhs.Driver(compression_rate=1.0), odhs.Solver("dense"), correction_interval=1)
        st.tolerance = 2e-6
        before = st.settings
        try:
            status, rep = st.jam_lp(quench=True, tol=1e-6, own_integrator=own)
        except odhs.NotInstalledError:
            pytest.skip("libodhs built without CLP")
        assert status == odhs.Status.JAMMED and st.settings == before
        c = st.certificate()
        assert c.jammed and c.isostatic and c.force_balance < 1e-12 and c.gap_error < 1e-13 and c.overlap <= 1e-14
        assert c.min_force > 0
        b = st.batched_stats
        assert (b.batched_steps + b.exact_steps == rep.end_steps) if not own else (b.batched_steps + b.exact_steps == 0)
        out.append((rep.end_steps, c.phi))
    assert 0 < out[0][0] < out[1][0] and abs(out[0][1] - out[1][1]) < 1e-12
