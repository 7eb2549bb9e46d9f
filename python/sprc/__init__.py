"""sprc for Python: SPR / SPR-C stress recovery and ZZ error estimation on
cut Cartesian grids, and on your own mesh (:func:`recover`), through
libsprc's C API (ctypes, no compiled extension). See :mod:`sprc.library`
for how libsprc.so is found.

>>> import sprc
>>> rows = sprc.run_scene("example/scenes/lame_cylinder.nml", levels=[3, 4])
>>> rows[0]["err_fe"]            # doctest: +SKIP
0.2716...
"""

import ctypes
import math
import os

import numpy as np

from . import library
from .library import SprcError
from .recovery import Recovery, recover

__all__ = ["__version__", "SprcError", "get_version", "run_scene", "recover", "Recovery", "INTEGER_COLUMNS"]

__version__ = "0.1.0"

#: Report columns that hold integers (returned as int; every other column is float).
INTEGER_COLUMNS = frozenset({"level", "elements", "cut_elements", "dofs", "contact_iterations", "solver_iterations",
                             "step"})


def get_version():
    """The version of the loaded libsprc as (major, minor, patch)."""
    v = library.get_version()
    return v // 10000, v // 100 % 100, v % 100


def run_scene(path, levels=None):
    """Run the study of the scene file ``path`` (SCENE.md) and return its
    report: one dict per level, keyed by the report's columns in the order
    of its CSV header (``level, h, elements, ..., theta_sprc``, the contact
    columns in a study with contact, ``solver_iterations``, and ``step``,
    ``t_adapt`` in an adaptive study: one dict per step). Integer
    columns are ``int``, the others ``float``; a cell that does not apply is
    ``None``. ``levels`` (a sequence of ints) overrides the scene's levels.
    Writes no files. Raises :class:`SprcError` with the library's message
    when the scene cannot be read or run, ``ValueError`` for bad ``levels``
    or a path with a NUL character.
    """
    if levels is None:
        lv, nlevels, lv_ptr = None, 0, None
    else:
        lv = np.ascontiguousarray(levels, dtype=np.intc)
        if lv.ndim != 1 or lv.size == 0:
            raise ValueError("levels must be a non-empty sequence of integers (or None for the scene's levels)")
        if not np.array_equal(lv, np.asarray(levels)):
            raise ValueError(f"levels must be integers, got {levels!r}")
        nlevels, lv_ptr = lv.size, lv.ctypes.data_as(ctypes.POINTER(ctypes.c_int))
    encoded = os.fsencode(path)
    if b"\0" in encoded:
        # C would read the path up to the NUL: another file, silently.
        raise ValueError(f"path contains a NUL character: {path!r}")
    report = ctypes.c_void_p(library.run_scene(encoded, lv_ptr, nlevels))
    try:
        nrows = library.get_report_rows(report)
        ncols = library.get_report_columns(report)
        names = [library.get_report_column(report, j) for j in range(ncols)]
        columns = {name: library.get_report_values(report, name, nrows) for name in names}
    finally:
        library.delete_report(ctypes.byref(report))
    return [{name: _cell(name, columns[name][i]) for name in names} for i in range(nrows)]


def _cell(name, x):
    if math.isnan(x):
        return None
    return int(x) if name in INTEGER_COLUMNS else float(x)
