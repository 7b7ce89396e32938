"""docs/python.md's code: every ```python block runs, in order, in one
namespace (a tutorial builds on the blocks before), in a scratch directory;
a block followed by a ```text block marked <!-- python-output --> must
print exactly that text. And the examples in python/examples run with small
options and write their pictures."""

import contextlib
import io
import os
import re
import subprocess
import sys

import pytest

from conftest import PYDIR, ROOT

DOC = os.path.join(ROOT, "docs", "python.md")
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```\s*$", re.S | re.M)


def blocks(text):
    """(code, expected output or None) for each ```python block."""
    out = []
    fences = [(m.group(1), m.group(2), m.start(), m.end()) for m in FENCE.finditer(text)]
    for k, (lang, body, start, end) in enumerate(fences):
        if lang != "python":
            continue
        expected = None
        if k + 1 < len(fences):
            nlang, nbody, nstart, _ = fences[k + 1]
            between = text[end:nstart]
            if nlang == "text" and "<!-- python-output -->" in between and between.strip() == \
                    "<!-- python-output -->":
                expected = nbody
        out.append((body, expected))
    return out


def test_docs_python_blocks(tmp_path, monkeypatch):
    text = open(DOC, encoding="utf-8").read()
    found = blocks(text)
    assert len(found) >= 6 and sum(e is not None for _, e in found) >= 6
    # every output block belongs to a python block
    assert text.count("<!-- python-output -->") == sum(e is not None for _, e in found)
    monkeypatch.chdir(tmp_path)
    ns = {"__name__": "__docs__"}
    for k, (code, expected) in enumerate(found):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            exec(compile(code, "%s block %d" % (DOC, k + 1), "exec"), ns)
        if expected is not None:
            assert buf.getvalue() == expected, "block %d printed:\n%s" % (k + 1, buf.getvalue())


def _run_example(name, args, tmp_path):
    pytest.importorskip("matplotlib")
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=PYDIR)
    r = subprocess.run([sys.executable, os.path.join(PYDIR, "examples", name)] + args, cwd=str(tmp_path),
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    return r.stdout


def test_flow_curve_example(tmp_path):
    out = _run_example("flow_curve.py", ["--n", "32", "--pressures", "10,100", "--strain", "0.2", "--transient",
                                         "0.1", "--block", "0.05", "--out", "fc.svg", "--csv", "fc.csv"], tmp_path)
    assert "wrote fc.svg" in out
    assert (tmp_path / "fc.svg").read_text().count("<svg") == 1
    import numpy as np

    t = np.genfromtxt(str(tmp_path / "fc.csv"), delimiter=",", names=True)
    assert list(t["p"]) == [10.0, 100.0] and np.all(t["mu"] > 0) and np.all((t["phi"] > 0.7) & (t["phi"] < 0.9))


def test_jammed_packing_example(tmp_path):
    out = _run_example("jammed_packing.py", ["--n", "32", "--seed", "2", "--out", "j.png", "--svg", "j.svg",
                                             "--contacts", "j.csv"], tmp_path)
    assert "certified              yes" in out
    png = (tmp_path / "j.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10000
    assert (tmp_path / "j.svg").exists() and (tmp_path / "j.csv").exists()
