"""Ownership: a stepper keeps its system, driver and solver alive; closing or
dropping them in any order, with reference cycles through callbacks, never
frees a C object still in use and never leaks one (repeated create/destroy
under tracemalloc and gc, the library's live handle count, the process's
resident memory)."""

import gc
import os
import tracemalloc
import weakref

import numpy as np

import odhs
from odhs._core import live_handles


def make_stepper(n=24, seed=1):
    sys = odhs.System(2, n)
    sys.set_radii_bidisperse(0.5, 1.4, 0.03, seed)
    sys.place_random(0.4, seed)
    drv = odhs.Driver(shear_rate=1.0)
    return odhs.Stepper(sys, drv, odhs.Solver("auto"))  # only the stepper is returned


def test_stepper_outlives_the_names_of_its_system():
    gc.collect()
    base = live_handles()
    st = make_stepper()
    gc.collect()
    assert live_handles() == base + 4
    assert st.run_until_strain(0.1) == odhs.Status.OK
    assert st.system.positions.shape == (24, 2)
    wr = weakref.ref(st.system)
    del st
    gc.collect()
    assert wr() is None and live_handles() == base


def test_closing_dependencies_first_is_safe():
    gc.collect()
    base = live_handles()
    sys = odhs.System(2, 24)
    sys.set_radii_bidisperse(0.5, 1.4, 0.03, 1)
    sys.place_random(0.4, 1)
    with odhs.Driver(shear_rate=1.0) as drv, odhs.Solver("dense") as solver:
        st = odhs.Stepper(sys, drv, solver)
    sys.close()  # the Python objects are closed ...
    assert sys.closed and drv.closed and solver.closed
    assert live_handles() == base + 4  # ... the C objects live on for the stepper
    assert st.run_until_strain(0.1) == odhs.Status.OK
    net = st.network  # a view keeps the stepper alive
    st.close()
    assert live_handles() == base + 4
    assert net.count >= 0
    del net
    gc.collect()
    assert live_handles() == base


def test_cycles_through_callbacks_are_collected():
    gc.collect()
    base = live_handles()
    for k in range(20):
        st = make_stepper(seed=k + 1)
        sys = st.system
        # cycles: stepper -> callback -> stepper and system
        st.set_event_callback(lambda ev, st=st, sys=sys: sys.n < 0 and st)
        st.driver.set_force_callback(lambda t, s, st=st: np.zeros((s.n, s.dim)))
        st.driver.set_force_callback(None)
        st.run_until_strain(0.02)
        del st, sys
    gc.collect()
    assert live_handles() == base


def test_solver_fallback_kept_alive():
    gc.collect()
    base = live_handles()
    s = odhs.Solver("cg")
    s.fallback = odhs.Solver("dense")  # no other name for it
    gc.collect()
    assert s.fallback.name == "dense" and live_handles() == base + 2
    s.fallback = None
    gc.collect()
    assert live_handles() == base + 1
    s.close()
    assert live_handles() == base


def _rss_kib():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") // 1024


def test_no_leak_under_repeated_create_destroy():
    def cycle(k):
        st = make_stepper(seed=k % 5 + 1)
        st.set_event_callback(lambda ev: None)
        st.run_until_strain(0.01)
        c = st.contacts()
        x = st.system.positions
        net = st.network
        assert len(c.i) == net.count and x.shape == (24, 2)
        backend_solver = odhs.Solver("dense")
        backend_solver.fallback = odhs.Solver("cg")
        return c

    for k in range(30):  # warm up caches, allocator pools
        cycle(k)
    gc.collect()
    gc.collect()
    base = live_handles()
    rss0 = _rss_kib()
    tracemalloc.start()
    snap0 = tracemalloc.take_snapshot()
    for k in range(300):
        cycle(k)
    gc.collect()
    snap1 = tracemalloc.take_snapshot()
    tracemalloc.stop()
    growth = sum(s.size_diff for s in snap1.compare_to(snap0, "filename"))
    assert growth < 64 * 1024, "Python memory grew by %d bytes over 300 cycles" % growth
    assert live_handles() == base
    assert _rss_kib() - rss0 < 4096, "resident memory grew by %d KiB" % (_rss_kib() - rss0)
