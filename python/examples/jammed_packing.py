#!/usr/bin/env python3
"""jammed_packing - compress hard discs until the event-driven rewiring
certifies a jammed packing (Sect. IV D of Lerner, Duering and Wyart 2013)
and draw its force network with matplotlib.

The scene is examples/cli.h's built-in one (50:50 bidisperse radii 0.5 and
0.7 with 3% polydispersity, random placement at phi = 0.45), compressed at
rate 1 until the stepper returns Status.JAMMED. The picture shows the discs
in the periodic cell (images across its edges included), small ones light
and large ones darker, rattlers in grey, and every contact as a line from
centre to centre whose width is proportional to its force; the certificate
is printed.

    python3 jammed_packing.py                   # N = 128, a few seconds
    python3 jammed_packing.py --n 1024 --seed 3 --out big.png --svg big.svg

--svg also writes the library's own SVG picture (odhs_svg_write) for
comparison, --contacts the contacts as CSV.
"""

import argparse
import os
import sys

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
from matplotlib.collections import LineCollection, PatchCollection  # noqa: E402
from matplotlib.patches import Circle, Polygon  # noqa: E402


def jam(n, seed, solver):
    """The built-in scene compressed until jammed: (system, stepper)."""
    system = odhs.System(2, n)
    system.set_radii_bidisperse(0.5, 1.4, 0.03, seed)
    system.place_random(0.45, seed + 1)
    st = odhs.Stepper(system, odhs.Driver(compression_rate=1.0), odhs.Solver(solver))
    status = st.run_until_packing_fraction(0.999)
    if status != odhs.Status.JAMMED:
        raise SystemExit("jammed_packing: the compression stopped without jamming: %s (%s)"
                         % (status.name, st.errmsg))
    return system, st


def lattice_images(L, strain, reach):
    """Lattice shifts (dx, dy) of the sheared periodic cell within `reach`
    cells: a = (Lx, 0), b = (strain Ly, Ly)."""
    out = []
    for m in range(-reach, reach + 1):
        for k in range(-reach, reach + 1):
            out.append((k * L[0] + m * strain * L[1], m * L[1]))
    return out


def draw(system, st, path, title, dpi=100):
    x = system.positions
    r = system.radii
    L = system.box
    g = system.strain
    c = st.contacts()
    net = st.network
    rattler = net.rattlers()
    # contact vectors: normal times the centre distance (gap + a_i + a_j)
    i, j = c.i.astype(np.intp), c.j.astype(np.intp)
    rij = net.normals * (c.gap + r[i] + r[j])[:, None]
    fmean = c.force[~rattler[i]].mean() if len(c.force) else 1.0

    fig, ax = plt.subplots(figsize=(7, 7 * L[1] / L[0] + 0.6), constrained_layout=True)
    cell = np.array([[0, 0], [L[0], 0], [L[0] + g * L[1], L[1]], [g * L[1], L[1]]])
    clip = Polygon(cell, closed=True, transform=ax.transData)
    small = r < np.median(r)
    colours = np.where(rattler, "#c8c8c8", np.where(small, "#9ecae1", "#3182bd"))
    discs, cols, segs, widths = [], [], [], []
    for dx, dy in lattice_images(L, g, 1):
        shift = np.array([dx, dy])
        for k in range(system.n):
            discs.append(Circle(x[k] + shift, r[k]))
            cols.append(colours[k])
        a = x[i] + shift
        segs.extend(np.stack([a, a + rij], axis=1))
        widths.extend(3.0 * c.force / fmean)
    pc = PatchCollection(discs, facecolors=cols, edgecolors="#08306b", linewidths=0.4)
    pc.set_clip_path(clip)
    ax.add_collection(pc)
    lc = LineCollection(segs, linewidths=widths, colors="#a50f15", capstyle="round")
    lc.set_clip_path(clip)
    ax.add_collection(lc)
    ax.add_patch(Polygon(cell, closed=True, fill=False, edgecolor="black", linewidth=1.0))
    ax.set_xlim(min(0, g * L[1]) - 0.5, max(L[0], L[0] + g * L[1]) + 0.5)
    ax.set_ylim(-0.5, L[1] + 0.5)
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(title, fontsize=9)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--n", type=int, default=128, help="number of discs")
    ap.add_argument("--seed", type=int, default=1, help="random seed of the scene")
    ap.add_argument("--solver", default="auto", help="linear solver")
    ap.add_argument("--out", default="jammed_packing.png", help="the picture (.png, .svg, .pdf)")
    ap.add_argument("--dpi", type=int, default=100, help="resolution of a PNG picture")
    ap.add_argument("--svg", default=None, help="also the library's own SVG picture (odhs_svg_write)")
    ap.add_argument("--contacts", default=None, help="also the contacts as CSV i,j,kind,force,gap")
    args = ap.parse_args(argv)

    system, st = jam(args.n, args.seed, args.solver)
    cert = st.certificate()
    for field in cert._fields:
        print("%-22s %s" % (field, getattr(cert, field)))
    certified = (cert.jammed and cert.isostatic and cert.force_balance < 1e-12 and cert.gap_error < 1e-13
                 and cert.overlap <= 1e-14 and cert.min_force > 0)
    print("%-22s %s" % ("certified", "yes" if certified else "no"))
    title = ("jammed packing of N = %d discs (seed %d): phi_J = %.5f, z_backbone = %.3f, %d rattlers,\n"
             "%d contacts (isostatic: %d); line width proportional to the contact force"
             % (args.n, args.seed, cert.phi, cert.z_backbone, cert.n_rattlers, cert.n_contacts_backbone,
                cert.n_contacts_isostatic))
    draw(system, st, args.out, title, args.dpi)
    print("wrote %s" % args.out)
    if args.svg:
        st.write_svg(args.svg)
        print("wrote %s" % args.svg)
    if args.contacts:
        st.write_contacts_csv(args.contacts)
        print("wrote %s" % args.contacts)
    return 0 if certified else 3


if __name__ == "__main__":
    sys.exit(main())
