"""Errors: bad input raises ValueError with the message the command line prints, a refused memory budget
ResourceLimitError, failed checks CheckFailedError, files that cannot be read FileError (an OSError)."""

import json

import numpy as np
import pytest

import lacuna
from conftest import write_json

BAD_RECIPES = [
    {"inputs": {"ball": {"type": "sphere", "radius_mm": -1}}, "outputs": [{"of": "ball", "file": "b.stl"}]},
    {"inputs": {"ball": {"type": "sphere", "radus_mm": 1}}, "outputs": [{"of": "ball", "file": "b.stl"}]},
    {"inputs": {"ball": {"type": "sphear", "radius_mm": 1}}, "outputs": [{"of": "ball", "file": "b.stl"}]},
    {"inputs": {"ball": {"type": "sphere", "radius_mm": 1}}, "outputs": [{"of": "bal", "file": "b.stl"}]},
    {"inputs": {"ball": {"type": "sphere", "radius_mm": 1}}, "operations": [{"name": "o", "op": "offset", "of": "ball",
     "distance_mm": 0}], "outputs": [{"of": "o", "file": "b.stl"}]},
]


@pytest.mark.parametrize("recipe", BAD_RECIPES)
def test_bad_recipes_raise_value_error_with_the_command_line_message(tmp_path, cli, recipe):
    path = write_json(tmp_path / "bad.json", recipe)
    code, out, err = cli("run", path, "-o", tmp_path / "out")
    assert code == 2
    with pytest.raises(ValueError) as raised:
        lacuna.run(path, output_dir=tmp_path / "out")
    assert isinstance(raised.value, lacuna.InvalidInputError)
    assert err == "lacuna: error: " + str(raised.value) + "\n"
    assert not (tmp_path / "out").exists()


def test_constructors_give_the_recipe_messages():
    with pytest.raises(ValueError, match=r"radius_mm: expected a positive length in mm, got -1"):
        lacuna.sphere(radius_mm=-1)
    with pytest.raises(ValueError, match=r'unknown key "radus_mm"; did you mean "radius_mm"\?'):
        lacuna.sphere(radus_mm=1)
    with pytest.raises(ValueError, match="minor_radius_mm: expected less than major_radius_mm"):
        lacuna.torus(major_radius_mm=1, minor_radius_mm=2)
    with pytest.raises(ValueError, match="distance_mm: expected a non-zero distance"):
        lacuna.sphere(radius_mm=1).offset(0)
    with pytest.raises(ValueError, match="thickness_mm"):
        lacuna.sphere(radius_mm=1).shell(-1)
    with pytest.raises(TypeError):
        lacuna.sphere(radius_mm=1) | 3
    with pytest.raises(TypeError):
        lacuna.box([1, 2, 3])
    with pytest.raises(ValueError, match="must be an input"):
        lacuna.lattice(cell="cubic", period_mm=2, strut_radius_mm=0.2, fit_to=lacuna.box(size_mm=[4, 4, 4]).offset(1))


def test_generator_messages_match_the_command_line(cli):
    code, out, err = cli("curve", "fill-rate", "--kind", "peano", "--orders", "1..3")
    assert code == 2
    with pytest.raises(ValueError) as raised:
        lacuna.curve_fill_rate(kind="peano", orders="1..3")
    # The same message, naming the option as each front end spells it.
    assert err == "lacuna: error: --" + str(raised.value) + "\n"
    code, out, err = cli("bcifs", "rules", "--boundary", "C4 X2")
    with pytest.raises(ValueError) as raised:
        lacuna.bcifs_rules("C4 X2")
    assert str(raised.value).startswith("boundary: ") and str(raised.value)[len("boundary: "):] in err


def test_unreadable_files_raise_file_error(tmp_path, cli):
    missing = tmp_path / "missing.json"
    code, out, err = cli("run", missing)
    with pytest.raises(OSError) as raised:
        lacuna.run(missing)
    assert isinstance(raised.value, lacuna.FileError) and isinstance(raised.value, ValueError)
    assert err == "lacuna: error: " + str(raised.value) + "\n"
    garbage = tmp_path / "garbage.stl"
    garbage.write_bytes(b"solid nonsense\nfacet normal x\n")
    code, out, err = cli("check", garbage)
    assert code == 2
    with pytest.raises(ValueError) as raised:
        lacuna.read_mesh(garbage)
    assert err == "lacuna: error: " + str(raised.value) + "\n"


def test_refused_memory_budget(tmp_path, cli):
    recipe = {"voxel_size_mm": 0.02, "inputs": {"ball": {"type": "sphere", "radius_mm": 20}},
              "outputs": [{"of": "ball", "file": "b.stl"}]}
    path = write_json(tmp_path / "big.json", recipe)
    code, out, err = cli("run", path, "--max-memory", 0.5, "-o", tmp_path / "out")
    assert code == 3
    with pytest.raises(lacuna.ResourceLimitError) as raised:
        lacuna.run(path, max_memory_gb=0.5, output_dir=tmp_path / "out")
    assert err == "lacuna: error: " + str(raised.value) + "\n"
    assert "voxel size of" in str(raised.value)
    with pytest.raises(lacuna.ResourceLimitError):
        lacuna.sphere(radius_mm=20).mesh(voxel_size_mm=0.02, max_memory_gb=0.5)
    assert isinstance(raised.value, lacuna.LacunaError) and not isinstance(raised.value, ValueError)


def test_failed_checks_raise_check_failed(tmp_path):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    open_mesh = lacuna.Mesh(v, np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2]]))
    with pytest.raises(lacuna.CheckFailedError) as raised:
        open_mesh.save(tmp_path / "t.msh")
    assert "boundary edges" in str(raised.value)
    assert raised.value.report["checks"]["valid"] is False
    assert not (tmp_path / "t.msh").exists()
