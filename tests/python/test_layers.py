"""`lacuna slice` against PrusaSlicer: the PNG layers of the hollow sphere, read with PIL, against the
layers PrusaSlicer itself rasterizes from Lacuna's own STL of it (`prusa-slicer --export-sla`,
supports and pad off), layer by layer: the areas agree within a tenth of PrusaSlicer's pixel along
the boundary. The CLI file's contours read back to the report's areas."""

import io
import json
import math
import shutil
import subprocess
import zipfile

import numpy as np
import pytest

from conftest import BINARY, SOURCE_DIR

PIL = pytest.importorskip("PIL.Image")


def run_recipe(recipe, out):
    # The plain surface (not simplified): what is compared is slicing, and a compact mesh lies up to
    # its deviation from the level set, which near a pole moves a layer's area by 2 pi R times that.
    done = subprocess.run([BINARY, "run", str(recipe), "-o", str(out), "--quiet", "--simplify", "0"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def stl_bottom(path):
    data = path.read_bytes()
    count = int.from_bytes(data[80:84], "little")
    facets = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                           count=count, offset=84)
    return float(facets["v"][:, :, 2].min())


def shell_area(z):
    """The hollow sphere's section at height z (radius 10, wall 1.2): the closed form."""
    return math.pi * (max(0, 100 - z * z) - max(0, 8.8 ** 2 - z * z))


def height_shift(stl, report):
    """PrusaSlicer cuts the mesh (k + 1/2) layers above the mesh's lowest vertex, Lacuna the level set
    above its lowest point. A surface vertex lies at least min_edge_fraction (1 %) of a voxel along its
    edge from a grid point, so where the sphere's pole falls on a grid point the mesh's bottom sits up
    to 0.01 voxel above the level set's: the shift, bounded by that."""
    shift = stl_bottom(stl) - report["z0_mm"]
    assert -1e-6 <= shift <= 0.01 * report["voxel_size_mm"] + 1e-6, shift
    return shift


def slice_json(*args):
    done = subprocess.run([BINARY, "slice", *map(str, args), "--json"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_png_layers_match_prusaslicer(tmp_path):
    if not shutil.which("prusa-slicer"):
        pytest.skip("prusa-slicer is not installed (scripts/setup.sh --test installs it)")
    recipe = SOURCE_DIR / "samples" / "hollow_sphere.json"
    run_recipe(recipe, tmp_path / "run")
    report = slice_json(recipe, "-o", tmp_path / "layers.zip", "--layer-mm", 0.2, "--pixel-mm", 0.05)
    archive = zipfile.ZipFile(tmp_path / "layers.zip")
    manifest = json.loads(archive.read("manifest.json"))
    assert manifest["layers"] == report["layer_count"] == len(report["layers"])
    ours = []
    for name, layer in zip(manifest["files"], report["layers"]):
        image = np.asarray(PIL.open(io.BytesIO(archive.read(name))))
        assert image.shape == (report["height"], report["width"])
        ours.append(image.sum(dtype=np.int64) / 255 * 0.05 ** 2)
        assert ours[-1] == pytest.approx(layer["image_area_mm2"], abs=1e-9)

    sla = tmp_path / "prusa.sl1"
    done = subprocess.run(["prusa-slicer", "--export-sla", "--no-supports-enable", "--no-pad-enable",
                           "--layer-height", "0.2", "--initial-layer-height", "0.2",
                           str(tmp_path / "run" / "hollow_sphere.stl"), "-o", str(sla)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    theirs_zip = zipfile.ZipFile(sla)
    config = dict(line.split(" = ", 1) for line in theirs_zip.read("prusaslicer.ini").decode().splitlines()
                  if " = " in line)
    pixel_x = float(config["display_width"]) / float(config["display_pixels_x"])
    pixel_y = float(config["display_height"]) / float(config["display_pixels_y"])
    theirs = [np.asarray(PIL.open(io.BytesIO(theirs_zip.read(n)))).sum(dtype=np.int64) / 255 * pixel_x * pixel_y
              for n in sorted(n for n in theirs_zip.namelist() if n.endswith(".png"))]
    # PrusaSlicer cuts layer k at the same height, (k + 1/2) layers above the part's bottom; it
    # leaves out a top layer whose centre is within the last layer height.
    assert len(theirs) in (len(ours), len(ours) - 1)
    shift = height_shift(tmp_path / "run" / "hollow_sphere.stl", report)
    for k in range(len(theirs)):
        boundary = report["layers"][k]["contour_length_mm"]
        # PrusaSlicer's layer k lies `shift` higher: ours corrected by the closed form's change there.
        z = report["layers"][k]["z_mm"]
        moved = ours[k] + shell_area(z + shift) - shell_area(z)
        assert abs(moved - theirs[k]) <= 0.1 * max(pixel_x, pixel_y) * boundary + 4 * pixel_x * pixel_y, k
        # Both against the closed form of the shell (radius 10, wall 1.2) within the meshes' and
        # level set's resolution (the recipe's voxel, 0.2 mm, along the boundary).
        assert abs(ours[k] - shell_area(z)) <= 0.2 * boundary, k


def test_cli_contours_read_back(tmp_path):
    recipe = SOURCE_DIR / "samples" / "hollow_sphere.json"
    report = slice_json(recipe, "-o", tmp_path / "part.cli", "--layer-mm", 0.5)
    layers, tops = [], []
    for line in (tmp_path / "part.cli").read_text().splitlines():
        if line.startswith("$$LAYER/"):
            tops.append(float(line[8:]))
            layers.append(0.0)
        elif line.startswith("$$POLYLINE/"):
            values = [float(v) for v in line[11:].split(",")]
            n = int(values[2])
            xs, ys = values[3::2][:n], values[4::2][:n]
            assert (xs[0], ys[0]) == (xs[-1], ys[-1])
            area = sum(xs[i] * ys[i + 1] - xs[i + 1] * ys[i] for i in range(n - 1)) / 2
            assert int(values[1]) == (1 if area > 0 else 0)  # outer counter-clockwise, holes clockwise
            layers[-1] += area
    assert len(layers) == report["layer_count"]
    assert tops == pytest.approx([0.5 * (k + 1) for k in range(len(layers))], abs=1e-6)
    for area, layer in zip(layers, report["layers"]):
        # Simplified by a quarter pixel (the voxel): within that along the boundary.
        assert area == pytest.approx(layer["contour_area_mm2"], abs=0.25 * 0.2 * layer["contour_length_mm"])


def ini(text):
    return [(line.split("=", 1)[0].strip(), line.split("=", 1)[1].strip()) for line in text.splitlines() if "=" in line]


def test_sl1_archive_matches_prusaslicer(tmp_path):
    """An SL1 archive against the one PrusaSlicer exports from Lacuna's STL of the same part: the same
    files, the same keys in the same order with the same settings, and layer by layer the same image
    (same size, the part in the same place, pixel sums within a tenth of a pixel along the boundary)."""
    if not shutil.which("prusa-slicer"):
        pytest.skip("prusa-slicer is not installed (scripts/setup.sh --test installs it)")
    recipe = SOURCE_DIR / "samples" / "hollow_sphere.json"
    run_recipe(recipe, tmp_path / "run")
    report = slice_json(recipe, "-o", tmp_path / "ours.sl1", "--layer-mm", 0.2)
    done = subprocess.run(["prusa-slicer", "--export-sla", "--no-supports-enable", "--no-pad-enable",
                           "--layer-height", "0.2", "--initial-layer-height", "0.2",
                           str(tmp_path / "run" / "hollow_sphere.stl"), "-o", str(tmp_path / "theirs.sl1")],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    ours, theirs = zipfile.ZipFile(tmp_path / "ours.sl1"), zipfile.ZipFile(tmp_path / "theirs.sl1")
    # prusaslicer.ini: every key, in order, with the same value.
    assert ini(ours.read("prusaslicer.ini").decode()) == ini(theirs.read("prusaslicer.ini").decode())
    # config.ini: the same keys in order; the values the settings decide are equal.
    a, b = dict(ini(ours.read("config.ini").decode())), dict(ini(theirs.read("config.ini").decode()))
    assert [k for k, _ in ini(ours.read("config.ini").decode())] == [k for k, _ in ini(theirs.read("config.ini").decode())]
    for key in ("action", "expTime", "expTimeFirst", "expUserProfile", "hollow", "layerHeight", "materialName",
                "numFade", "numSlow", "printProfile", "printerModel", "printerProfile", "printerVariant"):
        assert a[key] == b[key], key
    # PrusaSlicer leaves out the top layer (its centre within a layer of the top); Lacuna keeps it.
    ours_layers = sorted(n for n in ours.namelist() if n.endswith(".png"))
    theirs_layers = sorted(n for n in theirs.namelist() if n.endswith(".png"))
    assert int(a["numFast"]) == len(ours_layers) == report["layer_count"]
    assert int(b["numFast"]) == len(theirs_layers) == len(ours_layers) - 1
    # Resin: the layers' areas times their height, so within what the dropped layer holds.
    top = report["layers"][-1]["image_area_mm2"] * 0.2 / 1000
    assert float(a["usedMaterial"]) - float(b["usedMaterial"]) == pytest.approx(top, rel=0.05, abs=2e-4)
    assert float(a["printTime"]) == pytest.approx(float(b["printTime"]), rel=0.03)
    step_x, step_y = 68 / 1440, 120 / 2560  # PrusaSlicer 2.5's pixel steps along the image's rows and columns
    shift = height_shift(tmp_path / "run" / "hollow_sphere.stl", report)
    for k, (mine, its) in enumerate(zip(ours_layers, theirs_layers)):
        x = np.asarray(PIL.open(io.BytesIO(ours.read(mine)))).astype(np.int32)
        y = np.asarray(PIL.open(io.BytesIO(theirs.read(its)))).astype(np.int32)
        assert x.shape == y.shape == (2560, 1440)
        boundary = report["layers"][k]["contour_length_mm"]
        z = report["layers"][k]["z_mm"]
        difference = abs(x.sum() / 255 * step_x * step_y + shell_area(z + shift) - shell_area(z)
                         - y.sum() / 255 * step_x * step_y)
        assert difference <= 0.1 * step_x * boundary + 4 * step_x * step_y, k
        # The part in the same place: pixels that disagree (one solid, the other empty) are few, along
        # the boundary only.
        disagree = int((np.abs(x - y) > 128).sum())
        assert disagree <= 0.25 * boundary / step_y + 4, (k, disagree)


def test_python_slice_is_the_command_lines(tmp_path):
    """lacuna.slice on a recipe dict: the same bytes as `lacuna slice`, slab by slab too, and the report."""
    import lacuna

    recipe = json.loads((SOURCE_DIR / "samples" / "hollow_sphere.json").read_text())
    (tmp_path / "r.json").write_text(json.dumps(recipe))
    report = slice_json(tmp_path / "r.json", "-o", tmp_path / "cli.cli", "--layer-mm", 0.4, "--binary")
    mine = lacuna.slice(recipe, tmp_path / "py.cli", layer_mm=0.4, binary=True)
    assert (tmp_path / "py.cli").read_bytes() == (tmp_path / "cli.cli").read_bytes()
    assert mine["layer_count"] == report["layer_count"] == 50 and mine["valid"] and mine["slabs"] == 1
    slabs = lacuna.slice(recipe, tmp_path / "slabs.cli", layer_mm=0.4, binary=True, slab_mm=4)
    assert slabs["slabs"] >= 4 and slabs["halo_mm"] > 0
    assert (tmp_path / "slabs.cli").read_bytes() == (tmp_path / "cli.cli").read_bytes()
    with pytest.raises(ValueError, match="layer_mm"):
        lacuna.slice(recipe, tmp_path / "bad.cli", layer_mm=-1)
    assert not (tmp_path / "bad.cli").exists()
