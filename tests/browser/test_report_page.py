"""report.html in a real browser (headless Chromium): the page of a run decodes every object's Draco
mesh to the triangle count report.json gives, shows the part (the screenshot's centre is not
background), cuts it with the section plane, makes no request and logs no error."""

import json
import os
import pathlib
import subprocess

import pytest
from PIL import Image

from browser_page import centre_pixels, console_errors, open_page

SOURCE_DIR = pathlib.Path(os.environ.get("LACUNA_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BINARY = os.environ.get("LACUNA_BINARY", str(SOURCE_DIR / "build" / "lacuna"))
BACKGROUND = (0xF4, 0xF5, 0xF7)  # the viewer's background (export/viewer/src/viewer.js)


def run_recipe(recipe, out):
    done = subprocess.run([BINARY, "run", str(recipe), "-o", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout, json.loads((out / "report.json").read_text())


def assert_page_matches_report(result, report):
    assert not result["timed_out"]
    state = result["state"]
    assert state["ready"], state
    assert state["errors"] == []
    assert console_errors(result) == []
    assert result["requests"] == []  # nothing leaves the page
    # Every exported object decoded from its Draco data, with the triangles of its files.
    triangles = {}
    for out in report["outputs"]:
        if "triangles" in out:
            triangles.setdefault(out["object"], set()).add(out["triangles"])
    decoded = {m["object"]: m["triangles"] for m in state["meshes"]}
    assert decoded.keys() == triangles.keys()
    for obj, count in decoded.items():
        assert triangles[obj] == {count}, obj
    return state


def not_background(pixels):
    return sum(1 for p in pixels if max(abs(a - b) for a, b in zip(p, BACKGROUND)) > 24) / len(pixels)


def cap_coloured(pixels):
    return sum(1 for r, g, b in pixels if r > 150 and g < 110 and b < 110) / len(pixels)


def test_hollow_sphere_page(tmp_path):
    recipe = json.loads((SOURCE_DIR / "samples" / "hollow_sphere.json").read_text())
    recipe["printability"] = {"on_failure": "report"}  # the cavity is a trapped void: one marker
    path = tmp_path / "hollow.json"
    path.write_text(json.dumps(recipe))
    stdout, report = run_recipe(path, tmp_path / "out")
    page = tmp_path / "out" / "report.html"
    assert stdout.rstrip().splitlines()[-1].startswith(f"  wrote {tmp_path / 'out' / 'report.html'}")

    result = open_page(page, tmp_path / "whole.png", element="#viewer")
    state = assert_page_matches_report(result, report)
    findings = report["outputs"][0]["printability"]
    assert len(findings["trapped_voids"]) == 1
    assert [m["markers"] for m in state["meshes"]] == [1]
    assert not_background(centre_pixels(result["image"])) > 0.95  # the sphere fills the centre

    # Cut at half height, markers off: the cut shell shows as a ring in the cap colour (the viewer
    # draws back faces so), which the whole part does not show.
    cut = open_page(page, tmp_path / "cut.png", element="#viewer", clicks=["#markers", "#section"])
    assert_page_matches_report(cut, report)
    assert cap_coloured(list(cut["image"].getdata())) > 0.01
    assert cap_coloured(list(result["image"].getdata())) < 0.002


def test_main_sample_page(tmp_path):
    # The quick start's sample: one object in two files, with a sectioned picture.
    _, report = run_recipe(SOURCE_DIR / "samples" / "egg_infill.json", tmp_path / "out")
    result = open_page(tmp_path / "out" / "report.html", tmp_path / "page.png", element="#viewer")
    state = assert_page_matches_report(result, report)
    assert not_background(centre_pixels(result["image"])) > 0.5
    picture = Image.open(tmp_path / "out" / "egg_infill.png")
    assert [(p["width"], p["height"]) for p in state["pictures"]] == [picture.size]


def test_page_is_one_file(tmp_path):
    # The page still works alone: moved away from the files it describes.
    _, report = run_recipe(SOURCE_DIR / "samples" / "hollow_sphere.json", tmp_path / "out")
    alone = tmp_path / "elsewhere" / "page.html"
    alone.parent.mkdir()
    (tmp_path / "out" / "report.html").rename(alone)
    result = open_page(alone, tmp_path / "alone.png", element="#viewer")
    assert_page_matches_report(result, report)


def test_input_figures_page(tmp_path):
    # A lacunar plate's density map and plot, and a wallpaper pattern's SVG, as the browser decodes them.
    recipe = {
        "lacuna_recipe": 1, "name": "figures", "voxel_size_mm": 0.3,
        "inputs": {
            "plate": {"type": "bcifs_plate", "face": {"boundary": "C2 B2 C2 B2 C2 B2"}, "radius_mm": 10, "level": 2},
            "holes": {"type": "fill_motifs", "motif": "circle", "count": 20, "c": 1.15, "N": 2, "min_area_mm2": 0.2,
                      "gap_mm": 0.3, "seed": 7, "height_mm": 2,
                      "wallpaper": {"group": "p4m", "a_mm": [20, 0], "b_mm": [0, 20], "cells": [2, 2],
                                    "policy": "snap"}}},
        "outputs": [{"of": "plate", "file": "plate.stl"}, {"of": "holes", "file": "holes.stl"}],
    }
    path = tmp_path / "figures.json"
    path.write_text(json.dumps(recipe))
    _, report = run_recipe(path, tmp_path / "out")
    result = open_page(tmp_path / "out" / "report.html", tmp_path / "figures.png")
    state = assert_page_matches_report(result, report)
    sizes = {p["caption"].split(":")[0] + (" plot" if "box counting" in p["caption"] else ""): (p["width"], p["height"])
             for p in state["pictures"]}
    assert sizes == {"holes": (800, 800), "plate": (1024, 1024), "plate plot": (1200, 400)}
