"""The thin 1:1 layer over libsprc's C API (include/sprc.h), with ctypes.

Each C entry point that takes an error handle is wrapped so that it gets a
fresh handle and raises :class:`SprcError` with the library's message when
the call fails; the wrapper otherwise returns what the C function returns.

The shared library is looked up in this order (the first that exists wins):

1. the file named by the environment variable ``SPRC_LIBRARY``;
2. ``libsprc.so`` in the ``libdir`` of ``pkg-config sprc`` (an installation
   by ``make install PREFIX=...``; set ``PKG_CONFIG_PATH`` to
   ``PREFIX/lib/pkgconfig`` for a non-standard prefix);
3. the dynamic loader's search (``ctypes.util.find_library("sprc")``:
   ``LD_LIBRARY_PATH``, ``/usr/local/lib`` after ``ldconfig``, ...);
4. the source tree's build output, ``build/lib/libsprc.so`` (``make lib``),
   when this package is used from ``python/`` of a checkout.
"""

import ctypes
import ctypes.util
import functools
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

__all__ = ["SprcError", "lib", "library_path", "error_check"]

# Status codes of sprc_get_error_status (include/sprc.h, SPRC_STAT_*).
STATUS_NAMES = {
    0: "success",
    1: "invalid input",
    2: "singular",
    3: "not positive definite",
    4: "not converged",
    5: "i/o error",
    6: "out of memory",
    7: "unsupported",
    8: "internal error",
}


class SprcError(RuntimeError):
    """An error reported by libsprc: ``str(e)`` is the library's message,
    ``e.status`` its status code (``e.status_name`` in words)."""

    def __init__(self, message, status=1):
        super().__init__(message)
        self.status = status
        self.status_name = STATUS_NAMES.get(status, "unknown status")


def _candidates():
    env = os.environ.get("SPRC_LIBRARY")
    if env:
        yield Path(env)
        return
    if shutil.which("pkg-config"):
        try:
            out = subprocess.run(["pkg-config", "--variable=libdir", "sprc"], capture_output=True,
                                 text=True, check=False, timeout=30)
            if out.returncode == 0 and out.stdout.strip():
                yield Path(out.stdout.strip()) / "libsprc.so"
        except (OSError, subprocess.SubprocessError):
            pass
    found = ctypes.util.find_library("sprc")
    if found:
        yield Path(found)
    yield Path(__file__).resolve().parents[2] / "build" / "lib" / "libsprc.so"


def _find_library():
    tried = []
    for path in _candidates():
        tried.append(str(path))
        # A bare soname from find_library is for the loader to resolve.
        if path.is_file() or (path.parent == Path(".") and path.name):
            try:
                return ctypes.CDLL(str(path)), str(path)
            except OSError as exc:
                tried[-1] += f" ({exc})"
    raise ImportError("sprc: libsprc.so not found; build it with `make lib` or set SPRC_LIBRARY. Tried: "
                      + "; ".join(tried))


lib, library_path = _find_library()

_c_int_p = ctypes.POINTER(ctypes.c_int)
_c_double_p = ctypes.POINTER(ctypes.c_double)
_handle = ctypes.c_void_p


def _prototype(name, restype, *argtypes):
    func = getattr(lib, name)
    func.restype = restype
    func.argtypes = list(argtypes)
    return func


get_version = _prototype("sprc_get_version", ctypes.c_int)
new_error = _prototype("sprc_new_error", _handle)
check_error = _prototype("sprc_check_error", ctypes.c_int, _handle)
get_error_status = _prototype("sprc_get_error_status", ctypes.c_int, _handle)
get_error = _prototype("sprc_get_error", None, _handle, ctypes.c_char_p, _c_int_p)
clear_error = _prototype("sprc_clear_error", None, _handle)
delete_error = _prototype("sprc_delete_error", None, ctypes.POINTER(_handle))
delete_report = _prototype("sprc_delete_report", None, ctypes.POINTER(_handle))
delete_recovery = _prototype("sprc_delete_recovery", None, ctypes.POINTER(_handle))


def error_message(handle, size=4096):
    """The message held by an error handle ('' if none)."""
    buf = ctypes.create_string_buffer(size)
    get_error(handle, buf, ctypes.byref(ctypes.c_int(size)))
    return buf.value.decode("utf-8", errors="replace")


def error_check(func):
    """Wrap a C entry point whose first argument is an error handle: the
    wrapper supplies the handle and raises SprcError when the call fails."""

    @functools.wraps(func)
    def wrapper(*args):
        handle = _handle(new_error())
        if not handle:
            raise MemoryError("sprc: cannot allocate an error handle")
        try:
            result = func(handle, *args)
            if check_error(handle) != 0:
                raise SprcError(error_message(handle), get_error_status(handle))
            return result
        finally:
            delete_error(ctypes.byref(handle))

    return wrapper


run_scene = error_check(_prototype("sprc_run_scene", _handle, _handle, ctypes.c_char_p, _c_int_p, ctypes.c_int))
get_report_rows = error_check(_prototype("sprc_get_report_rows", ctypes.c_int, _handle, _handle))
get_report_columns = error_check(_prototype("sprc_get_report_columns", ctypes.c_int, _handle, _handle))
_get_report_column = error_check(_prototype("sprc_get_report_column", None, _handle, _handle, ctypes.c_int,
                                            ctypes.c_char_p, _c_int_p))
get_report_value = error_check(_prototype("sprc_get_report_value", ctypes.c_double, _handle, _handle,
                                          ctypes.c_int, ctypes.c_char_p))
_get_report_values = error_check(_prototype("sprc_get_report_values", None, _handle, _handle, ctypes.c_char_p,
                                            _c_double_p, ctypes.c_int))


def get_report_column(report, index, size=64):
    """The name of column ``index`` (0-based) of a report."""
    buf = ctypes.create_string_buffer(size)
    _get_report_column(report, index, buf, ctypes.byref(ctypes.c_int(size)))
    return buf.value.decode()


def get_report_values(report, column, nrows):
    """Column ``column`` of a report as a float64 array of ``nrows`` values (NaN = empty)."""
    values = np.empty(nrows, dtype=np.float64)
    _get_report_values(report, column.encode(), values.ctypes.data_as(_c_double_p), nrows)
    return values

_RECOVER_ARGS = (
    ctypes.c_int, ctypes.c_int, ctypes.c_int, _c_double_p,                  # dim, analysis, nnode, nodes
    ctypes.c_int, ctypes.c_int, ctypes.c_int, _c_int_p,                     # element_type, nen, nelem, connectivity
    ctypes.c_int, _c_double_p, _c_double_p, _c_double_p,                    # ngp, points, weights, stress
    ctypes.c_double, ctypes.c_double, ctypes.c_int, _c_double_p,            # young, poisson, method, body_force
    ctypes.c_int, ctypes.c_int, _c_int_p, _c_int_p, _c_double_p)            # facets
recover = error_check(_prototype("sprc_recover", _handle, _handle, *_RECOVER_ARGS))
recover_xi = error_check(_prototype("sprc_recover_xi", _handle, _handle, *_RECOVER_ARGS, _c_double_p))  # gauss_xi
recover_reference = error_check(_prototype("sprc_recover_reference", _handle, _handle, *_RECOVER_ARGS, _c_double_p,
                                           ctypes.c_int))  # gauss_xi, reference
get_recovery_nodal_stress = error_check(_prototype("sprc_get_recovery_nodal_stress", None, _handle, _handle,
                                                   _c_double_p, ctypes.c_int))
get_recovery_element_error = error_check(_prototype("sprc_get_recovery_element_error", None, _handle, _handle,
                                                    _c_double_p, ctypes.c_int))
get_recovery_global_error = error_check(_prototype("sprc_get_recovery_global_error", ctypes.c_double, _handle,
                                                   _handle))
get_recovery_eta = error_check(_prototype("sprc_get_recovery_eta", ctypes.c_double, _handle, _handle))
eval_recovery = error_check(_prototype("sprc_eval_recovery", None, _handle, _handle, ctypes.c_int, _c_double_p,
                                       _c_int_p, _c_double_p))

run_scene_threads = error_check(_prototype("sprc_run_scene_threads", _handle, _handle, ctypes.c_char_p, _c_int_p,
                                           ctypes.c_int, ctypes.c_int))
run_study = error_check(_prototype("sprc_run_study", _handle, _handle, ctypes.c_char_p, _c_int_p, ctypes.c_int,
                                   _c_int_p, ctypes.c_int, ctypes.c_int))
get_study_report = error_check(_prototype("sprc_get_study_report", _handle, _handle, _handle))
get_study_grids = error_check(_prototype("sprc_get_study_grids", ctypes.c_int, _handle, _handle, ctypes.c_int))
_get_study_grid = error_check(_prototype("sprc_get_study_grid", ctypes.c_int, _handle, _handle, ctypes.c_int,
                                         ctypes.c_int, ctypes.c_char_p, _c_int_p))
_get_study_fields = error_check(_prototype("sprc_get_study_fields", ctypes.c_int, _handle, _handle, ctypes.c_int,
                                           ctypes.c_char_p))
_get_study_field_name = error_check(_prototype("sprc_get_study_field_name", None, _handle, _handle, ctypes.c_int,
                                               ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, _c_int_p))
_get_study_field_shape = error_check(_prototype("sprc_get_study_field_shape", ctypes.c_int, _handle, _handle,
                                                ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, _c_int_p))
_get_study_field = error_check(_prototype("sprc_get_study_field", None, _handle, _handle, ctypes.c_int,
                                          ctypes.c_char_p, ctypes.c_char_p, _c_double_p, ctypes.c_int))
_get_study_field_int = error_check(_prototype("sprc_get_study_field_int", None, _handle, _handle, ctypes.c_int,
                                              ctypes.c_char_p, ctypes.c_char_p, _c_int_p, ctypes.c_int))
delete_study = _prototype("sprc_delete_study", None, ctypes.POINTER(_handle))

#: Field types of sprc_get_study_field_shape (SPRC_FIELD_REAL, SPRC_FIELD_INT).
FIELD_REAL, FIELD_INT = 1, 2


def get_study_grid(study, row, index, size=256):
    """(name, kind) of grid ``index`` of report row ``row``: kind 0 a body, 1 a contact pair."""
    buf = ctypes.create_string_buffer(size)
    kind = _get_study_grid(study, row, index, buf, ctypes.byref(ctypes.c_int(size)))
    return buf.value.decode(), kind


def get_study_fields(study, row, grid):
    """Number of fields of grid ``grid`` (str) at report row ``row``, the mesh arrays included."""
    return _get_study_fields(study, row, grid.encode())


def get_study_field_name(study, row, grid, index, size=256):
    """The name of field ``index`` of grid ``grid`` (str) at report row ``row``."""
    buf = ctypes.create_string_buffer(size)
    _get_study_field_name(study, row, grid.encode(), index, buf, ctypes.byref(ctypes.c_int(size)))
    return buf.value.decode()


def get_study_field(study, row, grid, field):
    """A field as a numpy array: float64 or int32, shape (rows, columns) in C
    order, or (rows,) for a field of one column."""
    shape = (ctypes.c_int * 2)()
    kind = _get_study_field_shape(study, row, grid.encode(), field.encode(), shape)
    rows, cols = shape[0], shape[1]
    if kind == FIELD_INT:
        values = np.empty((rows, cols), dtype=np.intc)
        _get_study_field_int(study, row, grid.encode(), field.encode(), values.ctypes.data_as(_c_int_p), rows * cols)
    else:
        values = np.empty((rows, cols), dtype=np.float64)
        _get_study_field(study, row, grid.encode(), field.encode(), values.ctypes.data_as(_c_double_p), rows * cols)
    return values[:, 0].copy() if cols == 1 else values

new_contact_input = error_check(_prototype("sprc_new_contact_input", _handle, _handle))
contact_add_body = error_check(_prototype("sprc_contact_add_body", ctypes.c_int, _handle, _handle,
                                          ctypes.c_int, ctypes.c_int, ctypes.c_int, _c_double_p,   # dim ... nodes
                                          ctypes.c_int, ctypes.c_int, ctypes.c_int, _c_int_p,      # connectivity
                                          ctypes.c_int, _c_double_p, _c_double_p, _c_double_p,     # points
                                          ctypes.c_double, ctypes.c_double, _c_double_p,           # material, force
                                          ctypes.c_int, ctypes.c_int, _c_int_p, _c_int_p, _c_double_p,  # facets
                                          _c_double_p, ctypes.c_int))                              # gauss_xi
contact_add_pair = error_check(_prototype("sprc_contact_add_pair", ctypes.c_int, _handle, _handle,
                                          ctypes.c_int, ctypes.c_int,                              # slave, master
                                          ctypes.c_int, _c_int_p, _c_int_p, _c_double_p,           # slave side
                                          ctypes.c_int, _c_int_p, _c_int_p, _c_double_p,           # master side
                                          ctypes.c_double, _c_double_p))                           # mu, pressure
recover_contact = error_check(_prototype("sprc_recover_contact", _handle, _handle, _handle, ctypes.c_int))
get_contact_body = error_check(_prototype("sprc_get_contact_body", _handle, _handle, _handle, ctypes.c_int))
get_contact_points = error_check(_prototype("sprc_get_contact_points", ctypes.c_int, _handle, _handle,
                                            ctypes.c_int))
get_contact_pair = error_check(_prototype("sprc_get_contact_pair", None, _handle, _handle, ctypes.c_int,
                                          ctypes.c_int, *([_c_double_p] * 8)))
delete_contact_input = _prototype("sprc_delete_contact_input", None, ctypes.POINTER(_handle))
delete_contact_recovery = _prototype("sprc_delete_contact_recovery", None, ctypes.POINTER(_handle))
