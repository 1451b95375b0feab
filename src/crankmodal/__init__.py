"""crankmodal: structural dynamics of crank-linkage machines.

Stages (one subpackage each) hand plain data to each other:
parameters -> geometry -> mesh -> matrices -> modes -> reduced body -> dynamics -> report.
Heavy dependencies (gmsh, scikit-fem, pyvista) are imported inside the stage that uses them,
so ``import crankmodal`` stays light.
"""

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _version

try:
    __version__ = _version("crankmodal")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+local"

__all__ = ["__version__"]
