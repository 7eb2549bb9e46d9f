"""A tiny HDF5 reader over the HDF5 C library that libsprc links (ctypes):
enough to read back a dataset of the driver's PREFIX.h5 for the tests, where
h5py is not a dependency of the project."""

import ctypes
import ctypes.util

import numpy as np

_hid = ctypes.c_int64
_name = ctypes.util.find_library("hdf5_serial") or ctypes.util.find_library("hdf5")
if _name is None:
    raise ImportError("the HDF5 C library (libhdf5_serial or libhdf5) is not found")
_lib = ctypes.CDLL(_name)
_lib.H5open()
for _f, _res, _args in (("H5Fopen", _hid, [ctypes.c_char_p, ctypes.c_uint, _hid]),
                        ("H5Fclose", ctypes.c_int, [_hid]),
                        ("H5Dopen2", _hid, [_hid, ctypes.c_char_p, _hid]),
                        ("H5Dclose", ctypes.c_int, [_hid]),
                        ("H5Dget_space", _hid, [_hid]),
                        ("H5Sclose", ctypes.c_int, [_hid]),
                        ("H5Sget_simple_extent_ndims", ctypes.c_int, [_hid]),
                        ("H5Sget_simple_extent_dims", ctypes.c_int, [_hid, ctypes.POINTER(ctypes.c_uint64),
                                                                      ctypes.c_void_p]),
                        ("H5Dread", ctypes.c_int, [_hid, _hid, _hid, _hid, _hid, ctypes.c_void_p]),
                        ("H5Lexists", ctypes.c_int, [_hid, ctypes.c_char_p, _hid])):
    getattr(_lib, _f).restype = _res
    getattr(_lib, _f).argtypes = _args
_NATIVE_DOUBLE = _hid.in_dll(_lib, "H5T_NATIVE_DOUBLE_g").value
_NATIVE_INT = _hid.in_dll(_lib, "H5T_NATIVE_INT_g").value
_RDONLY, _DEFAULT, _ALL = 0, 0, 0


class File:
    """An HDF5 file open for reading: ``f.read(path, dtype)``, ``path in f``."""

    def __init__(self, path):
        self._id = _lib.H5Fopen(str(path).encode(), _RDONLY, _DEFAULT)
        if self._id < 0:
            raise OSError(f"cannot open {path} with HDF5")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        _lib.H5Fclose(self._id)

    def __contains__(self, path):
        parts = path.strip("/").split("/")
        return all(_lib.H5Lexists(self._id, ("/" + "/".join(parts[:k])).encode(), _DEFAULT) > 0
                   for k in range(1, len(parts) + 1))

    def read(self, path, dtype):
        """Dataset ``path`` as a numpy array of ``dtype`` (float64 or int32), in its C shape."""
        ds = _lib.H5Dopen2(self._id, path.encode(), _DEFAULT)
        if ds < 0:
            raise KeyError(path)
        try:
            space = _lib.H5Dget_space(ds)
            ndims = _lib.H5Sget_simple_extent_ndims(space)
            dims = (ctypes.c_uint64 * max(ndims, 1))()
            _lib.H5Sget_simple_extent_dims(space, dims, None)
            _lib.H5Sclose(space)
            out = np.empty(tuple(dims[:ndims]), dtype=dtype)
            mem = _NATIVE_INT if np.dtype(dtype) == np.intc else _NATIVE_DOUBLE
            if _lib.H5Dread(ds, mem, _ALL, _ALL, _DEFAULT, out.ctypes.data) < 0:
                raise OSError(f"cannot read {path}")
            return out
        finally:
            _lib.H5Dclose(ds)
