"""The fields of a run as numpy arrays: :func:`run` returns a :class:`Study`.

>>> study = sprc.run("example/scenes/shrink_fit.nml", levels=[3, 4])   # doctest: +SKIP
>>> study.report[-1]["err_fe"]                                          # doctest: +SKIP
>>> level = study.levels[-1]                                            # level 4
>>> level.bodies["shaft"]["sigma_sprc"]          # (n_nodes, 3) float64, Voigt xx yy xy
>>> level.contact["p_sprc"]                      # (n_points,) float64

Per body (``level.bodies[name]``, a dict of arrays; ``n`` nodes, ``c`` cells):

============== ============ ======= ===============================================
name           shape        dtype   meaning
============== ============ ======= ===============================================
nodes          (n, dim)     float64 node coordinates
cells          (c, k)       int32   connectivity, 0-based, VTK order (k = 4, 9, 8, 27)
displacement   (n, dim)     float64 FE displacement
sigma_fe       (n, s)       float64 FE stress averaged over the elements at the node
sigma_spr      (n, s)       float64 SPR nodal stress (where SPR ran)
sigma_sprc     (n, s)       float64 SPR-C nodal stress (where SPR-C ran)
inside         (n,)         int32   1 in the body or on its boundary, 0 beyond it
zz_error_spr   (c,)         float64 ZZ error indicator per element, energy norm (SPR)
zz_error_sprc  (c,)         float64 the same with SPR-C
exact_error_fe (c,)         float64 exact FE error per element (with an exact solution)
cut            (c,)         int32   1 for a cell the boundary crosses
volume_fraction (c,)        float64 share of the cell inside the body
cell_level     (c,)         int32   refinement level of the cell
============== ============ ======= ===============================================

Stresses in Voigt order: s = 3 (xx, yy, xy) in 2D, 6 (xx, yy, zz, xy, yz, xz)
in 3D. Per ``&contact`` pair (``level.contacts[k]``; ``level.contact`` when
there is one): ``points`` (m, dim), ``p_fe``, ``p_spr``, ``p_sprc``,
``p_exact``, ``gap``, ``ts_fe``, ``ts_sprc``, ``weight`` (m,) float64,
``normal`` (m, dim) float64 and ``state`` (m,) int32 (0 open, 1 stick, 2
slip): the columns of PREFIX_contact.csv. Values are in the scene's units;
NaN marks a value not computed. The names are those of the datasets of the
driver's PREFIX.h5 (``/level_LL/<body>/node/<name>`` or ``.../cell/<name>``,
``nodes`` and ``cells`` are ``mesh/x`` and ``mesh/connectivity``) and the
arrays have their bits (there a 2-D vector has a third, zero column).
"""

import ctypes
import os

import numpy as np

from . import library
from .library import SprcError

__all__ = ["Study", "Level", "run", "run_arguments"]


class _Arrays(dict):
    """A dict of arrays whose missing keys raise KeyError naming what exists."""

    def __init__(self, what, items):
        super().__init__(items)
        self._what = what

    def __missing__(self, key):
        raise KeyError(f"{self._what} has no {key!r} (it has: {', '.join(self)})")


class Level:
    """The fields of one level: ``level`` (its number), ``report`` (its row),
    ``bodies`` (name -> dict of arrays), ``contacts`` (one dict of arrays per
    ``&contact`` pair, in scene order) and ``contact`` (the only pair's, None
    without contact)."""

    def __init__(self, report, bodies, contacts):
        self.report = report
        self.level = report["level"]
        #: the adaptive step (0 the start mesh); None in a uniform study
        self.step = report.get("step")
        self.bodies = bodies
        self.contacts = contacts

    @property
    def contact(self):
        if not self.contacts:
            return None
        if len(self.contacts) > 1:
            raise ValueError(f"level {self.level} has {len(self.contacts)} contact pairs: use .contacts[k]")
        return self.contacts[0]

    def __repr__(self):
        return f"<sprc.Level {self.level}: bodies {list(self.bodies)}, {len(self.contacts)} contact pair(s)>"


class Study:
    """A run's report (``report``: one dict per level, as :func:`sprc.run_scene`
    gives) and the fields of the levels kept (``levels``, in run order)."""

    def __init__(self, report, levels):
        self.report = report
        self.levels = levels

    def step(self, number):
        """The :class:`Level` of adaptive step ``number`` (0 the start mesh);
        ValueError in a uniform study, or when that step was not run or its
        fields were not kept. Several steps can share a finest level: name
        them by step."""
        run = [r.get("step") for r in self.report]
        if not run or run[0] is None:
            raise ValueError("a uniform study has no steps: use level(number)")
        for lv in self.levels:
            if lv.step == number:
                return lv
        if number in run:
            raise ValueError(f"the fields of step {number} were not kept (kept: {[lv.step for lv in self.levels]})")
        raise ValueError(f"step {number} was not run (steps run: 0 to {len(run) - 1})")

    def level(self, number):
        """The :class:`Level` of level ``number`` (in an adaptive study, the
        first step whose finest level it is; :meth:`step` names one step);
        ValueError when that level was not run or its fields were not kept."""
        for lv in self.levels:
            if lv.level == number:
                return lv
        run = [r["level"] for r in self.report]
        if number in run:
            raise ValueError(f"the fields of level {number} were not kept (kept: {[lv.level for lv in self.levels]})")
        raise ValueError(f"level {number} was not run (levels run: {run})")

    def __repr__(self):
        return f"<sprc.Study: levels run {[r['level'] for r in self.report]}, kept {[lv.level for lv in self.levels]}>"


def _int_list(values, name):
    """A non-empty 1-D intc array of ``values`` (an int or a sequence of ints)."""
    if isinstance(values, (int, np.integer)) and not isinstance(values, bool):
        values = [values]
    if isinstance(values, (str, bytes)):
        raise ValueError(f"{name} must be an int or a sequence of ints, got {values!r}")
    array = np.ascontiguousarray(values, dtype=np.intc)
    if array.ndim != 1 or array.size == 0 or not np.array_equal(array, np.asarray(values)):
        raise ValueError(f"{name} must be an int or a non-empty sequence of ints, got {values!r}")
    return array


def run_arguments(path, levels, threads):
    """The C arguments (path bytes, levels array or None, its pointer, count,
    threads) of a run, checked."""
    encoded = os.fsencode(path)
    if b"\0" in encoded:
        # C would read the path up to the NUL: another file, silently.
        raise ValueError(f"path contains a NUL character: {path!r}")
    if threads is None:
        threads = 0
    elif isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"threads must be a positive int (or None: as the driver chooses), got {threads!r}")
    if levels is None:
        return encoded, None, None, 0, int(threads)
    lv = _int_list(levels, "levels")
    return encoded, lv, lv.ctypes.data_as(ctypes.POINTER(ctypes.c_int)), lv.size, int(threads)


def run(path, levels=None, keep=None, threads=None):
    """Run the study of the scene file ``path`` as :func:`sprc.run_scene` does
    and return a :class:`Study` holding the fields of the levels ``keep``
    (an int or ints among those run; None: every level run; in an adaptive
    study, ``&adapt``, the steps, 0 the start mesh) as numpy arrays
    (module notes). ``levels`` (an int or ints) overrides the scene's levels;
    ``threads`` (a positive int) runs on that many threads, None as the
    driver does. Writes no files. Raises :class:`SprcError` when the scene
    cannot be read or run or ``keep`` names a level not run, ValueError for
    malformed arguments."""
    from . import _report_rows  # the report reader of run_scene

    encoded, lv, lv_ptr, nlevels, nthreads = run_arguments(path, levels, threads)
    if keep is None:
        kp, kp_ptr, nkeep = None, None, 0
    else:
        kp = _int_list(keep, "keep")
        kp_ptr, nkeep = kp.ctypes.data_as(ctypes.POINTER(ctypes.c_int)), kp.size
    study = ctypes.c_void_p(library.run_study(encoded, lv_ptr, nlevels, kp_ptr, nkeep, nthreads))
    try:
        report = ctypes.c_void_p(library.get_study_report(study))
        try:
            rows = _report_rows(report)
        finally:
            library.delete_report(ctypes.byref(report))
        # keep names levels, or steps in an adaptive study (its rows carry a step)
        key = "step" if rows and "step" in rows[0] else "level"
        kept = set(range(len(rows))) if kp is None else {i for i, r in enumerate(rows) if r[key] in set(kp.tolist())}
        levels_kept = [_level(study, i, rows[i]) for i in sorted(kept)]
    finally:
        library.delete_study(ctypes.byref(study))
    return Study(rows, levels_kept)


def _level(study, row, report):
    bodies, contacts = {}, []
    for g in range(library.get_study_grids(study, row)):
        name, kind = library.get_study_grid(study, row, g)
        fields = [library.get_study_field_name(study, row, name, f)
                  for f in range(library.get_study_fields(study, row, name))]
        what = f"contact pair {name!r}" if kind == 1 else f"body {name!r}"
        arrays = _Arrays(f"{what} at level {report['level']}",
                         {f: library.get_study_field(study, row, name, f) for f in fields})
        if kind == 1:
            contacts.append(arrays)
        else:
            bodies[name] = arrays
    return Level(report, _Arrays(f"level {report['level']}", bodies), contacts)


__all__ += ["SprcError"]
