"""Interoperability with meshio (Debian's python3-meshio): the Gmsh and VTK files Lacuna writes read back
with the node and element counts of Lacuna's report."""

import warnings

import numpy as np
import pytest

import lacuna

meshio = pytest.importorskip("meshio")


def tetra_count(m):
    return sum(len(block.data) for block in m.cells if block.type == "tetra")


@pytest.mark.parametrize("name,options", [("part.msh", {}), ("part2.msh", {"msh_version": "2.2"}),
                                          ("part.vtu", {}), ("part.msh", {"max_tet_volume_mm3": 0.5})])
def test_tetrahedra_saved_from_a_mesh_read_with_meshio(tmp_path, name, options):
    surface = lacuna.sphere(radius_mm=2).mesh(voxel_size_mm=0.25)
    report = surface.save(tmp_path / name, **options)
    assert report["checks"]["valid"] and report["file"] == str(tmp_path / name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = meshio.read(tmp_path / name)
    assert len(m.points) == report["nodes"]
    assert tetra_count(m) == report["tets"]
    assert np.allclose(m.points.min(axis=0), surface.bounding_box[0], atol=1e-6)
    if "max_tet_volume_mm3" in options:
        assert report["max_tet_volume_mm3"] <= 0.5


def test_tetrahedral_outputs_of_a_recipe_read_with_meshio(tmp_path):
    recipe = {
        "voxel_size_mm": 0.2,
        "inputs": {"ball": {"type": "sphere", "radius_mm": 2}, "core": {"type": "sphere", "radius_mm": 1}},
        "outputs": [{"of": "ball", "file": "ball.msh", "fea": {"regions": ["core", "ball"]}},
                    {"of": "ball", "file": "ball.vtu"}],
    }
    result = lacuna.run(recipe, output_dir=tmp_path)
    for entry in result.report["outputs"]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = meshio.read(entry["file"])
        assert len(m.points) == entry["nodes"]
        assert tetra_count(m) == entry["tets"]
    assert result.meshes == {}  # no surface outputs
