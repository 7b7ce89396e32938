#!/usr/bin/env python3
"""flow_curve - the flow curve of hard discs sheared at fixed pressure:
the friction coefficient mu = sigma_xy / p and the packing fraction phi
against the viscous number I_v = xi0 gammadot / p (= 1/p in the library's
units), as in docs/rheology.md, plotted with matplotlib.

Each pressure starts from the same random scene (examples/cli.h's built-in
scene at phi = 0.45), is sheared to --strain with the pressure held by the
volume (odhs.Driver(shear_rate=1, pressure=p)), and after the --transient
is sampled every 0.01 of strain; error bars are one standard error of the
block means (blocks of --block strain).

    python3 flow_curve.py                        # N = 64, 4 pressures, ~20 s
    python3 flow_curve.py --n 256 --strain 2 --pressures 10,100,1000,10000

Writes the plot (--out, PNG by default; .svg or .pdf by the name) and, with
--csv, a table p,I_v,mu,mu_err,phi,phi_err,z,events.
"""

import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
try:
    import odhs
except ImportError:  # run from the source tree after `make python`
    sys.path.insert(0, os.path.dirname(HERE))
    import odhs

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def scene(n, seed, dim=2):
    """examples/cli.h's built-in scene: 50:50 bidisperse radii 0.5 and 0.7
    (3% polydispersity), random placement at phi = 0.45 (2D)."""
    s = odhs.System(dim, n)
    s.set_radii_bidisperse(0.5, 1.4, 0.03, seed)
    s.place_random(0.45 if dim == 2 else 0.30, seed + 1)
    return s


def run_pressure(p, args, seed):
    """Shear at fixed pressure p; the samples of mu, phi, z after the
    transient, and the event count."""
    with scene(args.n, seed, args.dim) as system:
        driver = odhs.Driver(shear_rate=1.0, pressure=p)
        st = odhs.Stepper(system, driver, odhs.Solver(args.solver), dt=args.dt)
        mu, phi, z = [], [], []
        steps = int(round(args.strain / 0.01))
        for k in range(1, steps + 1):
            g = 0.01 * k
            status = st.run_until_strain(g)
            if status != odhs.Status.OK:
                raise RuntimeError("p = %g stopped at strain %.3f: %s (%s)" % (p, st.strain, status.name, st.errmsg))
            if g > args.transient + 1e-9:
                mu.append(st.shear_stress / p)
                phi.append(system.packing_fraction)
                z.append(st.coordination)
        c = st.counts
        return np.array(mu), np.array(phi), np.array(z), c.collisions + c.openings


def block_stats(x, per_block):
    """Mean and standard error of the block means."""
    nb = len(x) // per_block
    if nb < 2:
        return float(np.mean(x)), float("nan")
    blocks = x[:nb * per_block].reshape(nb, per_block).mean(axis=1)
    return float(blocks.mean()), float(blocks.std(ddof=1) / np.sqrt(nb))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--n", type=int, default=64, help="number of discs")
    ap.add_argument("--dim", type=int, default=2, choices=(2, 3), help="dimension")
    ap.add_argument("--pressures", default="3,10,30,100", help="comma-separated pressures (units gammadot/xi0)")
    ap.add_argument("--strain", type=float, default=1.0, help="total strain per pressure")
    ap.add_argument("--transient", type=float, default=0.3, help="strain discarded at the start")
    ap.add_argument("--block", type=float, default=0.1, help="block length (strain) for the error bars")
    ap.add_argument("--seeds", type=int, default=1, help="independent scenes per pressure (seeds 1, 2, ...)")
    ap.add_argument("--dt", type=float, default=1e-3, help="largest step (units 1/gammadot)")
    ap.add_argument("--solver", default="auto", help="linear solver")
    ap.add_argument("--out", default="flow_curve.png", help="the plot (.png, .svg, .pdf)")
    ap.add_argument("--dpi", type=int, default=100, help="resolution of a PNG plot")
    ap.add_argument("--csv", default=None, help="also write the table as CSV")
    ap.add_argument("--quiet", action="store_true", help="no progress lines")
    args = ap.parse_args(argv)
    pressures = [float(v) for v in args.pressures.split(",")]
    if args.transient >= args.strain:
        ap.error("--transient must be below --strain")

    rows = []
    t0 = time.time()
    for p in pressures:
        mus, phis, zs, events = [], [], [], 0
        for seed in range(1, args.seeds + 1):
            mu, phi, z, ev = run_pressure(p, args, seed)
            mus.append(mu)
            phis.append(phi)
            zs.append(z)
            events += ev
        per_block = max(1, int(round(args.block / 0.01)))
        # blocks within each seed, pooled
        mu_all = np.concatenate([m[:len(m) // per_block * per_block] for m in mus])
        phi_all = np.concatenate([f[:len(f) // per_block * per_block] for f in phis])
        m, me = block_stats(mu_all, per_block)
        f, fe = block_stats(phi_all, per_block)
        row = (p, 1.0 / p, m, me, f, fe, float(np.mean(np.concatenate(zs))), events)
        rows.append(row)
        if not args.quiet:
            print("p = %-8g I_v = %-8.3g mu = %.4f +- %.4f  phi = %.4f +- %.4f  z = %.3f  events %d  (%.1f s)"
                  % (row + (time.time() - t0,)), flush=True)

    data = np.array(rows)
    if args.csv:
        np.savetxt(args.csv, data, delimiter=",", fmt="%.10g", comments="",
                   header="p,I_v,mu,mu_err,phi,phi_err,z,events")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.8), constrained_layout=True)
    iv = data[:, 1]
    ax1.errorbar(iv, data[:, 2], yerr=data[:, 3], marker="o", capsize=3, color="tab:blue")
    ax1.set_xscale("log")
    ax1.set_xlabel(r"viscous number $I_v = \xi_0\dot\gamma/p$")
    ax1.set_ylabel(r"friction coefficient $\mu = \sigma_{xy}/p$")
    ax1.grid(True, which="both", alpha=0.3)
    ax2.errorbar(iv, data[:, 4], yerr=data[:, 5], marker="s", capsize=3, color="tab:red")
    ax2.set_xscale("log")
    ax2.set_xlabel(r"viscous number $I_v$")
    ax2.set_ylabel(r"packing fraction $\phi$")
    ax2.grid(True, which="both", alpha=0.3)
    fig.suptitle("%dD hard %s at fixed pressure, N = %d, strain %g (first %g discarded), %d seed%s, libodhs %s"
                 % (args.dim, "discs" if args.dim == 2 else "spheres", args.n, args.strain, args.transient,
                    args.seeds, "" if args.seeds == 1 else "s", odhs.version()), fontsize=9)
    fig.savefig(args.out, dpi=args.dpi)
    if not args.quiet:
        print("wrote %s" % args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
