"""The gallery's figures that are more than a recipe's outputs (samples/gallery/, README "Gallery"): the
density map of the delayed three-face assembly, read back as an image."""

import json
import math

import numpy as np
import pytest


def test_the_delayed_assembly_density_map(cli, source_dir, tmp_path):
    image = pytest.importorskip("PIL.Image")
    recipe = source_dir / "samples" / "lacunar_assembly_plate.json"
    code, out, err = cli("bcifs", "measure", recipe, "--levels", "0..3", "--mask-px", "1", "-o", tmp_path / "m1",
                         "--json")
    assert code == 0, err
    plate = json.loads(out)["plate"]
    # The hexagon F0 splits into 6 at every level; the triangle with a delay of 3 stays one face without
    # lacunas for levels 0 to 2 (it only notches its gaps), then subdivides.
    hexagon, _, triangle = plate["topology"]
    assert hexagon["subfaces"] == [1, 6, 36, 216]
    assert triangle["subfaces"][:3] == [1, 1, 1] and triangle["lacunas"][:3] == [0, 0, 0]
    assert triangle["subfaces"][3] > 1 and triangle["lacunas"][3] > 0
    rgb = np.asarray(image.open(plate["density_map"]).convert("RGB"), dtype=np.int64)
    assert rgb.shape == (1024, 1024, 3)
    # The colour map: (255 f, 0, 255 (1 - f)) for the material fraction f of the window.
    assert (rgb[:, :, 1] == 0).all() and ((rgb[:, :, 0] + rgb[:, :, 2]) == 255).all()
    # A one-pixel window is the mask itself: its set pixels are the boxes of 1/1024 of the box count.
    f = rgb[:, :, 0] / 255.0
    assert set(np.unique(f)) <= {0.0, 1.0}
    assert f.sum() == round(math.exp(plate["box_counting"]["region_log_count"][-1]))
    # A wider window averages the mask: inside the plate's box, where no window is clipped by the image
    # border, the mean of the map is the mean of the mask over the same pixels grown by the window.
    code, out, err = cli("bcifs", "measure", recipe, "--levels", "0..3", "--mask-px", "33", "-o", tmp_path / "m33",
                         "--json")
    assert code == 0, err
    g = np.asarray(image.open(json.loads(out)["plate"]["density_map"]).convert("RGB"), dtype=np.int64)[:, :, 0] / 255.0
    window = np.ones(33) / 33
    smoothed = np.apply_along_axis(lambda r: np.convolve(r, window, mode="same"), 1, f)
    smoothed = np.apply_along_axis(lambda c: np.convolve(c, window, mode="same"), 0, smoothed)
    inner = (slice(16, 1024 - 16), slice(16, 1024 - 16))
    assert np.abs(g[inner] - smoothed[inner]).max() <= 0.5 / 255 + 1e-9
    assert 0.05 < g.mean() < 0.95
