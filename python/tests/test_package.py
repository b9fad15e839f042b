# SPDX-License-Identifier: MIT
"""The package as users meet it: stubs in step with the module, documented API, threads."""
import ast
import concurrent.futures
import importlib
import inspect
import os
import pathlib
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

import taxel

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "taxel"
# Child processes import the package under test, wherever the working directory is.
ENV = dict(os.environ, PYTHONPATH=str(pathlib.Path(taxel.__file__).resolve().parents[1]))


def test_stubs_are_current_and_parse():
    tool = PACKAGE.parent / "tools" / "stubgen.py"
    run = subprocess.run([sys.executable, str(tool), "--check", str(PACKAGE)], capture_output=True, text=True,
                         env=ENV)
    assert run.returncode == 0, run.stderr
    for stub in PACKAGE.glob("*.pyi"):
        ast.parse(stub.read_text())


def test_version_and_submodules():
    assert taxel.__version__.count(".") == 2
    from taxel.fusion import ContactCloud  # submodules import like packages

    assert ContactCloud is taxel.fusion.ContactCloud
    assert importlib.import_module("taxel.image").segment is taxel._taxel.image.segment


SUBMODULES = ("fusion", "image", "index", "io", "learn", "optical", "registration", "sensor", "shape", "sim")


def _doc_text(obj, name):
    """A member's documentation without pybind11's signature lines."""
    if isinstance(obj, property):
        doc = obj.__doc__ or (obj.fget.__doc__ if obj.fget else "") or ""
    else:
        doc = getattr(obj, "__doc__", "") or ""
    signature = re.compile(rf"^(\d+\. )?{re.escape(name)}\(.*\) -> |^\(self: .*\) -> |^Overloaded function\.$")
    return "\n".join(ln for ln in doc.splitlines() if ln.strip() and not signature.match(ln.strip()))


def _public():
    """(qualified name, object) of every public class, function and class member."""
    seen = set()
    for sub in ("",) + SUBMODULES:
        mod = getattr(taxel, sub) if sub else taxel
        for name in dir(mod):
            obj = getattr(mod, name)
            if name.startswith("_") or inspect.ismodule(obj) or id(obj) in seen:
                continue
            seen.add(id(obj))
            if inspect.isclass(obj):
                yield f"{sub}.{name}", name, obj
                for attr, member in vars(obj).items():
                    if not attr.startswith("_"):
                        yield f"{sub}.{name}.{attr}", attr, member
            elif callable(obj):
                yield f"{sub}.{name}", name, obj


def test_every_public_member_is_documented():
    members = list(_public())
    assert len(members) > 280
    undocumented = [q for q, name, obj in members if not _doc_text(obj, name).strip()]
    assert undocumented == []


def test_every_class_has_a_repr_of_its_own():
    default = [q for q, _, obj in _public() if inspect.isclass(obj) and not issubclass(obj, BaseException)
               and obj.__repr__ is object.__repr__]
    assert default == []


def test_a_misspelled_keyword_names_itself_and_its_neighbour():
    with pytest.raises(TypeError) as e:
        taxel.image.segment(np.zeros((8, 8)), min_aera=3)
    assert str(e.value).startswith("segment() got an unexpected keyword argument 'min_aera'; did you mean 'min_area'?")
    with pytest.raises(TypeError, match=r"ContactCloud.insert\(\) got an unexpected keyword argument 'sigmaa'"):
        taxel.fusion.ContactCloud().insert(np.zeros((2, 3)), sigmaa=1e-3)
    with pytest.raises(TypeError) as e:
        taxel.image.segment(np.zeros((400, 400)).tolist(), k="three")
    assert len(str(e.value)) < 400 and "got (list, k=str)" in str(e.value)
    with pytest.raises(TypeError, match="unexpected keyword argument 'Cc'; did you mean 'C'"):
        taxel.learn.LinearSvm(Cc=1.0)


def _mypy(*targets, strict=False):
    if shutil.which("mypy") is None:
        pytest.skip("mypy is not installed (Debian: mypy)")
    config = pathlib.Path(os.environ.get("TMPDIR", "/tmp")) / f"taxel-mypy-{os.getpid()}.ini"
    config.write_text("[mypy]\ncache_dir = /dev/null\n[mypy-matplotlib.*]\nignore_missing_imports = True\n")
    try:
        cmd = ["mypy", "--config-file", str(config), "--no-incremental"] + (["--strict"] if strict else []) + list(targets)
        run = subprocess.run(cmd, capture_output=True, text=True, env=ENV, cwd=str(config.parent))
    finally:
        config.unlink()
    assert run.returncode == 0, run.stdout + run.stderr


def test_mypy_strict_on_the_package():
    _mypy("-p", "taxel", strict=True)


def test_mypy_on_the_examples_and_the_readme(tmp_path):
    root = PACKAGE.parents[1]
    blocks = re.findall(r"```python\n(.*?)```", (root / "README.md").read_text(), re.S)
    assert blocks
    readme = tmp_path / "readme_block.py"
    readme.write_text("\n".join(blocks))
    _mypy(str(root / "examples" / "python"), str(readme))


def test_errors_are_python_exceptions():
    assert issubclass(taxel.IoError, OSError)
    try:
        taxel.io.read_image("/nonexistent/x.npy")
    except OSError as e:
        assert "/nonexistent/x.npy" in str(e)


def test_long_calls_release_the_gil():
    # Two threads each align; with the GIL released both run in C++ at once, and the results
    # equal the sequential ones.
    shape = taxel.sim.Torus()
    model = shape.sample_surface(20000, 1).points
    target = taxel.registration.Target(model)
    src = model[::3] + [0.002, -0.001, 0.0015]
    icp = taxel.registration.Icp(max_iterations=30)
    alone = icp.align(target, src).transform
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        results = list(pool.map(lambda _: icp.align(target, src).transform, range(4)))
    for r in results:
        np.testing.assert_array_equal(r, alone)


def test_examples_run(tmp_path):
    examples = PACKAGE.parents[1] / "examples" / "python"
    env = dict(ENV, MPLBACKEND="Agg", TAXEL_EXAMPLE_QUICK="1")
    scripts = sorted(examples.glob("*.py"))
    assert len(scripts) >= 2
    for script in scripts:
        run = subprocess.run([sys.executable, str(script), "--out", str(tmp_path)], capture_output=True,
                             text=True, env=env, timeout=300)
        assert run.returncode == 0, f"{script.name}: {run.stderr}"
        assert run.stdout.strip(), script.name


def test_readme_session_runs(tmp_path):
    readme = (PACKAGE.parents[1] / "README.md").read_text()
    block = re.search(r"```python\n(.*?)```", readme, re.S).group(1)
    run = subprocess.run([sys.executable, "-W", "ignore", "-c", block], cwd=tmp_path, capture_output=True,
                         text=True, timeout=300, env=ENV)
    assert run.returncode == 0, run.stderr
    # It prints the cloud's size and its error against the true sphere, well under a millimetre.
    points, error = run.stdout.split(" ", 1)
    assert int(points) > 10
    assert 0 < ast.literal_eval(error)["rms"] < 1e-3
