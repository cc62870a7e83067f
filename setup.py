"""Build the optional C extension ``inertia_tool._accel`` (everything else is in pyproject.toml).

``optional=True``: when no C compiler is available the build prints a warning and the package installs
without it; the engine then runs on its pure-numpy path (the same results, slower).
"""

from setuptools import Extension, setup

setup(ext_modules=[Extension("inertia_tool._accel", sources=["inertia_tool/_accel.c"], optional=True)])
