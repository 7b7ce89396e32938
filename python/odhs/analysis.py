"""The analysis calls of libodhs (include/odhs/analysis.h): time-series
statistics with automatic error bars, histograms and power-law exponents,
the forces of a packing's backbone and the gaps of its nearly touching
pairs, the transverse velocity correlation g_y(x) and the scaling collapse
of flow curves. Arrays are copied in and out (numpy float64)."""

from collections import namedtuple

import numpy as np

from ._core import F64, INT, SIZE_T, cstr, ffi, in_array, lib, out_array
from .errors import make_error

SeriesStats = namedtuple("SeriesStats", "n mean variance sem sem_err block nblocks plateau tau_int window sem_tau")
SeriesStats.__doc__ = """Statistics of a correlated series (odhs_series_stats): mean, variance, the
error of the mean by block averaging (sem, its uncertainty sem_err, at
blocks of `block` samples, `nblocks` of them; plateau True when the blocked
error levelled off) and from the integrated autocorrelation time tau_int
(samples; Sokal's `window`), sem_tau."""

Histogram = namedtuple("Histogram", "edges density counts outside")
Histogram.__doc__ = """A histogram (odhs_histogram): nbins + 1 edges, the density (integrating to
the fraction of samples inside), the counts and the samples outside."""

PowerLaw = namedtuple("PowerLaw", "exponent error used")
PowerLaw.__doc__ = "The small-x exponent a of p(x) ~ x^a with its error and the samples used."

Gaps = namedtuple("Gaps", "i j gap role")
Gaps.__doc__ = """Nearly touching pairs (odhs_packing_gaps): i < j (uintp), relative gap h,
role (0 both on the backbone, 1 one rattler, 2 both rattlers)."""

Collapse = namedtuple("Collapse", "phi_j phi_j_err y y_err znu znu_err q chi2 dof degree coef x0 xs evaluations")
Collapse.__doc__ = """A scaling collapse (odhs_collapse_fit): phi_J, y, z nu with errors, q = y/z nu,
chi2 and its degrees of freedom, and the master curve ln F(x) =
sum_k coef[k] ((x - x0)/xs)^k."""


def _raise(rc, fn, message=None):
    raise make_error(rc, cstr(lib.odhs_last_error()) if message is None else message, fn)


def _series(x, what="x"):
    arr = np.ascontiguousarray(x, dtype=F64).ravel()
    return arr, ffi.from_buffer("double[]", arr)


def series_stats(x):
    """Mean and errors of the correlated series x (odhs_series_stats_compute;
    at least 4 samples). Returns a SeriesStats."""
    arr, p = _series(x)
    out = ffi.new("odhs_series_stats *")
    out.size = ffi.sizeof("odhs_series_stats")
    rc = lib.odhs_series_stats_compute(p, arr.size, out)
    if rc:
        _raise(rc, "series_stats")
    return SeriesStats(out.n, out.mean, out.variance, out.sem, out.sem_err, out.block, out.nblocks,
                       bool(out.plateau), out.tau_int, out.window, out.sem_tau)


def autocorrelation(x, maxlag):
    """The normalised autocorrelation rho(0..maxlag) of x
    (odhs_series_autocorrelation), a new array of maxlag + 1 values."""
    arr, p = _series(x)
    rho, pr = out_array((int(maxlag) + 1,))
    rc = lib.odhs_series_autocorrelation(p, arr.size, int(maxlag), pr)
    if rc:
        _raise(rc, "autocorrelation")
    return rho


def event_split(before, after, at_event):
    """Split an event-resolved signal (odhs_series_event_split): before[k]
    and after[k] the values before and after step k's events, at_event[k]
    true for the steps to split at. Returns (jumps, drops): after - before
    at the marked steps, and after[k_m] - before[k_(m+1)] between
    consecutive marked steps (how far the signal fell between them)."""
    b, pb = _series(before, "before")
    a, pa = _series(after, "after")
    ev = np.ascontiguousarray(at_event, dtype=bool).ravel().astype(np.uint8)
    if not (b.size == a.size == ev.size):
        raise make_error(lib.ODHS_E_DIM, "before, after and at_event differ in length", "event_split")
    pe = ffi.from_buffer("unsigned char[]", ev)
    n = b.size
    jumps, pj = out_array((max(n, 1),))
    drops, pd = out_array((max(n, 1),))
    nj, nd = ffi.new("size_t *"), ffi.new("size_t *")
    rc = lib.odhs_series_event_split(pb, pa, pe, n, pj, nj, pd, nd)
    if rc:
        _raise(rc, "event_split")
    return jumps[: int(nj[0])].copy(), drops[: int(nd[0])].copy()


def histogram(x, lo, hi, nbins, log_bins=False):
    """The histogram of x on [lo, hi] in nbins bins, equal in x or in log x
    (odhs_histogram). Returns a Histogram."""
    arr, p = _series(x)
    edges, pe = out_array((int(nbins) + 1,))
    dens, pd = out_array((int(nbins),))
    counts = np.zeros(int(nbins), dtype=np.uint64)
    pc = ffi.from_buffer("uint64_t[]", counts, require_writable=True)
    outside = ffi.new("size_t *")
    rc = lib.odhs_histogram(p, arr.size, float(lo), float(hi), int(nbins), 1 if log_bins else 0, pe, pd, pc, outside)
    if rc:
        _raise(rc, "histogram")
    return Histogram(edges, dens, counts, int(outside[0]))


def power_law_exponent(x, xmax):
    """The exponent a of p(x) ~ x^a at small x from the samples in
    (0, xmax] (odhs_power_law_exponent, Hill's estimator). Returns a
    PowerLaw."""
    arr, p = _series(x)
    a, err, used = ffi.new("double *"), ffi.new("double *"), ffi.new("size_t *")
    rc = lib.odhs_power_law_exponent(p, arr.size, float(xmax), a, err, used)
    if rc:
        _raise(rc, "power_law_exponent")
    return PowerLaw(a[0], err[0], int(used[0]))


def backbone_forces(network):
    """The forces of the contacts between backbone particles of a Network
    (rattlers, bonds and walls left out; odhs_backbone_forces), a new array."""
    pn = network._cptr()
    n = ffi.new("size_t *")
    rc = lib.odhs_backbone_forces(pn, 0, n, ffi.NULL)
    if rc and rc != -5:  # ODHS_E_RANGE: the size query
        _raise(rc, "backbone_forces", cstr(lib.odhs_network_errmsg(pn)))
    f, pf = out_array((int(n[0]),))
    if n[0]:
        rc = lib.odhs_backbone_forces(pn, n[0], n, pf)
        if rc:
            _raise(rc, "backbone_forces", cstr(lib.odhs_network_errmsg(pn)))
    return f


def packing_gaps(system, network, max_gap):
    """The pairs of system not in network with relative gap up to max_gap,
    with their roles (odhs_packing_gaps). Returns Gaps of copies."""
    ps = system._p or system._closed()
    pn = network._cptr()
    n = ffi.new("size_t *")
    rc = lib.odhs_packing_gaps(ps, pn, float(max_gap), 0, n, ffi.NULL, ffi.NULL, ffi.NULL, ffi.NULL)
    if rc and rc != -5:
        _raise(rc, "packing_gaps", cstr(lib.odhs_system_errmsg(ps)))
    m = int(n[0])
    i, pi = out_array((m,), dtype=SIZE_T)
    j, pj = out_array((m,), dtype=SIZE_T)
    gap, pg = out_array((m,))
    role, pr = out_array((m,), dtype=INT)
    if m:
        rc = lib.odhs_packing_gaps(ps, pn, float(max_gap), m, n, pi, pj, pg, pr)
        if rc:
            _raise(rc, "packing_gaps", cstr(lib.odhs_system_errmsg(ps)))
    return Gaps(i, j, gap, role)


def velocity_correlation(system, velocities, width, nbins):
    """g_y(x) at the centres of nbins bins of [0, L_x/2] over pairs in strips
    of the given width (odhs_velocity_correlation); returns (g, pairs), NaN
    in empty bins. velocities: shape (N, dim), e.g.
    Stepper.nonaffine_velocities()."""
    ps = system._p or system._closed()
    nd = lib.odhs_system_count(ps) * lib.odhs_system_dim(ps)
    v, pv = in_array(velocities, nd, "velocities")
    g, pg = out_array((int(nbins),))
    pairs = np.zeros(int(nbins), dtype=np.uint64)
    pp = ffi.from_buffer("uint64_t[]", pairs, require_writable=True)
    rc = lib.odhs_velocity_correlation(ps, pv, float(width), int(nbins), pg, pp)
    if rc:
        _raise(rc, "velocity_correlation", cstr(lib.odhs_system_errmsg(ps)))
    del v
    return g, pairs


def correlation_minimum(g):
    """(x, g_min) of the minimum of g, x in units of the bin width from 0
    (odhs_correlation_minimum)."""
    arr, p = _series(g)
    x, gm = ffi.new("double *"), ffi.new("double *")
    rc = lib.odhs_correlation_minimum(p, arr.size, x, gm)
    if rc:
        _raise(rc, "correlation_minimum")
    return x[0], gm[0]


def collapse_fit(phi, rate, value, rel_err=None, degree=3, guess=None):
    """Fit phi_J, y and z nu of value = rate^(y/z nu) F((phi - phi_J) /
    rate^(1/z nu)) (odhs_collapse_fit). rel_err: relative errors (None:
    1 %); guess: (phi_J, y, z nu) or None. Returns a Collapse."""
    ph, pp = _series(phi)
    n = ph.size
    ra, pr = in_array(rate, n, "rate")
    va, pv = in_array(value, n, "value")
    ea, pe = (None, ffi.NULL) if rel_err is None else in_array(rel_err, n, "rel_err")
    ga, pg = (None, ffi.NULL) if guess is None else in_array(guess, 3, "guess")
    out = ffi.new("odhs_collapse *")
    out.size = ffi.sizeof("odhs_collapse")
    rc = lib.odhs_collapse_fit(pp, pr, pv, pe, n, int(degree), pg, out)
    if rc:
        _raise(rc, "collapse_fit")
    del ra, va, ea, ga
    return Collapse(out.phi_j, out.phi_j_err, out.y, out.y_err, out.znu, out.znu_err, out.q, out.chi2, out.dof,
                    out.degree, np.array([out.coef[k] for k in range(out.degree + 1)]), out.x0, out.xs,
                    out.evaluations)
