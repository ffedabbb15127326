"""A lacunar panel from a fill pattern: circular holes with p4m symmetry, their areas following the
area rule, drilled through a 30 x 30 x 2 mm plate; the panel is meshed, checked and written as 3MF.

    python3 samples/python/lacunar_panel.py [OUTPUT_DIR]
"""

import json
import pathlib
import sys

import numpy as np

import lacuna

SIDE_MM, THICKNESS_MM, RIM_MM = 30.0, 2.0, 1.0


def polygon_area(points):
    x, y = points[:, 0], points[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def main(out_dir):
    out_dir.mkdir(parents=True, exist_ok=True)
    # The fundamental region of p4m in a 15 mm square cell, filled by the area rule, replicated 2 x 2.
    pattern = lacuna.fill_pattern(group="p4m", lattice=[[15, 0], [0, 15]], c=1.25, N=2, motif="circle", count=15,
                                  gap_mm=0.5, seed=4, cells=2)
    # Every hole whose outline stays a rim away from the plate's edges: each one goes right through.
    holes = [o for o in pattern["pattern"]["outlines"] if o.min() > RIM_MM and o.max() < SIDE_MM - RIM_MM]
    plate = lacuna.box(min_mm=[0, 0, 0], max_mm=[SIDE_MM, SIDE_MM, THICKNESS_MM])
    cutter = lacuna.region(loops_mm=holes, height_mm=THICKNESS_MM + 2, origin_mm=[0, 0, -1])
    panel = (plate - cutter).mesh(voxel_size_mm=0.12)
    check = panel.check()
    panel.save(out_dir / "lacunar_panel.3mf", name="lacunar_panel")
    open_area = sum(polygon_area(h) for h in holes)
    summary = {
        "holes": len(holes),
        "fill_fraction": pattern["fill_fraction"],
        "volume_mm3": panel.volume_mm3,
        "expected_volume_mm3": (SIDE_MM**2 - open_area) * THICKNESS_MM,
        "genus": panel.genus,
        "components": panel.components,
        "triangles": int(len(panel.faces)),
        "valid": check["valid"],
        "file": str(out_dir / "lacunar_panel.3mf"),
    }
    print(json.dumps(summary, indent=1))
    return summary


if __name__ == "__main__":
    main(pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "lacunar_panel-out"))
