#!/usr/bin/env python3
"""Per-call overhead of the Python bindings.

A step taken three ways on one stepper, in alternating blocks along the same
trajectory (the machine's noise then hits all three alike):

  C loop       one call of odhs_stepper_run_until_time with the run limit
               set to the block's number of steps (odhs_stepper_set_run_
               limits): the steps inside C, the step's own cost;
  raw cffi     one call of lib.odhs_stepper_step per step, from Python;
  Stepper.step one call of the wrapper per step (returns (Status, Event)).

Each block's time per step is CPU time of this thread (time.thread_time, so
that time spent descheduled by other jobs does not count); the figures are
medians over the blocks, and the overhead is the median of the per-block
differences to the C loop. A separate check runs K steps each way from the
same state and requires the three trajectories to be bit-identical. Then
the same for cheap calls (a scalar getter, the positions of N particles, the
contacts arrays), each against its raw cffi call.

    python3 python/bench/overhead.py [--n 100] [--blocks 200] [--block-steps 25]

Scenes: "dilute" (random placement at phi = 0.45: few contacts, cheap steps,
where overhead shows most) and "dense" (compressed to phi = 0.80 as
examples/shear_flow's built-in scene, a typical step), sheared at rate 1
with the defaults (adaptive Heun, solver auto)."""

import argparse
import os
import platform
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # the package in the tree (make python)

import odhs  # noqa: E402
from odhs._core import ffi, lib  # noqa: E402


def make_scene(n, phi, seed=1):
    """examples/cli.h's built-in scene at phi (compressed beyond 0.45)."""
    s = odhs.System(2, n)
    s.set_radii_bidisperse(0.5, 1.4, 0.03, seed)
    s.place_random(min(phi, 0.45), seed + 1)
    if phi > 0.45:
        with odhs.Driver(compression_rate=1.0) as d, odhs.Stepper(s, d, odhs.Solver("auto")) as st:
            st.run_until_packing_fraction(phi)
            st.correct()
    return s


def fresh(scene):
    """A stepper on a copy of the scene, reset, with its own solver."""
    s = scene.clone()
    st = odhs.Stepper(s, odhs.Driver(shear_rate=1.0), odhs.Solver("auto"))
    st.reset()
    return st


def same_trajectory(scene, k):
    """K steps three ways from the same state: the same positions, bit for bit."""
    out = []
    for how in ("c", "raw", "wrap"):
        st = fresh(scene)
        if how == "c":
            st.set_run_limits(max_steps=k, stall_steps=0)
            assert st.run_until_time(1e12) == odhs.Status.STEP_LIMIT
        elif how == "raw":
            ev = ffi.new("odhs_event *")
            for _ in range(k):
                lib.odhs_stepper_step(st._p, ev)
        else:
            for _ in range(k):
                st.step()
        assert st.counts.steps == k
        out.append(st.system.positions)
    return all(np.array_equal(out[0], x) for x in out[1:])


def bench_steps(name, scene, blocks, per_block):
    st = fresh(scene)
    p = st._p
    ev = ffi.new("odhs_event *")
    raw_step = lib.odhs_stepper_step
    step = st.step
    st.set_run_limits(max_steps=per_block, stall_steps=0)
    clock = time.thread_time
    times = {"c": [], "raw": [], "wrap": []}
    orders = (("c", "raw", "wrap"), ("raw", "wrap", "c"), ("wrap", "c", "raw"))
    for b in range(blocks):
        for how in orders[b % 3]:
            t0 = clock()
            if how == "c":
                rc = st.run_until_time(1e12)
            elif how == "raw":
                for _ in range(per_block):
                    raw_step(p, ev)
            else:
                for _ in range(per_block):
                    step()
            times[how].append((clock() - t0) * 1e6 / per_block)
            if how == "c":
                assert rc == odhs.Status.STEP_LIMIT, rc
    c, raw, wrap = (np.array(times[k]) for k in ("c", "raw", "wrap"))
    assert st.counts.steps == 3 * blocks * per_block
    return {"scene": name, "phi": scene.packing_fraction, "contacts": st.network.count,
            "c": np.median(c), "raw": np.median(raw), "wrap": np.median(wrap),
            "over_raw": np.median(raw - c), "over_wrap": np.median(wrap - c),
            "wrap_vs_raw": np.median(wrap - raw), "strain": st.strain}


def per_call(fn, calls):
    t0 = time.thread_time()
    for _ in range(calls):
        fn()
    return (time.thread_time() - t0) * 1e6 / calls


def bench_getters(scene, calls, repeats):
    st = fresh(scene)
    st.run_until_strain(0.05)
    s, p = st.system, st._p
    n, d = s.n, s.dim
    v = ffi.new("double *")
    buf = np.empty((n, d))
    pbuf = ffi.from_buffer("double[]", buf)
    nc = st.network.count
    arrs = [np.empty(nc, dtype=t) for t in (np.uintp, np.uintp, np.intc, np.float64, np.float64)]
    ptrs = [ffi.from_buffer(c, a) for c, a in zip(("size_t[]", "size_t[]", "int[]", "double[]", "double[]"), arrs)]
    pn = ffi.new("size_t *")
    rows = [
        ("Stepper.shear_stress", lambda: st.shear_stress, lambda: lib.odhs_stepper_shear_stress(p, v)),
        ("System.positions (N x 2)", lambda: s.positions, lambda: lib.odhs_system_get_positions(s._p, pbuf)),
        ("System.get_positions(out=)", lambda: s.get_positions(out=buf),
         lambda: lib.odhs_system_get_positions(s._p, pbuf)),
        ("Stepper.contacts() (%d)" % nc, st.contacts, lambda: lib.odhs_stepper_contacts(p, nc, pn, *ptrs)),
    ]
    out = []
    for name, wrapped, raw in rows:
        tw, tr = [], []
        for _ in range(repeats):  # alternating, the median of each
            tw.append(per_call(wrapped, calls))
            tr.append(per_call(raw, calls))
        out.append((name, float(np.median(tr)), float(np.median(tw))))
    return out


class _NoStepLib:
    """The compiled lib with odhs_stepper_step replaced by a Python no-op
    (for the wrapper's own cost; every other name is the real one)."""

    def __init__(self, real, kind):
        self._real = real
        self._kind = kind

    def __getattr__(self, name):
        return getattr(self._real, name)

    def odhs_stepper_step(self, p, ev):
        ev.kind = self._kind
        return 0


def bench_layers(scene, calls, repeats):
    """The cost of each layer of a step call without the step: the Python
    code of Stepper.step (the C step replaced by a no-op that reports no
    event, or a collision), and a cffi call of a trivial C function
    (odhs_stepper_time) against a Python no-op of the same arity."""
    import odhs.stepper as mod

    st = fresh(scene)
    p = st._p
    v = ffi.new("double *")
    ev = ffi.new("odhs_event *")
    real = mod.lib
    out = []
    try:
        for kind, label in ((0, "no event"), (1, "an event")):
            fake = _NoStepLib(real, kind)
            noop = fake.odhs_stepper_step
            mod.lib = fake
            tw, tn = [], []
            for _ in range(repeats):
                tw.append(per_call(st.step, calls))
                tn.append(per_call(lambda: noop(p, ev), calls))
            out.append(("Stepper.step's Python code (%s)" % label, float(np.median(np.array(tw) - np.array(tn)))))
    finally:
        mod.lib = real

    def pynoop(a, b):
        return 0

    tc, tn = [], []
    for _ in range(repeats):
        tc.append(per_call(lambda: lib.odhs_stepper_time(p, v), calls))
        tn.append(per_call(lambda: pynoop(p, v), calls))
    out.append(("a cffi call (odhs_stepper_time) beyond a Python call", float(np.median(np.array(tc) - np.array(tn)))))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=100, help="particles (default 100)")
    ap.add_argument("--blocks", type=int, default=200, help="blocks per way of stepping (default 200)")
    ap.add_argument("--block-steps", type=int, default=25, help="steps per block (default 25)")
    ap.add_argument("--repeats", type=int, default=15, help="timings per call figure (default 15)")
    ap.add_argument("--calls", type=int, default=2000, help="calls per call timing (default 2000)")
    args = ap.parse_args(argv)
    print("libodhs %s, Python %s, numpy %s, cffi %s, %s; OPENBLAS_NUM_THREADS=%s" % (
        odhs.version(), platform.python_version(), np.__version__, __import__("cffi").__version__,
        platform.processor() or platform.machine(), os.environ.get("OPENBLAS_NUM_THREADS", "unset")))
    print("N = %d, 2D, sheared at rate 1, adaptive Heun, solver auto; %d blocks of %d steps per way, "
          "CPU time, medians\n" % (args.n, args.blocks, args.block_steps))
    print("| scene | phi | contacts | C loop us/step | raw cffi us/step | Stepper.step us/step "
          "| overhead raw cffi | overhead Stepper.step | Stepper.step - raw cffi |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, phi in (("dilute", 0.45), ("dense", 0.80)):
        scene = make_scene(args.n, phi)
        assert same_trajectory(scene, 200), "the three ways took different steps"
        r = bench_steps(name, scene, args.blocks, args.block_steps)
        print("| %s | %.2f | %d | %.1f | %.1f | %.1f | %.2f us (%.1f%%) | %.2f us (%.1f%%) | %.2f us |" % (
            r["scene"], r["phi"], r["contacts"], r["c"], r["raw"], r["wrap"], r["over_raw"],
            100 * r["over_raw"] / r["c"], r["over_wrap"], 100 * r["over_wrap"] / r["c"], r["wrap_vs_raw"]))
    print("\n| layer of a step call, without the step | us per call |")
    print("|---|---:|")
    for name, t in bench_layers(make_scene(args.n, 0.45), args.calls * 10, args.repeats):
        print("| %s | %.2f |" % (name, t))
    print("\n| call | raw cffi us | wrapper us | wrapper overhead us |")
    print("|---|---:|---:|---:|")
    for name, tr, tw in bench_getters(make_scene(args.n, 0.80), args.calls, args.repeats):
        print("| %s | %.2f | %.2f | %.2f |" % (name, tr, tw, tw - tr))
    return 0


if __name__ == "__main__":
    sys.exit(main())
