# SPDX-License-Identifier: MIT
"""Readable reprs for the compiled classes that pybind11 leaves with the default one."""
import typing

import numpy as np

_Repr = typing.Callable[[typing.Any], str]


def _value(v: typing.Any) -> str:
    if isinstance(v, np.ndarray):
        return np.array2string(v, precision=6, separator=", ")
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, list) and all(isinstance(x, float) for x in v):
        return "[" + ", ".join(f"{x:.6g}" for x in v) + "]"
    return repr(v)


def _fields(*names: str) -> _Repr:
    def rep(self: typing.Any) -> str:
        args = ", ".join(f"{n}={_value(getattr(self, n))}" for n in names)
        return f"{type(self).__name__}({args})"

    return rep


def _from_state(names: typing.Sequence[str]) -> _Repr:
    """A repr from the pickled arguments (state (1, args)) of a class that keeps them."""

    def rep(self: typing.Any) -> str:
        args = self.__getstate__()[1]
        return f"{type(self).__name__}({', '.join(f'{n}={_value(a)}' for n, a in zip(names, args))})"

    return rep


def _mesh(m: typing.Any) -> str:
    vertices, triangles = m.__getstate__()[1]
    return (f"TriangleMesh({len(vertices)} vertices, {len(triangles)} triangles, "
            f"area {m.surface_area():.6g} m^2)")


def install(taxel: typing.Any) -> None:
    """Sets the reprs on the compiled classes of the package `taxel`."""
    sim, image, learn, registration, sensor = (
        taxel.sim, taxel.image, taxel.learn, taxel.registration, taxel.sensor)
    reprs: typing.Dict[typing.Any, _Repr] = {
        sim.Sphere: _fields("radius"),
        sim.Cylinder: _fields("radius", "half_height"),
        sim.Box: _fields("half_extents"),
        sim.Cone: _fields("radius", "height"),
        sim.Ellipsoid: _fields("semi_axes"),
        sim.Torus: _fields("major_radius", "minor_radius"),
        sim.TriangleMesh: _mesh,
        sim.PalmGraspSynth: _from_state(("rows", "cols", "fingers", "seed")),
        sim.Exploration: lambda e: f"Exploration({len(e)} frames, {len(e.contacts)} contacts)",
        sensor.ContactOptions: _fields("mode", "local_normals", "correct_censoring",
                                       "fallback_normal_sigma", "refine_censoring", "tactel_area"),
        image.KMeans1dResult: _fields("status", "k", "centroids", "sse"),
        image.Segmentation: _fields("regions", "background_level", "high_level"),
        image.Recognition: _fields("edged", "contour_gradient"),
        image.Recognizer: _from_state(("rows", "cols", "gradient_threshold", "gradient_source", "k",
                                       "polarity", "min_area", "connectivity")),
        learn.CvReport: _fields("status", "accuracy", "classes"),
        learn.FiveByTwoResult: _fields("status", "t", "p_value", "reject", "mean_error_a",
                                       "mean_error_b"),
        registration.Icp: _fields("error", "kernel", "kernel_scale"),
        registration.Target: lambda t: f"Target({len(t.points)} points with normals)",
        registration.ObjectLibrary: lambda lib: f"ObjectLibrary({lib.names!r})",
    }
    for cls, rep in reprs.items():
        cls.__repr__ = rep
