# SPDX-License-Identifier: MIT
"""The package as users meet it: stubs in step with the module, documented API, threads."""
import ast
import concurrent.futures
import importlib
import os
import pathlib
import re
import subprocess
import sys

import numpy as np

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


def test_every_public_callable_is_documented():
    undocumented = []
    for sub in ("fusion", "image", "io", "learn", "optical", "registration", "sensor", "sim"):
        mod = getattr(taxel, sub)
        for name in dir(mod):
            obj = getattr(mod, name)
            if name.startswith("_") or not callable(obj):
                continue
            doc = obj.__doc__ or ""
            signature = re.compile(rf"^(\d+\. )?{name}\(.*\) -> ")
            text = "\n".join(ln for ln in doc.splitlines() if not signature.match(ln) and ln.strip())
            if not text.strip():
                undocumented.append(f"{sub}.{name}")
    assert undocumented == []


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
