"""Event, force, pair and solver callbacks written in Python, with exceptions
inside them: the run stops cleanly (the force callback's step is rolled
back, the event callback's step is complete), the exception is re-raised by
the call that ran the library, and the stepper can go on afterwards."""

import math

import numpy as np
import pytest

import odhs


def scene(n=48, dim=2, seed=4, phi=0.45):
    s = odhs.System(dim, n)
    s.set_radii_bidisperse(0.5, 1.4, 0.03, seed)
    s.place_random(phi, seed + 1)
    return s


def sheared(solver="auto", **kw):
    s = scene(**kw)
    return odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver(solver))


# --- events ------------------------------------------------------------------------


def test_event_callback_sees_every_event():
    st = sheared()
    events = []
    st.set_event_callback(events.append)  # returns None: never stops
    assert st.run_until_strain(0.2) == odhs.Status.OK
    c = st.counts
    assert len(events) == c.collisions + c.openings > 0
    kinds = {e.kind for e in events}
    assert kinds <= {odhs.EventKind.COLLISION, odhs.EventKind.OPENING}
    assert all(e.i < e.j and 0 <= e.strain <= 0.2 + 1e-12 for e in events)
    assert all(a.time <= b.time for a, b in zip(events, events[1:]))


def test_event_callback_stop_by_return_value():
    st = sheared()
    seen = []

    def stop_at_second(ev):
        seen.append(ev)
        return len(seen) == 2

    st.set_event_callback(stop_at_second)
    assert st.run_until_strain(0.5) == odhs.Status.STOPPED
    assert len(seen) >= 2 and st.strain < 0.5
    st.set_event_callback(None)
    assert st.run_until_strain(0.5) == odhs.Status.OK


class Boom(Exception):
    pass


def test_event_callback_exception_stops_and_reraises():
    st = sheared()
    n = [0]

    def cb(ev):
        n[0] += 1
        if n[0] == 3:
            raise Boom("third event")

    st.set_event_callback(cb)
    with pytest.raises(Boom, match="third event") as e:
        st.run_until_strain(0.5)
    assert "ODHS_STOPPED" in "".join(getattr(e.value, "__notes__", []))
    g = st.strain
    assert 0 < g < 0.5
    # the state is valid: the run goes on from there
    assert st.errors.overlap <= 1e-9
    st.set_event_callback(None)
    assert st.run_until_strain(0.5) == odhs.Status.OK
    assert st.strain == pytest.approx(0.5)


def test_event_callback_exception_in_single_step():
    st = sheared()

    def cb(ev):
        raise KeyError("in step")

    st.set_event_callback(cb)
    with pytest.raises(KeyError):
        for _ in range(100000):
            st.step()
    assert st.counts.collisions + st.counts.openings >= 1


def test_keyboard_interrupt_in_callback_propagates():
    st = sheared()

    def cb(ev):
        raise KeyboardInterrupt

    st.set_event_callback(cb)
    with pytest.raises(KeyboardInterrupt):
        st.run_until_strain(0.5)


# --- forces ------------------------------------------------------------------------


def alternating(t, system):
    F = np.zeros((system.n, system.dim))
    F[:, 0] = 1.0
    F[::2, 0] = -1.0
    return F


def test_force_callback_matches_fixed_forces():
    s1, s2 = scene(), scene()
    d1, d2 = odhs.Driver(), odhs.Driver()
    d1.set_force_callback(alternating)
    d2.set_forces(alternating(0.0, s2))
    a = odhs.Stepper(s1, d1, odhs.Solver("dense"))
    b = odhs.Stepper(s2, d2, odhs.Solver("dense"))
    for st in (a, b):
        st.driver.set_time_unit(1.0)
        assert st.run_until_time(0.5) == odhs.Status.OK
    assert np.array_equal(s1.positions, s2.positions)
    assert np.array_equal(a.external_forces(), alternating(0.0, s1))


def test_force_callback_gets_a_readonly_view():
    s = scene()
    views = []

    def f(t, system):
        views.append(system)
        assert system.positions.shape == (system.n, 2)
        with pytest.raises(ValueError, match="read-only"):
            system.positions = system.positions
        return alternating(t, system)

    d = odhs.Driver()
    d.set_force_callback(f)
    st = odhs.Stepper(s, d, odhs.Solver("dense"))
    st.run_until_time(0.01)
    assert views
    with pytest.raises(ValueError, match="only valid inside the callback"):
        views[0].positions


def test_force_callback_exception_rolls_back_and_reraises():
    s = scene()
    d = odhs.Driver()
    d.set_time_unit(1.0)
    calls = [0]
    fail_at = [None]

    def f(t, system):
        calls[0] += 1
        if fail_at[0] is not None and calls[0] >= fail_at[0]:
            raise ZeroDivisionError("forces at t = %g" % t)
        return alternating(t, system)

    d.set_force_callback(f)
    st = odhs.Stepper(s, d, odhs.Solver("dense"))
    st.run_until_time(0.05)
    t0, x0, steps0 = st.time, s.positions, st.counts.steps
    fail_at[0] = calls[0] + 1
    with pytest.raises(ZeroDivisionError) as e:
        st.step()
    assert "ODHS_E_CALLBACK" in "".join(e.value.__notes__)
    # rolled back: nothing moved
    assert st.time == t0 and st.counts.steps == steps0
    assert np.array_equal(s.positions, x0)
    fail_at[0] = None
    st.run_until_time(0.1)
    assert st.time == pytest.approx(0.1)


def test_force_callback_bad_return():
    s = scene()
    d = odhs.Driver()
    d.set_force_callback(lambda t, system: np.zeros(3))
    st = odhs.Stepper(s, d, odhs.Solver("dense"))
    with pytest.raises(ValueError, match="expected"):
        st.reset()
    d.set_force_callback(lambda t, system: np.full((system.n, system.dim), math.nan))
    with pytest.raises(odhs.CallbackError) as e:  # NaN: the library's own check
        st.reset()
    assert e.value.status == -17


# --- pairs ---------------------------------------------------------------------------


def test_pairs_and_exception():
    s = scene()
    p = s.pairs(0.3)
    assert p.rij.shape == (len(p.i), 2) and np.all(p.i < p.j)
    assert np.all(p.gap <= 0.3)
    for k in range(len(p.i)):
        sep = s.separation(p.i[k], p.j[k])
        assert np.array_equal(sep.rij, p.rij[k])
    assert s.for_each_pair(0.3, lambda i, j, rij, gap: True) == odhs.Status.STOPPED

    def bad(i, j, rij, gap):
        raise LookupError("pair")

    with pytest.raises(LookupError):
        s.for_each_pair(0.3, bad)


# --- solver backends -------------------------------------------------------------------


class NumpyDense(odhs.SolverBackend):
    """N x = b by numpy on the dense N = S S^T."""

    name = "numpy-dense"
    flags = odhs.SolverFlag.DIRECT

    def __init__(self):
        self.setups = 0
        self.solves = 0
        self.fail = None

    def setup(self, network):
        S = network.S_dense()
        self.N = S @ S.T
        self.setups += 1

    def solve(self, network, b, x):
        if self.fail is not None:
            raise self.fail
        self.solves += 1
        x[:] = np.linalg.solve(self.N, b)

    def get_stat(self, key):
        return {"setups": self.setups, "python_solves": self.solves}[key]


def test_python_backend_agrees_with_dense():
    a, b = sheared("dense"), None
    backend = NumpyDense()
    b = odhs.Stepper(scene(), odhs.Driver(shear_rate=1.0), odhs.Solver(backend))
    for st in (a, b):
        st.run_until_strain(0.1)
    assert b.solver.name == "numpy-dense" and b.solver.backend is backend
    assert backend.solves > 0 and b.solver.get_stat("setups") == backend.setups
    assert b.solver.get_stat("solves") > 0  # the library's own statistic
    with pytest.raises(odhs.InvalidError):
        b.solver.get_stat("nothing")
    np.testing.assert_allclose(b.system.positions, a.system.positions, rtol=0, atol=1e-9)
    assert b.shear_stress == pytest.approx(a.shear_stress, rel=1e-8)


def test_python_backend_exception_reraised():
    backend = NumpyDense()
    st = odhs.Stepper(scene(), odhs.Driver(shear_rate=1.0), odhs.Solver(backend))
    st.run_until_strain(0.05)
    backend.fail = FloatingPointError("solver broke")
    t = st.time
    with pytest.raises(FloatingPointError, match="solver broke"):
        st.run_until_strain(0.2)
    assert st.time == t  # the failing step was rolled back
    backend.fail = None
    assert st.run_until_strain(0.2) == odhs.Status.OK


def test_python_backend_singular_goes_to_fallback():
    backend = NumpyDense()
    solver = odhs.Solver(backend)
    solver.fallback = odhs.Solver("dense")
    st = odhs.Stepper(scene(), odhs.Driver(shear_rate=1.0), solver)
    backend.fail = odhs.SingularError("said the backend")
    assert st.run_until_strain(0.05) == odhs.Status.OK  # rescued by the fallback
    assert solver.get_stat("chain_rescued") > 0
    solver.fallback = None
    with pytest.raises(odhs.SingularError):
        st.run_until_strain(0.1)


def test_solver_solve_direct_call():
    s = scene(phi=0.45)
    st = odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver("dense"))
    st.run_until_strain(0.1)
    net = st.network
    nc = net.count
    assert nc > 0
    b = np.linspace(1.0, 2.0, nc)
    x1 = odhs.Solver("dense").solve(net, b)
    x2 = odhs.Solver(NumpyDense()).solve(net, b)
    np.testing.assert_allclose(net.apply_N(x1), b, rtol=1e-10)
    np.testing.assert_allclose(x1, x2, rtol=1e-10)
    g = np.random.default_rng(0).normal(size=(s.n, 2))
    xl = odhs.Solver("dense").solve_ls(net, g)
    np.testing.assert_allclose(net.apply_N(xl), net.apply_S(g), rtol=1e-8, atol=1e-10)


def test_callback_exceptions_stay_in_their_thread():
    """Two steppers in two threads (cffi releases the GIL during the C
    calls): an exception raised in one thread's callback is raised in that
    thread only."""
    import threading

    results = {}

    def work(name, fail):
        st = sheared(seed=5 if fail else 6)
        n = [0]

        def cb(ev):
            n[0] += 1
            if fail and n[0] == 5:
                raise ArithmeticError("thread %s" % name)

        st.set_event_callback(cb)
        try:
            for g in np.linspace(0.05, 0.5, 10):
                st.run_until_strain(g)
            results[name] = ("ok", n[0])
        except ArithmeticError as e:
            results[name] = ("raised", str(e))

    threads = [threading.Thread(target=work, args=("a", True)), threading.Thread(target=work, args=("b", False))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results["a"] == ("raised", "thread a")
    assert results["b"][0] == "ok" and results["b"][1] > 5
