"""Build the optional C extension ``inertia_tool._accel`` (everything else is in pyproject.toml).

``optional=True``: when no C compiler is available the build prints a warning and the package installs
without it; the engine then runs on its pure-numpy path (the same results, slower).
"""

import sys

from setuptools import Extension, setup

# POSIX threads for the kernels' threads (part of libc on current glibc and macOS; older glibc, e.g.
# manylinux2014, needs the flag); Windows threads need nothing.
_PTHREAD = [] if sys.platform == "win32" else ["-pthread"]

setup(ext_modules=[Extension("inertia_tool._accel", sources=["inertia_tool/_accel.c"], optional=True,
                             extra_compile_args=_PTHREAD, extra_link_args=_PTHREAD)])
