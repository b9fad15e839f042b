# SPDX-License-Identifier: MIT
"""Writes the type stubs of the taxel package (taxel/*.pyi) from the compiled module.

pybind11 puts each function's signature on the first line of its docstring; this script turns
those signatures into stub declarations, one .pyi per submodule plus taxel/__init__.pyi.

    PYTHONPATH=<build>/python python3 python/tools/stubgen.py python/taxel      # write
    PYTHONPATH=<build>/python python3 python/tools/stubgen.py --check python/taxel
"""
import argparse
import ast
import inspect
import pathlib
import re
import sys

import taxel
from taxel import _taxel

SUBMODULES = ("fusion", "image", "index", "io", "optical", "registration", "sensor", "shape", "sim")
# Pure-Python submodules: typed inline (py.typed), so they get no stub of their own.
PYTHON_MODULES = ("learn",)
F64 = "numpy.typing.NDArray[numpy.float64]"
# Return types that pybind11 spells `object`, `tuple`, `dict` or `list`, by qualified name.
RETURNS = {
    "fusion.ContactCloud.insert": "taxel.fusion.InsertResult",
    "fusion.ContactCloud.insert_readings": "taxel.fusion.InsertResult",
    "fusion.ContactCloud.query": f"typing.Tuple[{F64}, numpy.typing.NDArray[numpy.int64]]",
    "fusion.ContactCloud.query_ball_point": "typing.List[numpy.typing.NDArray[numpy.int64]]",
    "index.KdTree.query": f"typing.Tuple[{F64}, numpy.typing.NDArray[numpy.int64]]",
    "index.KdTree.query_ball_point": "typing.List[numpy.typing.NDArray[numpy.int64]]",
    "image.Recognizer.features": "taxel.image.ImageFeatures",
    "image.gradient": f"typing.Tuple[{F64}, {F64}]",
    "image.sobel": f"typing.Tuple[{F64}, {F64}]",
    "image.label": "typing.Tuple[numpy.typing.NDArray[numpy.int32], int]",
    "image.region_props": "taxel.image.RegionProps",
    "image.regionprops": "typing.List[taxel.image.RegionProps]",
    "io.read_pad_poses_csv": "taxel.io.PadPoses",
    "io.read_ply": "typing.Tuple[taxel.PointCloud, numpy.typing.NDArray[numpy.uint32]]",
    "optical.MarkerTracker.field": f"typing.Tuple[{F64}, {F64}]",
    "optical.fit_ball": "typing.Tuple[float, float, float]",
    "optical.reconstruct": "taxel.optical.HeightMapResult",
    "registration.Target.nearest": f"typing.Tuple[numpy.typing.NDArray[numpy.int64], {F64}]",
    "registration.model_cloud": "typing.Tuple[taxel.PointCloud, str]",
    "shape.ImplicitSurface.mesh": "taxel.shape.SurfaceMesh",
    "shape.ImplicitSurface.predict": f"typing.Tuple[{F64}, {F64}, {F64}]",
    "shape.ImplicitSurface.score_touches": "taxel.shape.TouchScores",
    "shape.Explorer.estimate": "taxel.shape.SurfaceMesh",
    "shape.Explorer.score": "taxel.shape.TouchScores",
    "shape.Explorer.predict": f"typing.Tuple[{F64}, {F64}]",
    "shape.approach_rays": f"typing.Tuple[{F64}, {F64}]",
    "shape.marching_tetrahedra": f"typing.Tuple[{F64}, numpy.typing.NDArray[numpy.uint32]]",
    "sim.PalmGraspSynth.dataset": "taxel.sim.GraspDataset",
    "sim.surface_error": "taxel.sim.SurfaceError",
}
# Module constants whose type pybind11 cannot say.
CONSTANTS = {
    "fusion.INDEXES": "typing.Tuple[str, ...]",
    "fusion.POLICIES": "typing.Tuple[str, ...]",
    "image.EDGE_FEATURE_NAMES": "typing.List[str]",
    "image.REGIONAL_FEATURE_NAMES": "typing.List[str]",
}
B = "numpy.typing.NDArray[numpy.bool_]"
# The dicts the module returns, as TypedDicts of the stubs (for type checkers only).
TYPED_DICTS = {
    "fusion": {"InsertResult": {"added": "int", "fused": "int", "rejected": "int"}},
    "image": {
        "RegionProps": {
            "area": "float", "centroid": "typing.Tuple[float, float]",
            "bounding_box": "typing.Tuple[float, float, float, float]", "major_axis_length": "float",
            "minor_axis_length": "float", "eccentricity": "float", "orientation": "float",
            "convex_area": "float", "convex_hull": F64, "solidity": "float", "extent": "float",
            "equiv_diameter": "float", "euler_number": "int", "euler_number4": "int",
            "perimeter": "float", "label": "typing.NotRequired[int]",
        },
        "ImageFeatures": {"regional": F64, "edge": F64, "hybrid": F64, "edged": F64, "contour_gradient": F64},
    },
    "io": {
        "PadPoses": {
            "frame": "numpy.typing.NDArray[numpy.int64]", "pad": "numpy.typing.NDArray[numpy.int64]",
            "time": F64, "pose": F64,
        },
    },
    "optical": {"HeightMapResult": {"height": F64, "gx": F64, "gy": F64, "mask": B, "contact": B}},
    "shape": {
        "SurfaceMesh": {"vertices": F64, "triangles": "numpy.typing.NDArray[numpy.uint32]", "sigma": F64, "normals": F64},
        "TouchScores": {"contact": B, "point": F64, "normal": F64, "gain": F64},
    },
    "sim": {
        "SurfaceError": {"signed_mean": "float", "mean": "float", "rms": "float", "max": "float"},
        "GraspDataset": {
            "images": F64, "labels": "numpy.typing.NDArray[numpy.int32]",
            "subjects": "numpy.typing.NDArray[numpy.int32]", "right_hand": B,
        },
    },
}
HEADER = "# SPDX-License-Identifier: MIT\n# Generated by python/tools/stubgen.py from the compiled module; do not edit.\n"


def clean_type(text):
    """A pybind11 type spelling as a stub type."""
    text = re.sub(r"numpy\.ndarray\[([\w.]+)(?:\[[^\]]*\])?(?:, flags\.\w+)*\]", r"numpy.typing.NDArray[\1]", text)
    text = text.replace("numpy.ndarray", "numpy.typing.NDArray[typing.Any]")
    text = text.replace("NDArray[bool]", "NDArray[numpy.bool_]")
    text = re.sub(r"\btaxel\._taxel\.", "taxel.", text)
    for name in ("List", "Dict", "Tuple", "Optional", "Union", "Callable", "Any", "Iterable", "Sequence"):
        text = re.sub(rf"(?<![\w.]){name}\[", f"typing.{name}[", text)
    text = re.sub(r"(?<![\w.])(Any)(?![\w\[])", r"typing.Any", text)
    return text


def split_params(text):
    """Top-level comma split of a parameter list."""
    out, depth, cur = [], 0, ""
    for ch in text:
        if ch in "[(<":
            depth += 1
        elif ch in "])>":
            depth -= 1
        if ch == "," and depth == 0:
            out.append(cur.strip())
            cur = ""
        else:
            cur += ch
    if cur.strip():
        out.append(cur.strip())
    return out


def clean_params(params):
    out = []
    for p in split_params(params):
        if p in ("*", "/"):
            out.append(p)
            continue
        m = re.match(r"(\*{0,2}\w+)(?:: (.*?))?(?: = (.*))?$", p)
        name, typ, default = m.group(1), m.group(2), m.group(3)
        if name == "self":
            out.append("self")
            continue
        s = name
        if typ:
            s += ": " + clean_type(typ)
        if default is not None:
            try:
                ast.literal_eval(default)
            except (ValueError, SyntaxError):
                default = "..."  # not a literal (inf, an object): the docstring states it
            s += " = " + default
        out.append(s)
    return ", ".join(out)


def signatures(name, obj):
    """The (params, return type) of each overload of a pybind11 function."""
    doc = obj.__doc__ or ""
    sigs = re.findall(rf"^(?:\d+\. )?{re.escape(name)}\((.*)\) -> (.*)$", doc, re.M)
    return [(clean_params(p), clean_type(r)) for p, r in sigs]


def summary(obj):
    """The docstring without its signature lines, as a one-line stub docstring."""
    doc = obj.__doc__ or ""
    lines = [ln for ln in doc.splitlines() if not re.match(r"^(\d+\. )?\w+\(.*\) -> ", ln) and ln.strip() != "Overloaded function."]
    text = " ".join(ln.strip() for ln in lines if ln.strip())
    return text.replace("\\", "\\\\").replace('"""', "'''")


def function_stub(name, obj, indent="", qualname=""):
    sigs = signatures(name, obj)
    out = []
    over = len(sigs) > 1
    doc = summary(obj)
    for params, ret in sigs:
        if qualname in RETURNS:
            ret = RETURNS[qualname]
        elif ret in ("object", "tuple", "dict", "list"):
            raise SystemExit(f"stubgen: {qualname} returns a bare {ret}; give its type in RETURNS")
        if over:
            out.append(f"{indent}@typing.overload")
        line = f"{indent}def {name}({params}) -> {ret}:"
        out.append(line + (f' """{doc}"""' if doc and not over else " ..."))
    return out


def class_stub(name, cls, modname):
    doc = (cls.__doc__ or "").strip().replace('"""', "'''")
    out = [f"class {name}:"]
    if doc:
        out.append(f'    """{doc}"""')
    for attr, value in sorted(vars(cls).items(), key=lambda kv: kv[0]):
        if attr.startswith("_") and attr not in ("__init__", "__len__", "__repr__"):
            continue
        if isinstance(value, property):
            sig = signatures("", value.fget) if value.fget else []
            typ = sig[0][1] if sig else "typing.Any"
            out.append("    @property")
            out.append(f"    def {attr}(self) -> {typ}: ...")
        elif isinstance(value, staticmethod) or type(value).__name__ == "builtin_function_or_method":
            fn = getattr(cls, attr)
            out.append("    @staticmethod")
            out += function_stub(attr, fn, "    ", f"{modname}.{name}.{attr}")
        elif callable(value):
            out += function_stub(attr, value, "    ", f"{modname}.{name}.{attr}")
    if len(out) == 1:
        out.append("    ...")
    return out


def module_stub(mod, imports, modname=""):
    lines = [HEADER, "import typing", "", "import numpy", "import numpy.typing", ""]
    lines += [f"import {i}" for i in imports]
    lines.append("")
    for td, fields in TYPED_DICTS.get(modname, {}).items():
        lines += ["", f"class {td}(typing.TypedDict):"]
        lines += [f"    {key}: {typ}" for key, typ in fields.items()]
        lines.append("")
    prefix = f"{modname}." if modname else ""
    for name, value in sorted(vars(mod).items()):
        if name.startswith("_") or inspect.ismodule(value):
            continue
        if inspect.isclass(value):
            if issubclass(value, BaseException):
                continue
            lines += [""] + class_stub(name, value, modname) + [""]
        elif callable(value):
            lines += function_stub(name, value, "", prefix + name) + [""]
        elif prefix + name in CONSTANTS:
            lines.append(f"{name}: {CONSTANTS[prefix + name]}")
        else:
            typ = type(value).__name__
            if typ in ("tuple", "list", "dict"):
                raise SystemExit(f"stubgen: give the type of {prefix + name} in CONSTANTS")
            lines.append(f"{name}: {typ}")
    return "\n".join(lines).rstrip() + "\n"


def stubs():
    imports = ["taxel"] + [f"taxel.{s}" for s in sorted(SUBMODULES + PYTHON_MODULES)]
    out = {}
    for sub in SUBMODULES:
        out[f"{sub}.pyi"] = module_stub(getattr(_taxel, sub), imports, sub)
    top = module_stub(_taxel, imports).rstrip() + "\n\n"
    top += "class IoError(OSError): ...\nclass ProtocolError(OSError): ...\n\n__version__: str\n"
    top += "".join(f"from taxel import {s} as {s}\n" for s in sorted(SUBMODULES + PYTHON_MODULES))
    out["__init__.pyi"] = top
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("package_dir", type=pathlib.Path)
    ap.add_argument("--check", action="store_true", help="fail when a stub differs")
    args = ap.parse_args()
    stale = []
    for name, text in stubs().items():
        path = args.package_dir / name
        if args.check:
            if not path.exists() or path.read_text() != text:
                stale.append(str(path))
        else:
            path.write_text(text)
    if stale:
        print("stale stubs (regenerate with python/tools/stubgen.py): " + ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
