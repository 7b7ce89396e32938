"""Shared fixtures of the odhs Python tests.

Environment (set by `make check-python`):
  ODHS_EXAMPLES          directory of the C example binaries (build/examples)
  ODHS_REQUIRE_EXAMPLES  1: a missing example binary fails the test instead
                         of skipping it
  ODHS_STAGE             the staged install (build/stage), for pip install
"""

import os
import subprocess

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
PYDIR = os.path.dirname(HERE)
ROOT = os.path.dirname(PYDIR)


@pytest.fixture(scope="session")
def root():
    """The libodhs source tree."""
    return ROOT


@pytest.fixture(scope="session")
def example():
    """example(name) -> path of the C example binary, or skip/fail."""
    d = os.environ.get("ODHS_EXAMPLES", os.path.join(ROOT, "build", "examples"))

    def find(name):
        path = os.path.join(d, name)
        if not os.access(path, os.X_OK):
            msg = "C example %s not built (make examples-build, or make check-python)" % path
            if os.environ.get("ODHS_REQUIRE_EXAMPLES") == "1":
                pytest.fail(msg)
            pytest.skip(msg)
        return path

    return find


def run_c(args, cwd=None):
    """Run a C example; its stdout (fails the test on a non-zero exit)."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    r = subprocess.run(args, cwd=cwd, capture_output=True, text=True, env=env)
    assert r.returncode == 0, "%s failed (%d): %s" % (" ".join(args), r.returncode, r.stderr)
    return r.stdout
