"""An imported hull filled and checked: the sample egg hull (an STL) scaled up with numpy, given a 1 mm
skin and a body-centred lattice fused inside it, meshed, checked as `lacuna check` would, and saved.

    python3 samples/python/filled_hull.py [OUTPUT_DIR]
"""

import json
import pathlib
import sys

import lacuna

HULL = pathlib.Path(__file__).resolve().parents[1] / "meshes" / "egg_hull.stl"


def main(out_dir):
    out_dir.mkdir(parents=True, exist_ok=True)
    egg = lacuna.read_mesh(HULL)
    # The hull 1.25 times larger, about its base: plain numpy on the mesh's vertices.
    vertices = egg.vertices * 1.25
    hull = lacuna.mesh(vertices, egg.faces)
    lattice = lacuna.lattice(cell="bcc", period_mm=5, strut_radius_mm=0.5, fit_to=hull, layout="conforming", inset_mm=1.0)
    part = hull.infill(lattice, skin_mm=1.0)
    mesh = part.mesh(voxel_size_mm=0.15)
    check = mesh.check()
    mesh.save(out_dir / "filled_hull.stl")
    hull_volume = lacuna.Mesh(vertices, egg.faces).volume_mm3
    summary = {
        "valid": check["valid"],
        "problems": check["checks"]["problems"],
        "components": mesh.components,
        "sealed_pockets": mesh.components - 1,  # inward shells: cavities the lattice closes off inside the skin
        "genus": mesh.genus,
        "volume_mm3": mesh.volume_mm3,
        "hull_volume_mm3": hull_volume,
        "relative_density": mesh.volume_mm3 / hull_volume,
        "triangles": int(len(mesh.faces)),
        "file": str(out_dir / "filled_hull.stl"),
    }
    print(json.dumps(summary, indent=1))
    return summary


if __name__ == "__main__":
    main(pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "filled_hull-out"))
