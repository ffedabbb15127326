"""Lacuna: volumetric solid modeling for additive manufacturing.

Solids are made from the recipe's inputs with the recipe's keys as keyword arguments (lengths in
millimetres), combined with ``|``, ``-`` and ``&``, ``offset``, ``shell`` and ``infill``, and
meshed in memory; ``run`` runs a whole recipe into checked files; the generators return numpy
arrays and dicts. See README.md, "Python".
"""

from ._lacuna import *  # noqa: F401,F403
from ._lacuna import __version__  # noqa: F401

__all__ = [name for name in dir() if not name.startswith("_")]
