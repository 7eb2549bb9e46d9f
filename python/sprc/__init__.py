"""sprc for Python: SPR / SPR-C stress recovery and ZZ error estimation on
cut Cartesian grids, and on your own mesh (:func:`recover`), through
libsprc's C API (ctypes, no compiled extension). See :mod:`sprc.library`
for how libsprc.so is found.

>>> import sprc
>>> rows = sprc.run_scene("example/scenes/lame_cylinder.nml", levels=[3, 4])
>>> rows[0]["err_fe"]            # doctest: +SKIP
0.2716...
>>> study = sprc.run("example/scenes/lame_cylinder.nml", levels=4)    # fields as arrays
>>> study.levels[0].bodies["pipe"]["sigma_sprc"].shape                # doctest: +SKIP
(n_nodes, 3)

``python -m sprc SCENE.nml`` runs a scene's study and prints its report.
"""

import ctypes
import math


from . import library
from .library import SprcError
from .recovery import Recovery, recover
from .contact_recovery import ContactPair, ContactRecovery, recover_contact

__all__ = ["__version__", "SprcError", "get_version", "run_scene", "run", "Study", "Level", "recover", "Recovery",
           "recover_contact", "ContactRecovery", "ContactPair",
           "INTEGER_COLUMNS"]

__version__ = "0.1.0"

#: Report columns that hold integers (returned as int; every other column is float).
INTEGER_COLUMNS = frozenset({"level", "elements", "cut_elements", "dofs", "contact_iterations", "solver_iterations",
                             "step"})


def get_version():
    """The version of the loaded libsprc as (major, minor, patch)."""
    v = library.get_version()
    return v // 10000, v // 100 % 100, v % 100


def run_scene(path, levels=None, threads=None):
    """Run the study of the scene file ``path`` (SCENE.md) and return its
    report: one dict per level, keyed by the report's columns in the order
    of its CSV header (``level, h, elements, ..., theta_sprc``, the contact
    columns in a study with contact, ``solver_iterations``, and ``step``,
    ``t_adapt`` in an adaptive study: one dict per step). Integer
    columns are ``int``, the others ``float``; a cell that does not apply is
    ``None``. ``levels`` (an int or a sequence of ints) overrides the
    scene's levels; ``threads`` (a positive int) runs every level on that
    many OpenMP threads, None chooses as the driver does (a level below
    5000 estimated dofs on one thread). Writes no files. Raises
    :class:`SprcError` with the library's message when the scene cannot be
    read or run, ``ValueError`` for bad ``levels`` or ``threads`` or a path
    with a NUL character.
    """
    encoded, _lv, lv_ptr, nlevels, nthreads = run_arguments(path, levels, threads)
    report = ctypes.c_void_p(library.run_scene_threads(encoded, lv_ptr, nlevels, nthreads))
    try:
        return _report_rows(report)
    finally:
        library.delete_report(ctypes.byref(report))


def _report_rows(report):
    """The rows of a report handle as dicts (run_scene)."""
    nrows = library.get_report_rows(report)
    ncols = library.get_report_columns(report)
    names = [library.get_report_column(report, j) for j in range(ncols)]
    columns = {name: library.get_report_values(report, name, nrows) for name in names}
    return [{name: _cell(name, columns[name][i]) for name in names} for i in range(nrows)]


def _cell(name, x):
    if math.isnan(x):
        return None
    return int(x) if name in INTEGER_COLUMNS else float(x)


from .study import Level, Study, run, run_arguments  # noqa: E402  (study uses _report_rows)
