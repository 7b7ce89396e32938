#!/usr/bin/env python3
"""Checks of the files the examples write for other tools (run by
tests/examples_cli.sh): `traj FILE.xyz NFRAMES N` reads a trajectory with
ASE when it is installed (exit 77 when it is not); `svg FILE.svg NPOINTS
NPOLYLINES` parses a --plot picture and counts the points of its lines;
`csv FILE.csv NROWS` reads a contacts file with numpy.genfromtxt(names=True)
(exit 77 without numpy)."""
import sys
import xml.etree.ElementTree as ET


def traj(path, nframes, n):
    try:
        import ase.io
    except ImportError:
        print("ASE not installed (python3-ase): trajectory check skipped")
        return 77
    frames = ase.io.read(path, ":")
    assert len(frames) == nframes, f"{len(frames)} frames, expected {nframes}"
    for k, a in enumerate(frames):
        assert len(a) == n, f"frame {k}: {len(a)} particles"
        for key in ("strain", "phi", "time", "shear_strain"):
            assert key in a.info, f"frame {k}: no {key} in the comment line"
        for col in ("type", "radius", "velo", "nonaffine_velo", "force_ext"):
            assert col in a.arrays, f"frame {k}: no column {col}"
        assert a.info["frame"] == k
        # the affine part of V is V - U: gammadot y in x (rate 1), 0 otherwise
        v, u, y = a.arrays["velo"], a.arrays["nonaffine_velo"], a.positions[:, 1]
        assert abs((v - u)[:, 0] - y).max() < 1e-9 * max(1.0, abs(y).max()), f"frame {k}: V - U is not the shear"
    times = [a.info["time"] for a in frames]
    assert times == sorted(times) and len(set(times)) == len(times), "frame times do not increase"
    return 0


def svg(path, npoints, nlines):
    root = ET.parse(path).getroot()
    lines = [e for e in root.iter() if e.tag.endswith("polyline")]
    assert len(lines) == nlines, f"{len(lines)} polylines, expected {nlines}"
    for e in lines:
        pts = e.get("points").split()
        assert len(pts) == npoints, f"a line has {len(pts)} points, expected {npoints}"
    return 0


def csv(path, nrows):
    try:
        import numpy
    except ImportError:
        print("numpy not installed (python3-numpy): CSV check skipped")
        return 77
    a = numpy.atleast_1d(numpy.genfromtxt(path, delimiter=",", names=True))
    assert a.dtype.names == ("i", "j", "kind", "force", "gap"), a.dtype.names
    assert len(a) == nrows, f"{len(a)} rows, expected {nrows}"
    assert (a["i"] < a["j"]).all() and not numpy.isnan(a["force"]).any()
    return 0


if __name__ == "__main__":
    what, args = sys.argv[1], sys.argv[2:]
    if what == "traj":
        sys.exit(traj(args[0], int(args[1]), int(args[2])))
    if what == "svg":
        sys.exit(svg(args[0], int(args[1]), int(args[2])))
    if what == "csv":
        sys.exit(csv(args[0], int(args[1])))
    sys.exit(f"unknown check {what}")
