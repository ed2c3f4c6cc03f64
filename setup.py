"""The one compiled extension, :mod:`vnrrt.planners._straight` (the rest is pyproject.toml).

Optional: where it does not build (no C compiler or Python headers), the install goes on and
:mod:`vnrrt.planners.native` uses the Python answer instead. numpy's headers are found when
the extension is built (numpy is a build requirement in pyproject.toml).
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class BuildExt(build_ext):
    """``build_ext`` with numpy's include directory."""

    def finalize_options(self):
        super().finalize_options()
        import numpy

        self.include_dirs.append(numpy.get_include())


setup(
    cmdclass={"build_ext": BuildExt},
    ext_modules=[
        Extension(
            "vnrrt.planners._straight",
            ["src/vnrrt/planners/_straight.c"],
            define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
            optional=True,
        )
    ],
)
