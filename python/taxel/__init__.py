# SPDX-License-Identifier: MIT
"""taxel: tactile perception for robot hands, grippers and prostheses.

Fusion of contact streams into compact clouds (Meier et al. 2011), ICP and object recognition,
pressure-image segmentation, region descriptors, reconstruction and classifiers, with numpy
arrays in and out. Lengths are in metres, angles in radians, unless a name says otherwise.
"""
import sys as _sys

from . import _taxel
from ._taxel import Contacts, IoError, PointCloud, ProtocolError, __version__
from ._taxel import fusion, image, index, io, optical, registration, sensor, shape, sim

# `import taxel.fusion` and `from taxel.image import segment` work like for any package.
for _name in ("fusion", "image", "index", "io", "optical", "registration", "sensor", "shape", "sim"):
    _sys.modules[f"{__name__}.{_name}"] = getattr(_taxel, _name)

from . import learn  # noqa: E402 - the estimators over the compiled taxel._taxel.learn


def _pickle_by_arguments(cls, names):
    """Pickling and copies of a class that its constructor's keyword arguments, each readable
    as an attribute of the same name, fully describe (shapes, sensor models, options)."""
    import copyreg
    import functools

    def reduce(obj):
        return functools.partial(cls, **{n: getattr(obj, n) for n in names}), ()

    copyreg.pickle(cls, reduce)


for _cls, _names in (
    (sim.Sphere, ("radius",)),
    (sim.Cylinder, ("radius", "half_height")),
    (sim.Box, ("half_extents",)),
    (sim.Cone, ("radius", "height")),
    (sim.Ellipsoid, ("semi_axes",)),
    (sim.Torus, ("major_radius", "minor_radius")),
    (sensor.SensorModel, ("rows", "cols", "pitch", "full_scale_depth", "levels", "threshold",
                          "sigma_normal", "sigma_position", "sigma_tilt")),
    (sensor.ContactOptions, ("mode", "local_normals", "correct_censoring", "fallback_normal_sigma",
                             "refine_censoring", "tactel_area")),
):
    _pickle_by_arguments(_cls, _names)

__all__ = [
    "Contacts",
    "IoError",
    "PointCloud",
    "ProtocolError",
    "__version__",
    "fusion",
    "image",
    "index",
    "io",
    "learn",
    "optical",
    "registration",
    "sensor",
    "shape",
    "sim",
]

from . import _reprs  # noqa: E402

_reprs.install(_sys.modules[__name__])

from . import _errors  # noqa: E402

_errors.install(_taxel, fusion, image, index, io, optical, registration, sensor, shape, sim)
