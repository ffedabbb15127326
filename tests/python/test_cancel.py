"""Heavy calls release the GIL, and Ctrl-C cancels them: a SIGINT sent from a thread during a long call
raises KeyboardInterrupt soon after, with nothing left on disk, and the module keeps working."""

import os
import signal
import threading
import time

import pytest

import lacuna


def interrupt_after(seconds):
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def heavy():
    # About 20 s of voxelizing, meshing and simplifying on two cores: four balls at 0.03 mm.
    parts = [lacuna.sphere(center_mm=[10 * i, 0, 0], radius_mm=4) for i in range(4)]
    return parts[0] | parts[1] | parts[2] | parts[3]


def test_ctrl_c_cancels_meshing():
    start = time.monotonic()
    timer = interrupt_after(1.0)
    with pytest.raises(KeyboardInterrupt):
        heavy().mesh(voxel_size_mm=0.03)
    timer.join()
    assert time.monotonic() - start < 6.0  # about 20 s uninterrupted
    assert lacuna.sphere(radius_mm=1).mesh(voxel_size_mm=0.2).components == 1


def test_ctrl_c_cancels_a_run_and_leaves_nothing(tmp_path):
    recipe = heavy().to_recipe(name="heavy", voxel_size_mm=0.03)
    start = time.monotonic()
    timer = interrupt_after(1.5)
    with pytest.raises(KeyboardInterrupt):
        lacuna.run(recipe, output_dir=tmp_path / "out")
    timer.join()
    assert time.monotonic() - start < 6.5
    assert not (tmp_path / "out").exists()


def test_ctrl_c_cancels_a_mesh_conversion():
    # 14 s uninterrupted; OpenVDB's mesh conversion reports its progress only now and then.
    hull = lacuna.mesh(lacuna.sphere(radius_mm=10).mesh(voxel_size_mm=0.2))
    start = time.monotonic()
    timer = interrupt_after(0.5)
    with pytest.raises(KeyboardInterrupt):
        hull.voxelize(voxel_size_mm=0.02)
    timer.join()
    assert time.monotonic() - start < 10.0


def test_calls_release_the_gil():
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    start = time.monotonic()
    while time.monotonic() - start < 0.5:  # nearly all of it inside mesh()
        lacuna.sphere(radius_mm=3).mesh(voxel_size_mm=0.05)
    end = time.monotonic()
    stop.set()
    counter.join()
    during = [t for t in ticks if start < t < end]
    # Python ran on the other thread during the calls (a held GIL would allow no tick until each call returned).
    assert len(during) > 0.05 * (end - start) / 0.001


# A script that runs the heavy recipe into argv[1]; SIGTERM raises KeyboardInterrupt there (Python's own
# default_int_handler) when argv[2] is "handled", and keeps Python's default (the process dies) otherwise.
SIGTERM_SCRIPT = """
import signal, sys
import lacuna
if sys.argv[2] == "handled":
    signal.signal(signal.SIGTERM, signal.default_int_handler)
parts = [lacuna.sphere(center_mm=[10 * i, 0, 0], radius_mm=4) for i in range(4)]
recipe = (parts[0] | parts[1] | parts[2] | parts[3]).to_recipe(name="heavy", voxel_size_mm=0.03)
print("started", flush=True)
try:
    lacuna.run(recipe, output_dir=sys.argv[1])
except KeyboardInterrupt:
    sys.exit(143)
sys.exit(0)
"""


def run_and_terminate(tmp_path, mode, after_s):
    import subprocess
    import sys

    script = tmp_path / "term.py"
    script.write_text(SIGTERM_SCRIPT)
    child = subprocess.Popen([sys.executable, str(script), str(tmp_path / "out"), mode], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "started"
    time.sleep(after_s)
    start = time.monotonic()
    child.send_signal(signal.SIGTERM)
    code = child.wait(timeout=60)
    return code, time.monotonic() - start


def test_sigterm_with_pythons_interrupt_handler_cancels_and_leaves_nothing(tmp_path):
    code, seconds = run_and_terminate(tmp_path, "handled", 1.5)
    assert code == 143
    assert seconds < 5.0  # the run itself takes about 20 s
    assert not (tmp_path / "out").exists()


def test_a_run_after_one_killed_by_sigterm_removes_its_leftovers(tmp_path):
    # Python's default SIGTERM ends the process at once; whatever it left is a dead process's.
    code, _ = run_and_terminate(tmp_path, "default", 1.5)
    assert code == -signal.SIGTERM
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    import subprocess

    dead = subprocess.Popen(["true"])
    dead.wait()
    (out / f".s.stl.tmp-{dead.pid}-0").write_text("partial")
    lacuna.run(lacuna.sphere(radius_mm=1).to_recipe(name="s", voxel_size_mm=0.2), output_dir=out)
    assert sorted(p.name for p in out.iterdir()) == ["report.html", "report.json", "s.stl"]
