"""Build the optional C extension ``inertia_tool._accel`` (everything else is in pyproject.toml).

``optional=True``: when no C compiler is available the build prints a warning and the package installs
without it; the engine then runs on its pure-numpy path (the same results, slower).
"""

import os
import sys
import zlib

from setuptools import Extension, setup

# POSIX threads for the kernels' threads (part of libc on current glibc and macOS; older glibc, e.g.
# manylinux2014, needs the flag); Windows threads need nothing.
_PTHREAD = [] if sys.platform == "win32" else ["-pthread"]

# the CRC-32 of the source is compiled in (``_accel.SOURCE_CRC``): in a source checkout, inertia_tool._native
# sets aside an extension built from another _accel.c (a `git pull` without a rebuild) instead of calling
# kernels whose arguments may have changed
_SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "inertia_tool", "_accel.c")
with open(_SOURCE, "rb") as _f:
    _CRC = zlib.crc32(_f.read())

setup(ext_modules=[Extension("inertia_tool._accel", sources=["inertia_tool/_accel.c"], optional=True,
                             define_macros=[("ACCEL_SOURCE_CRC", f"{_CRC}UL")],
                             extra_compile_args=_PTHREAD, extra_link_args=_PTHREAD)])
