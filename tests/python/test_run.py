"""lacuna.run and lacuna.voxelize: recipes given as paths, JSON text or dicts, the same outputs as
`lacuna run`, and solids that build the same grids as their recipes."""

import json
import os

import numpy as np
import pytest

import lacuna
from conftest import write_json

RECIPE = {
    "voxel_size_mm": 0.15,
    "inputs": {
        "block": {"type": "box", "center_mm": [0, 0, 0], "size_mm": [12, 8, 5]},
        "bore": {"type": "cylinder", "center_mm": [-2, 0, 0], "radius_mm": 2, "height_mm": 6},
    },
    "operations": [{"name": "cut", "op": "difference", "of": ["block", "bore"]}],
    "outputs": [{"of": "cut", "file": "cut.stl"}, {"of": "cut", "file": "cut.3mf"}],
}


def without_times(report):
    r = {k: v for k, v in report.items()
         if k not in ("stage_seconds", "total_seconds", "peak_memory_bytes", "peak_memory_children_bytes",
                      "memory_budget_bytes", "recipe", "threads", "valid", "written")}
    r["outputs"] = [{k: v for k, v in o.items() if k != "file"} for o in report["outputs"]]
    return r


def test_run_gives_the_command_line_report(tmp_path, cli):
    path = write_json(tmp_path / "part.json", RECIPE)
    code, out, err = cli("run", path, "-o", tmp_path / "cli", "--json")
    assert code == 0, err
    expected = json.loads(out)
    result = lacuna.run(path, output_dir=tmp_path / "py")
    assert result.report["valid"] is True
    assert without_times(result.report) == without_times(expected)
    assert sorted(os.listdir(tmp_path / "py")) == ["cut.3mf", "cut.stl", "report.html", "report.json"]
    assert (tmp_path / "py" / "cut.stl").read_bytes() == (tmp_path / "cli" / "cut.stl").read_bytes()
    meshes = result.meshes
    assert sorted(meshes) == ["cut.3mf", "cut.stl"]
    entry = result.report["outputs"][0]
    assert meshes["cut.stl"].faces.shape[0] == entry["triangles"]
    assert meshes["cut.stl"].volume_mm3 == pytest.approx(entry["volume_mm3"], rel=1e-9)
    assert meshes["cut.stl"].genus == entry["genus"] == 1


def test_a_fill_split_by_colour_class_is_a_coloured_multi_object_3mf(tmp_path):
    # One fill_motifs input coloured by size class without "keep": the 3MF read here with zipfile and
    # ElementTree holds one object per class, each pointing at a base material of its palette colour, and
    # their volumes (computed here from the XML's triangles) add up to the file's.
    import xml.etree.ElementTree as ET
    import zipfile

    recipe = {
        "voxel_size_mm": 0.12,
        "inputs": {"tiles": {"type": "fill_motifs", "motif": "hexagon", "height_mm": 1, "count": 10, "seed": 2,
                             "gap_mm": 0.2, "region": {"disk": {"center_mm": [0, 0], "radius_mm": 8}},
                             "color_class": {"by": "size", "classes": 3, "palette": "#ff0000,#00ff00,#0000ff"}}},
        "outputs": [{"of": "tiles", "file": "tiles.3mf"}],
    }
    result = lacuna.run(recipe, output_dir=tmp_path / "out", write_report=False)
    entry = result.report["outputs"][0]
    assert entry["objects"] == ["tiles-0", "tiles-1", "tiles-2"]
    ns = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}
    with zipfile.ZipFile(tmp_path / "out" / "tiles.3mf") as z:
        model = ET.fromstring(z.read("3D/3dmodel.model"))
    groups = model.findall("m:resources/m:basematerials", ns)
    assert len(groups) == 1
    colours = [b.get("displaycolor") for b in groups[0].findall("m:base", ns)]
    assert colours == ["#FF0000FF", "#00FF00FF", "#0000FFFF"]
    total = 0.0
    objects = model.findall("m:resources/m:object", ns)
    assert [o.get("name") for o in objects] == entry["objects"]
    for i, o in enumerate(objects):
        assert o.get("pid") == groups[0].get("id") and o.get("pindex") == str(i)
        v = np.array([[float(x.get(k)) for k in "xyz"] for x in o.findall("m:mesh/m:vertices/m:vertex", ns)])
        t = np.array([[int(x.get(k)) for k in ("v1", "v2", "v3")] for x in o.findall("m:mesh/m:triangles/m:triangle", ns)])
        volume = np.einsum("ij,ij->i", v[t[:, 0]], np.cross(v[t[:, 1]], v[t[:, 2]])).sum() / 6
        assert volume > 0
        total += volume
    assert total == pytest.approx(entry["volume_mm3"], rel=1e-6)
    # The motifs of a size class are the octaves of area: hexagon i has area proportional to (2 + i)^-1.3.
    sizes = [result.report["inputs"]["tiles-%d" % k]["motifs"] for k in range(3)]
    octave = [int(np.floor(1.3 * np.log2((2 + i) / 2) + 1e-12)) % 3 for i in range(10)]
    assert sizes == [octave.count(k) for k in range(3)]


def test_draco_outputs_and_pictures(tmp_path):
    recipe = dict(RECIPE, outputs=[{"of": "cut", "file": "cut.drc", "render": "cut.png"}])
    result = lacuna.run(recipe, output_dir=tmp_path / "out")
    entry = result.report["outputs"][0]
    assert entry["draco"]["file_bytes"] == (tmp_path / "out" / "cut.drc").stat().st_size
    assert entry["picture"] == str(tmp_path / "out" / "cut.png")
    assert result.files == [str(tmp_path / "out" / n) for n in ("cut.drc", "cut.png", "report.html", "report.json")]
    back = result.meshes["cut.drc"]
    assert back.faces.shape[0] == entry["triangles"] and back.genus == entry["genus"] == 1
    assert back.volume_mm3 == pytest.approx(entry["volume_mm3"], rel=1e-9)


def test_dicts_and_json_text(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    from_dict = lacuna.run(RECIPE)
    assert (tmp_path / "recipe-out" / "cut.stl").exists()  # no file: the part is called "recipe"
    from_text = lacuna.run(json.dumps(RECIPE), output_dir="text", voxel_size_mm=0.15, threads=1)
    assert without_times(from_dict.report) == without_times(from_text.report)
    smaller = lacuna.run(dict(RECIPE, name="part"), voxel_size_mm=0.3, write_report=False)
    assert smaller.report["voxel_size_mm"] == 0.3
    assert sorted(os.listdir(tmp_path / "part-out")) == ["cut.3mf", "cut.stl"]


def test_solid_builds_the_grid_of_its_recipe(tmp_path):
    path = write_json(tmp_path / "part.json", RECIPE)
    from_recipe = lacuna.voxelize(path)
    solid = lacuna.box(size_mm=[12, 8, 5]) - lacuna.cylinder(center_mm=[-2, 0, 0], radius_mm=2, height_mm=6)
    from_solid = solid.voxelize(voxel_size_mm=0.15)
    assert from_recipe.active_voxels == from_solid.active_voxels
    rng = np.random.default_rng(1)
    points = rng.uniform(-7, 7, size=(2000, 3))
    assert np.array_equal(from_recipe.distance(points), from_solid.distance(points))
    assert lacuna.voxelize(path, object="bore").active_voxels < from_recipe.active_voxels


def test_solid_recipe_runs_to_the_same_mesh(tmp_path):
    solid = lacuna.sphere(radius_mm=2) | lacuna.capsule(a_mm=[0, 0, 0], b_mm=[4, 0, 0], radius_mm=0.8)
    mesh = solid.mesh(voxel_size_mm=0.1)
    recipe = solid.to_recipe(name="part", voxel_size_mm=0.1)
    assert json.loads(json.dumps(recipe)) == recipe
    result = lacuna.run(recipe, output_dir=tmp_path)
    written = result.meshes["part.stl"]
    assert written.faces.shape == mesh.faces.shape
    assert written.volume_mm3 == pytest.approx(mesh.volume_mm3, rel=1e-9)
    # The same numbers through the Mesh: checks pass and match the report.
    assert result.report["outputs"][0]["checks"]["valid"]
    assert mesh.check()["valid"]


def test_relative_mesh_files_are_read_from_where_the_solid_was_made(tmp_path, monkeypatch, source_dir):
    monkeypatch.chdir(source_dir / "samples")
    hull = lacuna.mesh(file="meshes/egg_hull.stl")
    monkeypatch.chdir(tmp_path)
    assert hull.voxelize(voxel_size_mm=0.5).active_voxels > 0


def test_stream_writes_the_runs_file_slab_by_slab(tmp_path, source_dir):
    recipe = json.loads((source_dir / "samples" / "menger_sponge.json").read_text())
    recipe["outputs"] = [recipe["outputs"][0]]  # the STL
    recipe["voxel_size_mm"] = 1 / 9
    whole = lacuna.run(recipe, tmp_path / "whole", write_report=False)
    assert whole.report["valid"]
    report = lacuna.stream(recipe, tmp_path / "stream", slab_mm=4)
    out = report["outputs"][0]
    assert report["valid"] and out["checks"]["valid"]
    assert out["slabs"] >= 4 and out["check_chunks"] >= 2
    name = "menger_sponge.stl"
    assert (tmp_path / "stream" / name).read_bytes() == (tmp_path / "whole" / name).read_bytes()
    assert out["triangles"] == whole.report["outputs"][0]["triangles"]
    assert out["genus"] == whole.report["outputs"][0]["genus"]
    # What a stream cannot write is refused by name, and nothing is made.
    recipe["outputs"].append({"of": "sponge", "file": "sponge.3mf"})
    with pytest.raises(ValueError, match="a streamed run writes STL meshes"):
        lacuna.stream(recipe, tmp_path / "refused")
    assert not (tmp_path / "refused").exists()
