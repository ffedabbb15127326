"""Meshes and numpy: round trips, views without copies, saving in every format, checks as `lacuna check`."""

import json

import numpy as np
import pytest

import lacuna


def cube(a=2.0):
    v = np.array([[x, y, z] for z in (0, a) for y in (0, a) for x in (0, a)], dtype=float)
    f = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return v, f


def test_arrays_round_trip():
    v, f = cube()
    m = lacuna.Mesh(v, f)
    assert np.array_equal(m.vertices, v) and np.array_equal(m.faces, f)
    assert m.vertices.dtype == np.float64 and m.faces.dtype == np.uint32
    assert m.vertices.shape == (8, 3) and m.faces.shape == (12, 3)
    assert m.volume_mm3 == pytest.approx(8.0, rel=1e-12) and m.area_mm2 == pytest.approx(24.0, rel=1e-12)
    assert m.genus == 0 and m.components == 1
    assert np.array_equal(m.bounding_box, [[0, 0, 0], [2, 2, 2]])
    # Other dtypes and layouts are taken too.
    assert np.array_equal(lacuna.Mesh(v.astype(np.float32), f.astype(np.int16)).faces, f)
    assert np.array_equal(lacuna.Mesh(np.asfortranarray(v), f).vertices, v)


def test_arrays_view_the_mesh_without_copies():
    m = lacuna.sphere(radius_mm=2).mesh(voxel_size_mm=0.2)
    a, b = m.vertices, m.vertices
    assert np.shares_memory(a, b) and np.shares_memory(m.faces, m.faces)
    assert not a.flags.writeable and not m.faces.flags.writeable
    with pytest.raises(ValueError):
        a[0, 0] = 1.0
    # The arrays keep the mesh alive after the Mesh object is gone.
    faces = m.faces
    count = len(faces)
    del m, a, b
    assert len(faces) == count and faces.max() < 10**7


def test_bad_arrays_raise_value_error():
    v, f = cube()
    with pytest.raises(ValueError, match="faces"):
        lacuna.Mesh(v, f + 8)
    with pytest.raises(ValueError, match="vertices"):
        lacuna.Mesh(v[:, :2], f)
    with pytest.raises(ValueError, match="faces"):
        lacuna.Mesh(v, f[:, :2])


def test_save_and_read_back(tmp_path):
    m = lacuna.torus(major_radius_mm=3, minor_radius_mm=1).mesh(voxel_size_mm=0.1)
    for name in ("t.stl", "t.3mf"):
        m.save(tmp_path / name)
        back = lacuna.read_mesh(tmp_path / name)
        assert back.faces.shape == m.faces.shape and back.vertices.shape == m.vertices.shape
        if name.endswith(".3mf"):  # vertices in order, as decimal text
            assert np.allclose(back.vertices, m.vertices, rtol=0, atol=1e-5)
            assert np.array_equal(back.faces, m.faces)
        assert back.volume_mm3 == pytest.approx(m.volume_mm3, rel=1e-6)
        assert back.genus == 1
    with pytest.raises(ValueError, match=r"\.stl"):
        m.save(tmp_path / "t.obj")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.3mf", "t.stl"]


def test_save_draco_within_a_tenth_of_the_voxel(tmp_path):
    m = lacuna.torus(major_radius_mm=3, minor_radius_mm=1).mesh(voxel_size_mm=0.25)
    report = m.save(tmp_path / "t.drc")
    draco = report["draco"]
    assert report["checks"]["valid"] and draco["max_move_mm"] <= 0.025
    assert draco["file_bytes"] == (tmp_path / "t.drc").stat().st_size
    assert draco["binary_stl_bytes"] == 84 + 50 * len(m.faces)
    back = lacuna.read_mesh(tmp_path / "t.drc")
    assert back.faces.shape == m.faces.shape and back.genus == 1
    # Every point of a face moves at most max_move (an affine combination of its corners' moves), so
    # the volume between the two surfaces is at most their area times it.
    area = m.check()["surface_area_mm2"]
    assert abs(back.volume_mm3 - m.volume_mm3) <= area * draco["max_move_mm"]
    # Every decoded vertex lies within the bound of one of the mesh's vertices.
    distances = np.linalg.norm(back.vertices[:, None, :] - m.vertices[None, :, :], axis=2)
    d = distances.min(axis=1)
    assert d.max() <= draco["max_move_mm"]
    # Each mesh vertex has its own decoded vertex, and the mesh's faces on those moved vertices hold
    # the decoded volume: the file keeps the faces, only the positions are quantized.
    match = distances.argmin(axis=0)
    assert len(np.unique(match)) == len(m.vertices)
    moved = back.vertices[match][m.faces]
    volume = np.einsum("ij,ij->i", moved[:, 0], np.cross(moved[:, 1], moved[:, 2])).sum() / 6
    assert volume == pytest.approx(back.volume_mm3, rel=1e-9)
    # A mesh made from arrays has no voxel: the bound must be given.
    v, f = cube()
    with pytest.raises(ValueError, match="quantize_mm"):
        lacuna.Mesh(v, f).save(tmp_path / "c.drc")
    assert lacuna.Mesh(v, f).save(tmp_path / "c.drc", quantize_mm=0.001)["checks"]["valid"]
    with pytest.raises(ValueError, match="quantize_mm only"):
        m.save(tmp_path / "x.drc", quality=2.0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.drc", "t.drc"]


def test_check_is_the_command_line_report(tmp_path, cli):
    m = lacuna.sphere(radius_mm=2).mesh(voxel_size_mm=0.2)
    path = tmp_path / "ball.stl"
    m.save(path)
    code, out, err = cli("check", path, "--json")
    assert code == 0, err
    expected = json.loads(out)
    mine = lacuna.read_mesh(path).check()
    assert mine.pop("valid") is True
    assert mine == expected
    printed = lacuna.read_mesh(path).check(printability=True, min_wall_mm=0.5)
    code, out, err = cli("check", path, "--json", "--print", "--min-wall", 0.5)
    assert printed["printability"] == json.loads(out)["printability"]
    down = lacuna.read_mesh(path).check(printability=True, build_direction=(1, 0, 0), critical_angle_deg=30)
    code, out, err = cli("check", path, "--json", "--print", "--build-dir", "x", "--critical-angle", 30)
    assert down["printability"] == json.loads(out)["printability"]
    with pytest.raises(ValueError, match="build_direction"):
        m.check(printability=True, build_direction=(0, 1))


def test_check_finds_an_open_mesh():
    v, f = cube()
    report = lacuna.Mesh(v, f[:-1]).check()
    assert report["valid"] is False and report["boundary_edges"] == 3


def test_simplify_keeps_a_valid_solid():
    m = lacuna.sphere(radius_mm=3).mesh(voxel_size_mm=0.1, simplify_mm=0)
    s = m.simplify(0.01)
    assert len(s.faces) < len(m.faces)
    assert s.check()["valid"]
    assert s.volume_mm3 == pytest.approx(m.volume_mm3, rel=0.005)
