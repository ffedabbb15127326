"""`mpirun -np 2 lacuna slice` on one machine: the ranks split the slabs, rank 0 gathers the layers
and writes; the files are the same bytes as one process's, and a rank that fails ends the job with
its message and nothing on disk. Skipped where mpirun is missing or lacuna was built without MPI."""

import json
import os
import shutil
import subprocess

import pytest

from conftest import BINARY, SOURCE_DIR

MPIRUN = shutil.which("mpirun")


def with_mpi():
    if not MPIRUN:
        pytest.skip("mpirun is not installed (scripts/setup.sh installs openmpi-bin)")
    version = subprocess.run([BINARY, "--version"], capture_output=True, text=True).stdout
    if "MPI" not in version:
        pytest.skip("this lacuna was built without MPI")


def mpirun(ranks, command):
    """`command` (a list) run as `ranks` ranks of one job, one thread each."""
    launcher = [MPIRUN, "-np", str(ranks), "--oversubscribe"]
    if os.geteuid() == 0:
        launcher.append("--allow-run-as-root")
    return subprocess.run(launcher + command, capture_output=True, text=True, timeout=600)


def files_of(path):
    if path.is_dir():
        return {p.name: p.read_bytes() for p in sorted(path.iterdir())}
    return {path.name: path.read_bytes()}


CASES = [
    # An imported hull filled with a lattice (a mesh clipped per slab, an infill's skin), as images.
    ("egg_infill.json", ["--voxel-size", "0.3"], "egg.zip"),
    # A shell (an inward offset), as CLI contours gathered from both ranks.
    ("hollow_sphere.json", [], "sphere.cli"),
    # A streamed CIFS input, as a folder of PNGs, and as an SL1 archive.
    ("menger_sponge.json", [], "sponge"),
    ("menger_sponge.json", [], "sponge.sl1"),
]


@pytest.mark.parametrize("recipe,extra,name", CASES)
def test_two_ranks_write_one_process_bytes(tmp_path, recipe, extra, name):
    with_mpi()
    path = SOURCE_DIR / "samples" / recipe
    alone = subprocess.run([BINARY, "slice", str(path), "-o", str(tmp_path / ("alone-" + name)), "--quiet", *extra],
                           capture_output=True, text=True)
    assert alone.returncode == 0, alone.stderr
    job = mpirun(2, [BINARY, "slice", str(path), "-o", str(tmp_path / ("ranks-" + name)), "--json", "--threads", "1", *extra])
    assert job.returncode == 0, job.stderr
    report = json.loads(job.stdout)  # rank 0 alone prints
    assert report["valid"] and report["slabs"] >= 2
    mine, theirs = files_of(tmp_path / ("alone-" + name)), files_of(tmp_path / ("ranks-" + name))
    assert len(mine) == len(theirs) and len(mine) >= 1
    for (a, bytes_a), (b, bytes_b) in zip(sorted(mine.items()), sorted(theirs.items())):
        assert a.replace("alone-", "") == b.replace("ranks-", "")
        assert bytes_a == bytes_b, a
    # Nothing else beside them: the ranks' spooled images are gone.
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["alone-" + name, "ranks-" + name])


def test_a_rank_that_dies_ends_the_job_and_leaves_nothing(tmp_path):
    with_mpi()
    recipe = SOURCE_DIR / "samples" / "menger_sponge.json"
    out = tmp_path / "layers.zip"
    # Rank 1 is interrupted a second into a job of some twenty seconds: it removes what it started and
    # dies; mpirun ends the others, which remove theirs (the output was never made).
    script = ('if [ "$OMPI_COMM_WORLD_RANK" = 1 ]; then (sleep 1; kill -INT $$) & fi; '
              f'exec "{BINARY}" slice "{recipe}" -o "{out}" --voxel-size 0.0370370370370 --threads 1')
    job = mpirun(2, ["sh", "-c", script])
    assert job.returncode != 0, job.stderr
    assert "interrupted" in job.stderr
    assert list(tmp_path.iterdir()) == []


def stl_only(tmp_path, recipe):
    """The sample's recipe with its first STL output alone (what a streamed run writes), its imported
    meshes named by absolute path, written beside the test's files."""
    path = SOURCE_DIR / "samples" / recipe
    data = json.loads(path.read_text())
    data["outputs"] = [o for o in data["outputs"] if o["file"].endswith(".stl")][:1]
    for key in ("render", "layers", "fea"):
        data["outputs"][0].pop(key, None)
    data.pop("printability", None)
    for spec in data["inputs"].values():
        if spec.get("type") == "mesh":
            spec["file"] = str(path.parent / spec["file"])
    out = tmp_path / ("stl-" + recipe)
    out.write_text(json.dumps(data))
    return out, data["outputs"][0]["file"]


STREAM_CASES = [
    # A shell (an inward offset) over three ranks: the last one's lead-in spans two slabs.
    ("hollow_sphere.json", 3, ["--slab-mm", "1"]),
    # An imported hull's lattice: cavities below a voxel filled across the ranks' parts.
    ("egg_infill.json", 2, []),
    # A streamed CIFS input, four slabs.
    ("menger_sponge.json", 2, ["--slab-mm", "1"]),
]


@pytest.mark.parametrize("recipe,ranks,extra", STREAM_CASES)
def test_ranks_stream_one_process_mesh(tmp_path, recipe, ranks, extra):
    with_mpi()
    path, name = stl_only(tmp_path, recipe)
    alone = subprocess.run([BINARY, "run", str(path), "--stream", "-o", str(tmp_path / "alone"), "--json"],
                           capture_output=True, text=True)
    assert alone.returncode == 0, alone.stderr
    job = mpirun(ranks, [BINARY, "run", str(path), "--stream", "-o", str(tmp_path / "ranks"), "--json",
                         "--threads", "1", *extra])
    assert job.returncode == 0, job.stderr
    report = json.loads(job.stdout)  # rank 0 alone prints
    out, single = report["outputs"][0], json.loads(alone.stdout)["outputs"][0]
    assert report["valid"] and out["slabs"] >= ranks
    # The same file, the same figures; the slabs differ (each rank takes a block of them).
    assert (tmp_path / "ranks" / name).read_bytes() == (tmp_path / "alone" / name).read_bytes()
    for key in ("triangles", "extracted_triangles", "genus", "components", "specks_removed", "cavities_filled"):
        assert out[key] == single[key], key
    # Nothing beside the file and the report: the ranks' parts and their vertex numbers are gone.
    assert sorted(p.name for p in (tmp_path / "ranks").iterdir()) == sorted([name, "report.json"])


def test_a_rank_that_dies_ends_a_streamed_run_and_leaves_nothing(tmp_path):
    with_mpi()
    path, name = stl_only(tmp_path, "menger_sponge.json")
    out = tmp_path / "out"
    # Rank 1 is interrupted a second into its part (some forty seconds of work): it removes its part
    # and dies; mpirun ends rank 0, which removes the staged file and the folder it made.
    script = ('if [ "$OMPI_COMM_WORLD_RANK" = 1 ]; then (sleep 1; kill -INT $$) & fi; '
              f'exec "{BINARY}" run "{path}" --stream -o "{out}" --voxel-size 0.0740740740741 --slab-mm 2 --threads 1')
    job = mpirun(2, ["sh", "-c", script])
    assert job.returncode != 0, job.stderr
    assert "interrupted" in job.stderr
    assert not out.exists() or list(out.iterdir()) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["stl-menger_sponge.json"] + (["out"] if out.exists() else [])
