"""The Python samples (samples/python) run as a user runs them, and give the figures they should."""

import json
import os
import subprocess
import sys

import pytest


def run_sample(source_dir, name, out_dir):
    script = source_dir / "samples" / "python" / name
    done = subprocess.run([sys.executable, str(script), str(out_dir)], capture_output=True, text=True,
                          env=dict(os.environ))
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_lacunar_panel(source_dir, tmp_path):
    s = run_sample(source_dir, "lacunar_panel.py", tmp_path)
    assert s["valid"] and s["components"] == 1
    assert s["holes"] > 20 and s["genus"] == s["holes"]  # every hole goes right through
    assert s["volume_mm3"] == pytest.approx(s["expected_volume_mm3"], rel=0.005)
    assert (tmp_path / "lacunar_panel.3mf").stat().st_size > 0


def test_filled_hull(source_dir, tmp_path):
    s = run_sample(source_dir, "filled_hull.py", tmp_path)
    assert s["valid"] and s["problems"] == []
    assert 0.2 < s["relative_density"] < 0.7 and s["genus"] > 50
    assert (tmp_path / "filled_hull.stl").stat().st_size > 0
