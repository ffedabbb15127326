"""Shared fixtures of the Python module's tests: the command-line program and the source tree."""

import json
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("LACUNA_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BINARY = os.environ.get("LACUNA_BINARY", str(SOURCE_DIR / "build" / "lacuna"))


def lacuna_cli(*args, cwd=None):
    """Runs the command-line program; returns (exit code, stdout, stderr)."""
    done = subprocess.run([BINARY, *map(str, args)], capture_output=True, text=True, cwd=cwd)
    return done.returncode, done.stdout, done.stderr


@pytest.fixture
def cli():
    return lacuna_cli


@pytest.fixture
def source_dir():
    return SOURCE_DIR


def write_json(path, value):
    path.write_text(json.dumps(value))
    return path
