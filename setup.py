"""The one compiled extension, :mod:`vnrrt.planners._straight` (the rest is pyproject.toml).

Optional: without a C compiler (or on a system without ``clock_gettime``) the install goes on
and :mod:`vnrrt.planners.native` uses the Python answer instead.
"""

import os

import numpy
from setuptools import Extension, setup

EXTENSIONS = [
    Extension(
        "vnrrt.planners._straight",
        ["src/vnrrt/planners/_straight.c"],
        include_dirs=[numpy.get_include()],
        define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
        extra_compile_args=["-O2"],
        optional=True,
    )
]

setup(ext_modules=EXTENSIONS if os.name == "posix" else [])
