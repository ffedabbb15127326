"""cmake --install puts the package (extension, stubs, py.typed) where the interpreter imports it from."""

import os
import pathlib
import shutil
import subprocess
import sys

import pytest


def test_installed_package_imports(tmp_path):
    build = os.environ.get("LACUNA_BUILD_DIR")
    if not build or not shutil.which("cmake"):
        pytest.skip("needs LACUNA_BUILD_DIR (set by CTest) and cmake")
    done = subprocess.run(["cmake", "--install", build, "--prefix", str(tmp_path), "--component", "python"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    packages = list(tmp_path.glob("lib/python3*/*-packages/lacuna"))
    assert len(packages) == 1
    names = sorted(p.name for p in packages[0].iterdir())
    assert "__init__.py" in names and "__init__.pyi" in names and "py.typed" in names
    assert any(n.startswith("_lacuna.") and n.endswith(".so") for n in names)
    env = dict(os.environ, PYTHONPATH=str(packages[0].parent))
    code = "import lacuna; print(lacuna.__file__); print(lacuna.sphere(radius_mm=1).mesh(voxel_size_mm=0.2).components)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    where, components = done.stdout.split()
    assert pathlib.Path(where).parent == packages[0] and components == "1"


def test_stubs_cover_the_module():
    import ast

    import lacuna

    stub = pathlib.Path(lacuna.__file__).with_name("__init__.pyi")
    tree = ast.parse(stub.read_text())
    declared = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    public = {n for n in dir(lacuna) if not n.startswith("_")}
    assert public <= declared, sorted(public - declared)
    assert pathlib.Path(lacuna.__file__).with_name("py.typed").exists()
