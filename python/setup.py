"""setuptools glue for the cffi extension (see odhs_build.py for where the
library is found). Build against an installed libodhs:

    pip install --no-build-isolation --no-index ./python

(PKG_CONFIG_PATH=<prefix>/lib/pkgconfig when pkg-config does not find odhs
by itself). The package version is the library's."""

import os
import sys

from setuptools import setup

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import odhs_build  # noqa: E402

setup(
    version=odhs_build.header_version(odhs_build.find_odhs()["include_dir"]),
    cffi_modules=["odhs_build.py:ffibuilder"],
)
