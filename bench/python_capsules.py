#!/usr/bin/env python3
"""The Python module's costs, measured (figures quoted in README.md, Benchmarks):

1. N capsules (a persistent random walk as in capsules_bench.cpp: step 0.5 mm, radius 0.5 mm, reflected
   inside a cube of 20 (N / 1000)^(1/3) mm, so the density stays constant; voxel radius / 6) passed from
   numpy, lacuna.tubes(points, radius).voxelize(), against the recipe path, lacuna.voxelize(recipe file):
   the same grid (active voxels, and the distance at 100 000 points, bit for bit) and the ratio of the
   times (median of the runs, alternated).
2. A mesh of about 1 M triangles (a 10 mm ball at 0.1 mm, not simplified) handed to numpy: the peak
   memory of the mesh() call (VmHWM, reset before it), the mesh's own size, and what taking its
   vertices and faces as arrays adds (nothing: they view the mesh).

    PYTHONPATH=build/python /usr/bin/python3 bench/python_capsules.py [--count 10000] [--runs 5]
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import lacuna


def random_walk(count, step, box, seed):
    rng = np.random.default_rng(seed)
    p, d = np.zeros(3), np.array([1.0, 0.0, 0.0])
    points = np.empty((count + 1, 3))
    points[0] = p
    half = 0.5 * box
    jitter = rng.uniform(-0.6, 0.6, size=(count, 3))
    for i in range(count):
        d = d + jitter[i]
        d /= np.linalg.norm(d)
        q = p + d * step
        for k in range(3):
            if abs(q[k]) > half:
                d[k] = -d[k]
                q[k] = p[k] + d[k] * step
        p = q
        points[i + 1] = p
    return points


def status_kib(field):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise KeyError(field)


def reset_peak():
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")


def capsules(count, runs):
    radius, step = 0.5, 0.5
    box = 20.0 * (count / 1000.0) ** (1.0 / 3.0)
    voxel = radius / 6
    points = random_walk(count, step, box, seed=7)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "walk.json")
        recipe = {"voxel_size_mm": voxel,
                  "inputs": {"walk": {"type": "tubes", "polylines": [{"points_mm": points.tolist(),
                                                                       "radius_mm": radius}]}},
                  "outputs": [{"of": "walk", "file": "walk.stl"}]}
        with open(path, "w") as f:
            json.dump(recipe, f)
        recipe_s, numpy_s = [], []
        for _ in range(runs):
            t = time.perf_counter()
            from_recipe = lacuna.voxelize(path)
            recipe_s.append(time.perf_counter() - t)
            t = time.perf_counter()
            from_numpy = lacuna.tubes(points, radius).voxelize(voxel_size_mm=voxel)
            numpy_s.append(time.perf_counter() - t)
        probes = np.random.default_rng(1).uniform(-box / 2, box / 2, size=(100_000, 3))
        same = (from_recipe.active_voxels == from_numpy.active_voxels and
                np.array_equal(from_recipe.distance(probes), from_numpy.distance(probes)))
    return {"capsules": count, "box_mm": box, "voxel_size_mm": voxel, "active_voxels": from_numpy.active_voxels,
            "same_grid": bool(same), "recipe_seconds": recipe_s, "numpy_seconds": numpy_s,
            "recipe_median_s": statistics.median(recipe_s), "numpy_median_s": statistics.median(numpy_s),
            "numpy_over_recipe": statistics.median(numpy_s) / statistics.median(recipe_s)}


def mesh_memory():
    solid = lacuna.sphere(radius_mm=10)
    before = status_kib("VmRSS")
    reset_peak()
    t = time.perf_counter()
    mesh = solid.mesh(voxel_size_mm=0.1, simplify_mm=0)
    seconds = time.perf_counter() - t
    peak = status_kib("VmHWM")
    after_call = status_kib("VmRSS")
    vertices, faces = mesh.vertices, mesh.faces
    after_arrays = status_kib("VmRSS")
    mesh_bytes = vertices.nbytes + faces.nbytes
    copied = np.array(vertices), np.array(faces)  # what a second copy would cost, for comparison
    after_copy = status_kib("VmRSS")
    del copied
    return {"triangles": int(len(faces)), "vertices": int(len(vertices)), "mesh_seconds": seconds,
            "mesh_mb": mesh_bytes / 1e6, "rss_before_call_mb": before * 1024 / 1e6,
            "peak_during_call_mb": peak * 1024 / 1e6, "rss_after_call_mb": after_call * 1024 / 1e6,
            "arrays_added_mb": (after_arrays - after_call) * 1024 / 1e6,
            "a_copy_would_add_mb": (after_copy - after_arrays) * 1024 / 1e6,
            "views_share_memory": bool(np.shares_memory(vertices, mesh.vertices))}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--count", type=int, default=10_000)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--part", choices=["all", "capsules", "memory"], default="all")
    args = parser.parse_args()
    if args.part == "all":
        # Each part in its own process, so the peak memory is that part's.
        for part in ("capsules", "memory"):
            subprocess.run([sys.executable, __file__, "--part", part, "--count", str(args.count), "--runs",
                            str(args.runs)], check=True)
        return
    result = capsules(args.count, args.runs) if args.part == "capsules" else mesh_memory()
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
