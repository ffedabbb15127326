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
