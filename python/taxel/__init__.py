# SPDX-License-Identifier: MIT
"""taxel: tactile perception for robot hands, grippers and prostheses.

Fusion of contact streams into compact clouds (Meier et al. 2011), ICP and object recognition,
pressure-image segmentation, region descriptors, reconstruction and classifiers, with numpy
arrays in and out. Lengths are in metres, angles in radians, unless a name says otherwise.
"""
import sys as _sys

from . import _taxel
from ._taxel import Contacts, IoError, PointCloud, ProtocolError, __version__
from ._taxel import fusion, image, io, optical, registration, sensor, sim

# `import taxel.fusion` and `from taxel.image import segment` work like for any package.
for _name in ("fusion", "image", "io", "optical", "registration", "sensor", "sim"):
    _sys.modules[f"{__name__}.{_name}"] = getattr(_taxel, _name)

from . import learn  # noqa: E402 - the estimators over the compiled taxel._taxel.learn

__all__ = [
    "Contacts",
    "IoError",
    "PointCloud",
    "ProtocolError",
    "__version__",
    "fusion",
    "image",
    "io",
    "learn",
    "optical",
    "registration",
    "sensor",
    "sim",
]
