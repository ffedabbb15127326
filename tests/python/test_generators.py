"""The generators called directly, against the closed forms of the C++ tests: counts from the definitions,
de Boor's algorithm, hand-worked fill rates and rules, the area law, Perron vectors."""

import math

import numpy as np
import pytest

import lacuna


def test_cifs_tessellations_count_their_pieces():
    for level in range(4):
        t = lacuna.cifs_tessellate("sierpinski_triangle", level=level)
        assert t["pieces"] == 3**level and t["dimension"] == 2
        assert t["triangles"].shape == (3**level, 3)
        assert len(t["points"]) == 3 * (3**level + 1) // 2  # welded corners of the Sierpinski triangle
    sponge = lacuna.cifs_tessellate("menger_sponge", level=1)
    assert sponge["pieces"] == 20 and sponge["cells"].shape == (20, 8) and sponge["points"].shape == (160, 3)
    assert len(sponge["faces"]) == 20 * 6
    koch = lacuna.cifs_tessellate("koch_curve", level=2)
    assert len(koch["polylines"]) == 1 and len(koch["polylines"][0]) == 4**2 + 1
    assert "menger_sponge" in lacuna.cifs_library()
    info = lacuna.cifs_info({"library": "sierpinski_triangle", "scale": 2})
    assert len(info["states"]) == 1 and len(info["transitions"]) == 3


def de_boor(d, t, points, x):
    """The piece with local knots t0 .. t(2d-1) and d + 1 control points at x, by de Boor's algorithm."""
    p = [np.array(q, dtype=float) for q in points]
    for r in range(1, d + 1):
        for j in range(d, r - 1, -1):
            alpha = (x - t[j - 1]) / (t[j + d - r] - t[j - 1])
            p[j] = (1 - alpha) * p[j - 1] + alpha * p[j]
    return p[d]


@pytest.mark.parametrize("degree", [2, 3, 4])
def test_nurbs_tessellation_is_de_boor(degree):
    knots = [0.0]
    for i in range(1, 2 * degree):
        knots.append(knots[-1] + 0.3 + 0.17 * i * i)
    rng = np.random.default_rng(degree)
    control = rng.uniform(-5, 5, size=(degree + 1, 3))
    level = 5
    r = lacuna.nurbs_tessellate(degree, knots, control, level=level)
    assert r["points"].shape == (2**level + 1, 3)
    u = r["parameters"]
    assert u[0] == pytest.approx(knots[degree - 1]) and u[-1] == pytest.approx(knots[degree])
    assert np.all(np.diff(u) > 0)
    for x, p in zip(u, r["points"]):
        assert np.allclose(p, de_boor(degree, knots, control, x), rtol=0, atol=1e-9)
    automaton = lacuna.nurbs_automaton(degree, knots)
    assert len(automaton["states"]) == 4 * (degree - 1)
    assert sum(s["stationary"] for s in automaton["states"]) == 3
    for s in automaton["states"]:
        for t in s["transitions"].values():
            assert np.allclose(t["matrix"].sum(axis=0), 1.0, atol=1e-12)


def test_curve_points_from_the_definition():
    r = lacuna.curve_points(kind="hilbert", orders="1..3")
    assert [c["order"] for c in r["orders"]] == [1, 2, 3]
    for c in r["orders"]:
        assert c["points"].shape == (4 ** c["order"], 3) and not c["closed"]
        assert np.all(np.abs(c["points"][:, :2]) < 1) and np.all(c["points"][:, 2] == 0)
    three = lacuna.curve_points(kind="hilbert3d", orders=[2])
    assert three["orders"][0]["points"].shape == (64, 3)
    sphere = lacuna.curve_points(kind="sierpinski", orders=[2], surface="sphere", tolerance=0.01)
    points = sphere["orders"][0]["points"]
    assert np.allclose(np.linalg.norm(points, axis=1), 1.0, atol=1e-12) and sphere["orders"][0]["closed"]
    with pytest.raises(ValueError, match="surface"):
        lacuna.curve_points(surface="klein_bottle")


def test_fill_rate_of_hilbert_order_one_by_hand():
    # Three 1 x 0.5 strokes with square caps, overlapping at the two bends: union 1.75 of the square's 4.
    f = lacuna.curve_fill_rate(kind="hilbert", orders=[1], width=0.5)
    assert f["fill_rate"] == pytest.approx(1.75 / 4, abs=1e-12)
    assert f["fill_rate_simple"] == pytest.approx(3 * 0.5 / 4, abs=1e-12)
    assert f["segments"] == 3 and f["length"] == pytest.approx(3.0)


def test_surface_fill_rate_on_patches_by_hand():
    # H_1 as round-ended tubes of diameter 0.5. On the plane: 3 x 0.5 less the bends' inner squares,
    # plus their outer quarter disks and the two end half disks, of the square's 4.
    round_ends = 3 * 0.5 - 2 * 0.0625 + 2 * math.pi * 0.0625 / 4 + math.pi * 0.0625
    plane = lacuna.curve_surface_fill_rate(kind="hilbert", orders=[1], width=0.5, samples=2000)
    assert plane["area"] == pytest.approx(4, abs=1e-9)
    assert plane["fill_rate"] == pytest.approx(round_ends / 4, abs=1e-3)
    # The flat 3 x 1 rectangle as a bilinear B-spline patch: the cell centres go to (+-0.75, +-0.25);
    # the middle 1.5 x 1, two half disks on the right, a 0.25 x 0.5 strip and two quarter disks on the left.
    patch = {"degree_u": 1, "degree_v": 1, "count_u": 2, "count_v": 2,
             "control_points_mm": [[-1.5, -0.5, 0], [1.5, -0.5, 0], [-1.5, 0.5, 0], [1.5, 0.5, 0]]}
    r = lacuna.curve_surface_fill_rate(kind="hilbert", orders=[1], width=0.5, surface="bspline", patch=patch,
                                       samples=2000)
    assert r["area"] == pytest.approx(3, abs=1e-5)
    assert r["fill_rate"] == pytest.approx((1.625 + 3 * math.pi / 32) / 3, abs=1e-3)
    # The square as an 8 x 8 mesh: mean-value flattening reproduces linear maps, so the plane's rate.
    g = np.linspace(-1, 1, 9)
    v = np.array([[x, y, 0.0] for y in g for x in g])
    f = []
    for j in range(8):
        for i in range(8):
            a = j * 9 + i
            f += [[a, a + 1, a + 10], [a, a + 10, a + 9]]
    m = lacuna.curve_surface_fill_rate(kind="hilbert", orders=[1], width=0.5, surface="mesh",
                                       mesh=lacuna.Mesh(v, np.array(f)), samples=2000)
    assert m["area"] == pytest.approx(4, abs=1e-5)
    assert m["fill_rate"] == pytest.approx(plane["fill_rate"], abs=1e-5)
    with pytest.raises(lacuna.InvalidInputError, match="patch"):
        lacuna.curve_surface_fill_rate(surface="bspline")
    with pytest.raises(lacuna.InvalidInputError, match="control_points_mm"):
        lacuna.curve_surface_fill_rate(surface="bspline", patch=dict(patch, count_v=3))


def test_fill_pattern_follows_the_area_law():
    c, N = 1.3, 2.0
    r = lacuna.fill_pattern(group="p1", lattice=[[10, 0], [0, 10]], c=c, N=N, count=40, seed=5)
    areas = r["motifs"]["area"]
    k = len(areas)
    assert k == 40 and r["stop_reason"] == "max_count"
    i = np.arange(k)
    assert np.allclose(areas / areas[0], (N / (N + i)) ** c, rtol=1e-12)
    assert areas.sum() / 100.0 == pytest.approx(r["fill_fraction"], rel=1e-12)
    assert r["motifs"]["center"].shape == (k, 2)
    region = r["fundamental_region"]
    x, y = region[:, 0], region[:, 1]
    assert 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) == pytest.approx(100.0)
    # p4m has 8 images of every motif per cell.
    sym = lacuna.fill_pattern(group="p4m", lattice=[[10, 0], [0, 10]], count=15, cells=2, policy="reject")
    placed = len(sym["motifs"]["area"])
    assert len(sym["pattern"]["area"]) == 2 * 2 * 8 * placed
    assert len(sym["pattern"]["outlines"]) == len(sym["pattern"]["area"])
    with pytest.raises(ValueError, match="group"):
        lacuna.fill_pattern(group="p7")


def test_fill_pattern_colours_and_motif_files(tmp_path):
    # Without snapping motif i's size class is floor(c log2((N + i) / N)); every image takes its motif's colour.
    palette = ["#000001", "#000002", "#000003"]
    p = lacuna.fill_pattern(group="p2", c=1.3, N=2.0, count=30, seed=4, cells=2, colors="size", palette=palette)
    n = len(p["colors"])
    assert n == len(p["motifs"]["area"]) and n > 10
    for i, colour in enumerate(p["colors"]):
        assert colour == palette[math.floor(1.3 * math.log2((2 + i) / 2) + 1e-12) % 3]
    assert len(p["pattern_colors"]) == 2 * 4 * n  # p2: two images per motif and cell, 2 x 2 cells
    assert sorted(set(p["pattern_colors"])) == sorted(set(p["colors"]))
    orbit = lacuna.fill_pattern(group="p2", count=30, seed=4, colors="orbit", palette="#ff0000,#00ff00")
    assert orbit["colors"][:4] == ["#ff0000", "#00ff00", "#ff0000", "#00ff00"]
    # A motif from a file: an L-shaped hexagon as an SVG path and as JSON points fill alike.
    (tmp_path / "ell.svg").write_text('<svg><path d="M0,0 h2 v1 h-1 v1 H0 Z"/></svg>')
    (tmp_path / "ell.json").write_text("[[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]")
    a = lacuna.fill_pattern(group="p2", count=20, seed=2, motif=tmp_path / "ell.svg")
    b = lacuna.fill_pattern(group="p2", count=20, seed=2, motif=str(tmp_path / "ell.json"))
    assert len(a["motifs"]["area"]) == len(b["motifs"]["area"])
    with pytest.raises(lacuna.InvalidInputError, match="colors"):
        lacuna.fill_pattern(colors="rainbow")
    with pytest.raises(lacuna.InvalidInputError, match="palette"):
        lacuna.fill_pattern(colors="orbit", palette="#12345")


def test_voronoi_rules_of_the_worked_example():
    example = [[0.86, 0.3], [0.3, 0.65], [0.73, 0.85]]
    r = lacuna.voronoi_rules(dimension=2, d=2, points=example, children="shifted")
    assert np.array_equal(r["matrix"], [[1, 2, 1], [2, 1, 2], [1, 1, 1]])
    assert np.allclose(r["limit_measures"], np.array([7, 8, 5]) / 20, atol=1e-14)
    assert [c["rule"] for c in r["rules"][0]] == [1, 2, 2, 3]
    scaled = lacuna.voronoi_rules(dimension=3, d=2, random=4, seed=2)
    assert np.allclose(scaled["matrix"].sum(axis=0), 8)
    assert scaled["limit_measures"].sum() == pytest.approx(1.0)


def test_voronoi_cells_and_walls():
    one = lacuna.voronoi_cells(points=[[0.5, 0.5]], level=2)
    assert one["measures"] == pytest.approx([1.0]) and one["walls"]["facets"] == 0
    # Two generators on a line: two walls of length 1 (the bisectors x = 1/2 and x = 0).
    two = lacuna.voronoi_cells(points=[[0.25, 0.5], [0.75, 0.5]], level=0)
    assert two["walls"]["facets"] == 2 and two["walls"]["measure"] == pytest.approx(2.0)
    walls = lacuna.voronoi_walls(points=[[0.25, 0.5], [0.75, 0.5]], level=0)
    lengths = [np.linalg.norm(f[1] - f[0]) for f in walls["facets"]]
    assert lengths == pytest.approx([1.0, 1.0]) and walls["colours"].shape == (2, 2)
    three = lacuna.voronoi_cells(dimension=3, random=3, seed=2, level=3)
    assert three["measures"].sum() == pytest.approx(1.0, abs=1e-9)
    with pytest.raises(ValueError, match="give either points or random"):
        lacuna.voronoi_rules()


def test_lacunar_face_rules_and_measures():
    worked = lacuna.bcifs_rules("C4 B2 C2 B2 C3 B2")
    assert worked["lacunas_1"] == 4 and worked["subfaces_1"] == 9
    f0 = lacuna.bcifs_rules("C2 B2 C2 B2 C2 B2", params="C2 B2 B2")
    assert f0["self_reproducing"] == [0] and f0["r_limit"] == pytest.approx(1 / 3, abs=1e-12)
    m = lacuna.bcifs_measure(face={"boundary": "C2 B2 C2 B2 C2 B2"}, radius_mm=8, levels=(0, 3))
    face = m["topology"][0]
    assert list(face["subfaces"]) == [1, 6, 36, 216] and face["lacunas"][1] == 2.5
    assert face["r_limit"] == pytest.approx(1 / 3, abs=1e-12)
    assert m["area_mm2"][0] == pytest.approx(3 * math.sqrt(3) / 2 * 64, rel=1e-12)
    assert np.all(np.diff(m["area_mm2"]) < 0)
    assert m["F_A"] == pytest.approx((m["area_mm2"][-1] / m["area_mm2"][0]) ** (1 / 3), rel=1e-9)
    assert 1 < m["box_counting"]["region_dimension"] <= 2.05
    with pytest.raises(ValueError, match="level"):
        lacuna.bcifs_measure(face={"boundary": "C2 B2 C2 B2 C2 B2"}, radius_mm=8, level=-1)


def test_bcifs_volume_measure_counts_volumes_and_sections():
    # A plain cube: 6^i cells, volumes (1 - 0.5^3)^i of the cube; at level 1 its middle sections are the square less
    # the lacuna's (half the edge) square, sampled at the pixel centres of the grid's square (the cube's side plus
    # sqrt(2)/128 of it each end).
    m = lacuna.bcifs_volume_measure(last=1, cell="hexahedron", edge_mm=10, walls="plain", interior="plain",
                                    lacuna_scale=0.5)
    assert list(m["topology"][0]["cells"]) == [1, 6]
    assert list(m["topology"][0]["lacunas"]) == [0, 1]
    assert abs(m["volume_mm3"][1] - 875) < 1e-9
    assert m["geometry_levels"] == (0, 1)
    side = 10 * (1 + 2 * math.sqrt(2) / 128)
    pixel = side / 1024
    origin = -5 - 10 * math.sqrt(2) / 128

    def centres(lo, hi):
        return sum(1 for i in range(1024) if lo <= origin + (i + 0.5) * pixel <= hi)

    expected = centres(-5, 5) ** 2 - centres(-2.5, 2.5) ** 2
    assert [s["axis"] for s in m["sections"]] == ["x", "y", "z"]
    for s in m["sections"]:
        assert s["mask"].shape == (1024, 1024) and s["mask"].dtype == np.uint8
        assert abs(s["at_mm"]) < 1e-6
        assert int(s["mask"].sum()) == expected
    # The voxel centres inside, times a voxel, are the volume but for voxels within half a diagonal of the surface.
    assert abs(m["box_counting"]["fill"] * side**3 - 875) <= m["surface_mm2"][1] * side / 256 * math.sqrt(3)
    assert 2.5 < m["box_counting"]["region_dimension"] <= 3.0


def test_fill_rate_series_reproduces_the_source_fit():
    # The union rates of H_(1..n), n = 1..5, at width 0.02, fitted as 100 rate = a e^(b n): the source's
    # 0.76 e^(0.89 n) within 2 %; each entry is the fill rate of its superposition.
    s = lacuna.curve_fill_rate_series(kind="hilbert", orders="1..5", width=0.02)
    a, b = s["fit_exact"]
    assert a == pytest.approx(0.76, rel=0.02) and b == pytest.approx(0.89, rel=0.02)
    assert [r["orders"][-1] for r in s["series"]] == [1, 2, 3, 4, 5]
    last = lacuna.curve_fill_rate(kind="hilbert", orders="1..5", width=0.02)
    assert s["series"][-1]["fill_rate"] == last["fill_rate"]
    with pytest.raises(ValueError, match="orders"):
        lacuna.curve_fill_rate_series(orders=[3])
