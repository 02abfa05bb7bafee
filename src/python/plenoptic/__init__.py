"""plenoptic: physically based global illumination precomputed as a light field.

Images are NumPy arrays (height, width, 3) of linear Rec.709 radiance in W/(sr m^2): the
functions return float32 and accept any floating dtype and memory layout. Every name is
defined by the compiled extension plenoptic._plenoptic and re-exported here; __init__.pyi
gives their types.
"""
try:
    import numpy as _numpy  # every image crosses as a NumPy array: fail here, not at the first call
except ImportError as error:
    raise ImportError("plenoptic needs NumPy, which this Python does not have (Debian: apt-get install python3-numpy; "
                      "elsewhere: pip install numpy)") from error
del _numpy

from . import _plenoptic
from ._plenoptic import *  # noqa: F401,F403 (the public API)

__version__ = _plenoptic.__version__
__all__ = sorted(name for name in dir(_plenoptic) if not name.startswith("_"))

# The objects say they belong to `plenoptic` (what users import), not to the extension inside
# it: reprs and help() name plenoptic.Camera, plenoptic.trace, ...
for _name in __all__:
    _object = getattr(_plenoptic, _name)
    if getattr(_object, "__module__", None) == _plenoptic.__name__:
        _object.__module__ = __name__
del _name, _object
