"""Every input constructor and operator against the closed forms the C++ tests use (tests/solids_test.cpp,
tests/cifs_solids_test.cpp): volumes within 0.5 % (1 % where the C++ tests allow it), genus and components."""

import math

import numpy as np
import pytest

import lacuna


def ball(r):
    return 4.0 / 3.0 * math.pi * r**3


def near(value, exact, relative):
    assert abs(value - exact) <= relative * abs(exact), (value, exact)


def test_sphere_volume_area_genus():
    m = lacuna.sphere(center_mm=[0.3, -0.2, 0.1], radius_mm=3).mesh(voxel_size_mm=0.1)
    near(m.volume_mm3, ball(3), 0.005)
    near(m.area_mm2, 4 * math.pi * 9, 0.01)
    assert m.genus == 0 and m.components == 1
    assert m.volume == m.volume_mm3 and m.area == m.area_mm2


def test_spheres_from_numpy_are_two_components():
    centers = np.array([[0.0, 0, 0], [6.0, 0, 0]])
    m = lacuna.spheres(centers, 2.0).mesh(voxel_size_mm=0.1)
    assert m.components == 2 and m.genus == 0
    near(m.volume_mm3, 2 * ball(2), 0.005)
    radii = lacuna.spheres(centers, np.array([2.0, 1.0])).mesh(voxel_size_mm=0.1)
    near(radii.volume_mm3, ball(2) + ball(1), 0.005)


def test_capsule_matches_closed_form():
    length = 6.0
    m = lacuna.capsule(a_mm=[0, 0, 0], b_mm=[length, 0, 0], radius_mm=1.5).mesh(voxel_size_mm=0.05)
    near(m.volume_mm3, math.pi * 1.5**2 * length + ball(1.5), 0.005)
    assert m.genus == 0


def test_tubes_from_numpy_closed_chain_is_a_torus():
    # A closed polygon of 24 capsules around a circle: one solid torus.
    phi = np.linspace(0, 2 * np.pi, 25)
    points = np.stack([6 * np.cos(phi), 6 * np.sin(phi), np.zeros_like(phi)], axis=1)
    m = lacuna.tubes(points, 1.0).mesh(voxel_size_mm=0.1)
    assert m.genus == 1 and m.components == 1
    chord = 2 * 6 * math.sin(math.pi / 24)
    # 24 cylinders plus the joints: between the torus and the capsules' sum.
    assert 24 * math.pi * chord * 0.9 < m.volume_mm3 < 24 * (math.pi * chord + ball(1))


def test_tubes_shapes_and_per_point_radii():
    two = np.array([[[0, 0, 0], [4, 0, 0]], [[0, 5, 0], [4, 5, 0]]], dtype=float)
    m = lacuna.tubes(two, 1.0).mesh(voxel_size_mm=0.1)
    near(m.volume_mm3, 2 * (math.pi * 4 + ball(1)), 0.005)
    assert m.components == 2
    listed = lacuna.tubes([two[0], two[1]], [1.0, 1.0]).mesh(voxel_size_mm=0.1)
    near(listed.volume_mm3, m.volume_mm3, 1e-9)
    # One radius per point equal everywhere: the same capsule.
    per_point = lacuna.tubes(two[0], np.array([1.0, 1.0])).mesh(voxel_size_mm=0.1)
    near(per_point.volume_mm3, math.pi * 4 + ball(1), 0.005)
    by_keys = lacuna.tubes(polylines=[{"points_mm": two[0], "radius_mm": 1.0}]).mesh(voxel_size_mm=0.1)
    near(by_keys.volume_mm3, per_point.volume_mm3, 1e-9)


def test_box_cylinder_torus():
    near(lacuna.box(size_mm=[10, 6, 4]).mesh(voxel_size_mm=0.1).volume_mm3, 240, 0.005)
    near(lacuna.box(min_mm=[0, 0, 0], max_mm=[10, 6, 4]).mesh(voxel_size_mm=0.1).volume_mm3, 240, 0.005)
    near(lacuna.cylinder(radius_mm=3, height_mm=10).mesh(voxel_size_mm=0.1).volume_mm3, math.pi * 90, 0.005)
    t = lacuna.torus(major_radius_mm=6, minor_radius_mm=1.5).mesh(voxel_size_mm=0.1)
    assert t.genus == 1
    near(t.volume_mm3, 2 * math.pi**2 * 6 * 1.5**2, 0.005)


def test_region_with_hole_has_genus_one():
    outer = [[0, 0], [8, 0], [8, 8], [0, 8]]
    hole = [[3, 3], [5, 3], [5, 5], [3, 5]]
    m = lacuna.region(loops_mm=[outer, hole], height_mm=1.5).mesh(voxel_size_mm=0.1)
    assert m.genus == 1
    near(m.volume_mm3, 60 * 1.5, 0.01)


def octahedron(r):
    vertices = np.array([[r, 0, 0], [-r, 0, 0], [0, r, 0], [0, -r, 0], [0, 0, r], [0, 0, -r]], dtype=float)
    faces = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return vertices, faces


def test_mesh_from_numpy_and_from_a_mesh():
    vertices, faces = octahedron(4.0)
    exact = 4.0 / 3.0 * 4.0**3
    m = lacuna.mesh(vertices, faces).mesh(voxel_size_mm=0.05)
    near(m.volume_mm3, exact, 0.005)
    again = lacuna.mesh(lacuna.Mesh(vertices, faces), translate_mm=[10, 0, 0]).mesh(voxel_size_mm=0.05)
    near(again.volume_mm3, exact, 0.005)
    assert again.bounding_box[0][0] > 5


def test_surface_thickened_square_plate():
    a, t = 6.0, 0.5
    vertices = np.array([[0, 0, 0], [a, 0, 0], [a, a, 0], [0, a, 0]], dtype=float)
    m = lacuna.surface(vertices, np.array([[0, 1, 2], [0, 2, 3]]), thickness_mm=2 * t).mesh(voxel_size_mm=0.1)
    # The plate thickened by t on each side: slab, quarter-cylinders along the four edges, corner spheres.
    exact = a * a * 2 * t + 4 * a * math.pi * t * t / 2 + ball(t)
    near(m.volume_mm3, exact, 0.01)


def test_menger_sponge_level_two_has_genus_81():
    side, h = 27.0, 1.0 / 3.0
    system = {"library": "menger_sponge", "scale": side, "translate_mm": [h / 2] * 3}
    m = lacuna.cifs(system=system, level=2).mesh(voxel_size_mm=h, simplify_mm=0)
    assert m.genus == 81 and m.components == 1
    near(m.volume_mm3, side**3 * (20 / 27) ** 2, 0.005)


def test_lattice_cubic_cell_count():
    # A cubic lattice of 2 x 1 x 1 cells: 12 + 4 + 4 = 20 struts... its genus is that of the cell graph:
    # edges - vertices + 1 = 20 - 12 + 1 = 9.
    m = lacuna.lattice(cell="cubic", period_mm=4, strut_radius_mm=0.4, min_mm=[0, 0, 0], max_mm=[8, 4, 4]).mesh(
        voxel_size_mm=0.1)
    assert m.components == 1 and m.genus == 20 - 12 + 1


def test_curve_planar_hilbert_is_one_tube():
    m = lacuna.curve(kind="hilbert", orders=[2], radius_mm=0.3, scale_mm=5).mesh(voxel_size_mm=0.1)
    assert m.components == 1 and m.genus == 0


def test_fill_motifs_circles_cut_from_a_plate():
    holes = lacuna.fill_motifs(motif="circle", region={"rectangle": {"min_mm": [0, 0], "max_mm": [20, 20]}},
                               count=10, c=1.3, height_mm=3, base_z_mm=-1, gap_mm=0.5, boundary_gap_mm=0.5)
    plate = lacuna.box(min_mm=[0, 0, 0], max_mm=[20, 20, 1]) - holes
    m = plate.mesh(voxel_size_mm=0.1)
    assert m.components == 1 and m.genus == 10


def test_fill_spheres_volume_is_the_fill_fraction(tmp_path):
    pores = lacuna.fill_spheres(box={"min_mm": [0, 0, 0], "max_mm": [10, 10, 10]}, count=20, c=1.2, gap_mm=0.3,
                                seed=3)
    result = lacuna.run(pores.to_recipe(name="pores", voxel_size_mm=0.08), output_dir=tmp_path / "out")
    report = result.report
    placed = report["inputs"][pores.name]
    m = result.meshes["pores.stl"]
    assert m.components == placed["spheres"]
    assert result.files[-1] == str(tmp_path / "out" / "report.json")
    near(m.volume_mm3, placed["fill_fraction"] * 1000, 0.02)


def test_voronoi_tiles_fill_the_period():
    keys = dict(dimension=3, d=2, points=[[0.1, 0.2, 0.3], [0.6, 0.7, 0.2]], level=1, period_mm=8)
    tiles = lacuna.voronoi_tiles(colours=[1], **keys).mesh(voxel_size_mm=0.1)
    other = lacuna.voronoi_tiles(colours=[2], **keys).mesh(voxel_size_mm=0.1)
    near(tiles.volume_mm3 + other.volume_mm3, 8**3, 0.01)


def test_voronoi_spheres_count():
    m = lacuna.voronoi_spheres(dimension=3, d=2, points=[[0.25, 0.25, 0.25]], level=1, period_mm=8,
                               radius_mm=1.5).mesh(voxel_size_mm=0.1)
    # Level 1 of one starting point with d = 2: 8 generators, 4 mm apart, radius 1.5: 8 balls.
    assert m.components == 8
    near(m.volume_mm3, 8 * ball(1.5), 0.005)


def test_voronoi_foam_is_walls():
    foam = lacuna.voronoi_foam(dimension=3, d=2, points=[[0.1, 0.2, 0.3], [0.6, 0.7, 0.2]], level=1, period_mm=8,
                               wall_mm=0.4)
    m = (foam & lacuna.box(min_mm=[0.5, 0.5, 0.5], max_mm=[7.5, 7.5, 7.5])).mesh(voxel_size_mm=0.1)
    assert m.components >= 1 and m.volume_mm3 > 0


def test_voronoi_foam_refined_where_the_field_asks():
    # A field that never passes the threshold leaves the two fractal cells whole: the walls of level 1 + 2, the
    # same mesh as the plain foam of level 3. A field that refines everywhere adds the walls between the tiles.
    keys = dict(dimension=3, d=2, points=[[0.1, 0.2, 0.3], [0.6, 0.7, 0.2]], period_mm=8, wall_mm=0.4)
    box = lacuna.box(min_mm=[0.5, 0.5, 0.5], max_mm=[7.5, 7.5, 7.5])
    plain = (lacuna.voronoi_foam(level=3, **keys) & box).mesh(voxel_size_mm=0.2)
    never = dict(field="ramp", axis=[1, 0, 0], from_mm=100, to_mm=200, levels=2)
    same = (lacuna.voronoi_foam(level=1, refine=never, **keys) & box).mesh(voxel_size_mm=0.2)
    assert len(same.faces) == len(plain.faces) and same.volume_mm3 == plain.volume_mm3
    always = dict(field="ramp", axis=[1, 0, 0], from_mm=-200, to_mm=-100, levels=2)
    dense = (lacuna.voronoi_foam(level=1, refine=always, **keys) & box).mesh(voxel_size_mm=0.2)
    assert dense.volume_mm3 > 1.5 * plain.volume_mm3
    with pytest.raises(ValueError, match="refine"):
        lacuna.voronoi_foam(level=1, refine=dict(field="depth", depth_mm=1), **keys)


def test_bcifs_plate_and_cell():
    # The plate is its level's region (what bcifs_measure measures) extruded by its thickness.
    plate = lacuna.bcifs_plate(face={"boundary": "C2 B2 C2 B2 C2 B2"}, radius_mm=6, level=1, thickness_mm=1)
    m = plate.mesh(voxel_size_mm=0.1)
    measured = lacuna.bcifs_measure(face={"boundary": "C2 B2 C2 B2 C2 B2"}, radius_mm=6, levels=(1, 1))
    near(m.volume_mm3, measured["area_mm2"][0] * 1.0, 0.01)
    cell = lacuna.bcifs_cell(cell="hexahedron", edge_mm=8, thickness_mm=1, level=1).mesh(voxel_size_mm=0.12)
    assert cell.components == 1 and cell.volume_mm3 > 0
    # The "paper" realization: F0's published F_A 0.76, F_P 1.97 and D_box 1.65 within 3 %.
    paper = lacuna.bcifs_measure(face={"boundary": "C2 B2 C2 B2 C2 B2"}, radius_mm=6, levels=(0, 5),
                                 realization="paper")
    near(paper["F_A"], 0.76, 0.03)
    near(paper["F_P"], 1.97, 0.03)
    near(paper["box_counting"]["region_dimension"], 1.65, 0.03)


def test_bcifs_volume_opens_a_cube_into_a_handlebody():
    # Level 1: six frusta around a cubic lacuna (half the edge), each face's central hole a tunnel into it:
    # a hollow cube with six windows, genus 5. Plain walls seal the lacuna: genus 0, two shells, and the volume
    # is the cube's less the lacuna's, (1 - 0.5^3) of it.
    keys = dict(cell="hexahedron", edge_mm=8, level=1, edge="B2", params="B2 B2 B2", lacuna_scale=0.5)
    opened = lacuna.bcifs_volume(**keys).mesh(voxel_size_mm=0.1)
    assert opened.components == 1 and opened.genus == 5
    sealed = lacuna.bcifs_volume(walls="plain", interior="plain", **keys).mesh(voxel_size_mm=0.1)
    assert sealed.genus == 0 and sealed.components == 2
    near(sealed.volume_mm3, 512 * (1 - 0.125), 0.005)
    assert opened.volume_mm3 < sealed.volume_mm3


def test_cifs_support_stands_the_shell_on_the_plate():
    # A bi-quadratic roof between z = 10 and 16 on its level-2 tree rooted on the plate: one solid reaching
    # z = 0, the same solid as the cifs shell with its "support" key.
    roof = {"nurbs_surface": {"u": {"degree": 2, "knots": [0, 1, 3, 4]}, "v": {"degree": 2, "knots": [0, 1, 2, 3]}},
            "control_points_mm": [[[0, 0, 10], [0, 8, 10], [0, 16, 10]], [[10, 0, 11], [10, 8, 16], [10, 16, 11]],
                                  [[20, 0, 12], [20, 8, 12], [20, 16, 12]]]}
    tree = lacuna.cifs_support(system=roof, level=2, thickness_mm=0.8, base_mm=[10, 8, 0], base_size_mm=3)
    m = tree.mesh(voxel_size_mm=0.2)
    same = lacuna.cifs(system=roof, level=2, thickness_mm=0.8, support={"base_mm": [10, 8, 0], "base_size_mm": 3})
    alone = lacuna.cifs(system=roof, level=2, thickness_mm=0.8).mesh(voxel_size_mm=0.2)
    assert m.components == 1
    assert abs(m.vertices[:, 2].min()) < 0.2 and alone.vertices[:, 2].min() > 9
    near(m.volume_mm3, same.mesh(voxel_size_mm=0.2).volume_mm3, 1e-12)
    assert m.volume_mm3 > alone.volume_mm3


def test_union_difference_intersection_of_spheres():
    a = lacuna.sphere(radius_mm=3)
    b = lacuna.sphere(center_mm=[3.5, 0.4, 0], radius_mm=2)
    d = math.hypot(3.5, 0.4)

    def lens(R, r, dist):
        return math.pi * (R + r - dist) ** 2 * (dist**2 + 2 * dist * r - 3 * r * r + 2 * dist * R + 6 * r * R
                                                 - 3 * R * R) / (12 * dist)

    h = 0.1
    near((a | b).mesh(voxel_size_mm=h).volume_mm3, ball(3) + ball(2) - lens(3, 2, d), 0.005)
    near((a & b).mesh(voxel_size_mm=h).volume_mm3, lens(3, 2, d), 0.01)
    near((a - b).mesh(voxel_size_mm=h).volume_mm3, ball(3) - lens(3, 2, d), 0.005)
    assert (a | b | lacuna.sphere(radius_mm=1, center_mm=[0, 0, 5])).type == "union"


def test_offset_shell_infill():
    ball4 = lacuna.sphere(radius_mm=4)
    near(ball4.offset(1.0).mesh(voxel_size_mm=0.1).volume_mm3, ball(5), 0.005)
    near(ball4.offset(-1.5).mesh(voxel_size_mm=0.1).volume_mm3, ball(2.5), 0.005)
    hollow = ball4.shell(1.2).mesh(voxel_size_mm=0.1)
    near(hollow.volume_mm3, ball(4) - ball(2.8), 0.01)
    assert hollow.components == 2
    # A hull with nothing inside its skin is its shell.
    elsewhere = lacuna.sphere(radius_mm=0.5, center_mm=[20, 0, 0])
    skin = ball4.infill(elsewhere, skin_mm=1.2).mesh(voxel_size_mm=0.1)
    near(skin.volume_mm3, ball(4) - ball(2.8), 0.01)


def test_every_input_type_has_a_constructor():
    for t in lacuna.input_types():
        assert callable(getattr(lacuna, t)), t
    assert lacuna.solid("sphere", radius_mm=1).type == "sphere"


def test_results_do_not_depend_on_threads():
    s = lacuna.tubes(np.array([[0, 0, 0], [3, 1, 0], [4, 4, 1]], dtype=float), 0.7)
    one = s.mesh(voxel_size_mm=0.08, threads=1)
    two = s.mesh(voxel_size_mm=0.08, threads=2)
    assert np.array_equal(one.vertices, two.vertices) and np.array_equal(one.faces, two.faces)


def test_voxelize_without_meshing():
    g = lacuna.sphere(radius_mm=2).voxelize(voxel_size_mm=0.1)
    assert g.active_voxels > 0
    near(g.voxel_volume_mm3, ball(2), 0.02)
    d = g.distance(np.array([[0, 0, 0], [2, 0, 0], [10, 0, 0]], dtype=float))
    assert d[0] < 0 and abs(d[1]) < 0.05 and d[2] > 0
    near(g.mesh().volume_mm3, ball(2), 0.005)
