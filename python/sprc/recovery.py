"""SPR / SPR-C stress recovery and the ZZ error estimate on your own mesh
(the C entries ``sprc_recover_xi`` and friends, include/sprc.h).

>>> rec = sprc.recover(nodes, elements, "quad4", gauss_points, gauss_weights,
...                    gauss_stress, young=210e3, poisson=0.3)   # doctest: +SKIP
>>> rec.nodal_stress, rec.element_error, rec.global_error, rec.eta  # doctest: +SKIP
>>> rec.evaluate([[0.5, 0.5]])                                  # doctest: +SKIP
"""

import ctypes

import numpy as np

from . import library

__all__ = ["recover", "Recovery", "ELEMENT_TYPES", "ANALYSES", "METHODS", "FACET_KINDS"]

#: Element types: name -> (VTK code, dimension, nodes, nodes per facet).
ELEMENT_TYPES = {
    "tri3": (5, 2, 3, 2),
    "quad4": (9, 2, 4, 2),
    "quad9": (28, 2, 9, 3),
    "tet4": (10, 3, 4, 3),
    "hex8": (12, 3, 8, 4),
    "hex27": (29, 3, 27, 9),
}
#: Analyses (SPRC_PLANE_STRESS, ...).
ANALYSES = {"plane_stress": 1, "plane_strain": 2, "solid": 3}
#: Recovery methods (SPRC_METHOD_*).
METHODS = {"spr": 1, "sprc": 2}
#: Patch degree: 'auto' (SPR at the element's degree p, SPR-C at p+1 for quad9 / hex27, p
#: otherwise), the element's (SPRC_RECOVERY_P) or one more (SPRC_RECOVERY_P_PLUS_1).
DEGREES = {"auto": 0, "p": 512, "p+1": 256}
#: Boundary facet kinds (SPRC_FACET_*).
FACET_KINDS = {"traction": 1, "symmetry": 2, "free": 3, "pressure": 4}
#: Conventions of gauss_xi (SPRC_REFERENCE_*): quads and hexes on [0, 1]^dim or [-1, 1]^dim.
REFERENCES = {"unit": 0, "symmetric": 1}

_INT_MIN, _INT_MAX = np.iinfo(np.intc).min, np.iinfo(np.intc).max
_c_double_p = ctypes.POINTER(ctypes.c_double)
_c_int_p = ctypes.POINTER(ctypes.c_int)


def _doubles(name, value, shape):
    """value as a C-contiguous float64 array of the given shape (None: any extent)."""
    try:
        arr = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be an array of numbers: {exc}") from None
    _check_shape(name, arr, shape)
    return arr


def _ints(name, value, shape):
    """value as a C-contiguous C int array of the given shape; integers only."""
    arr = np.asarray(value)
    if arr.size == 0 and arr.dtype.kind == "f":
        arr = arr.astype(np.intc)
    if arr.dtype.kind not in "iu":
        raise ValueError(f"{name} must hold integers, got dtype {arr.dtype}")
    if arr.size and (arr.min() < _INT_MIN or arr.max() > _INT_MAX):
        raise ValueError(f"{name} holds values outside the range of a C int")
    arr = np.ascontiguousarray(arr, dtype=np.intc)
    _check_shape(name, arr, shape)
    return arr


def _check_shape(name, arr, shape):
    if arr.ndim != len(shape) or any(want is not None and got != want for got, want in zip(arr.shape, shape)):
        want = "[" + ", ".join("*" if s is None else str(s) for s in shape) + "]"
        raise ValueError(f"{name} has shape {list(arr.shape)}, need {want}")


def _code(name, value, table):
    try:
        return table[value]
    except (KeyError, TypeError):
        raise ValueError(f"{name} = {value!r} is not one of {', '.join(map(repr, table))}") from None


def _ptr(arr, ctype):
    return None if arr is None else arr.ctypes.data_as(ctype)


class Recovery:
    """The result of :func:`recover`.

    Attributes: ``nodal_stress`` [nnode, nstress] (nodes of no element get
    zero), ``element_error`` [nelem] (ZZ error per element, energy norm),
    ``global_error`` (sqrt of the sum of squares), ``eta`` (estimated relative
    error err / sqrt(||sigma_h||^2 + err^2)), ``element_type``, ``dim``,
    ``nstress``. :meth:`evaluate` gives the recovered field at any points.
    """

    def __init__(self, handle, element_type, dim, nstress, nnode, nelem):
        self._handle = ctypes.c_void_p(handle)
        self.element_type, self.dim, self.nstress, self.nelem = element_type, dim, nstress, nelem
        self.nodal_stress = np.empty((nnode, nstress))
        library.get_recovery_nodal_stress(self._handle, _ptr(self.nodal_stress, _c_double_p), nnode)
        self.element_error = np.empty(nelem)
        library.get_recovery_element_error(self._handle, _ptr(self.element_error, _c_double_p), nelem)
        self.global_error = library.get_recovery_global_error(self._handle)
        self.eta = library.get_recovery_eta(self._handle)

    def evaluate(self, points, elements=None):
        """The recovered stress sigma* at ``points`` [npts, dim] as [npts, nstress]
        (a single point [dim] gives [nstress]). ``elements`` [npts] names the
        element of each point (0-based, -1 to search); None searches every
        point. A point in no element raises :class:`SprcError`."""
        if not self._handle:
            raise ValueError("this Recovery is closed")
        single = np.ndim(points) == 1
        pts = _doubles("points", np.atleast_2d(points) if single else points, (None, self.dim))
        npts = pts.shape[0]
        el = None
        if elements is not None:
            el = _ints("elements", np.atleast_1d(elements), (npts,))
        out = np.empty((npts, self.nstress))
        library.eval_recovery(self._handle, npts, _ptr(pts, _c_double_p), _ptr(el, _c_int_p),
                              _ptr(out, _c_double_p))
        return out[0] if single else out

    def close(self):
        """Free the library's copy of the mesh and patches (also done when garbage-collected)."""
        if getattr(self, "_handle", None):
            library.delete_recovery(ctypes.byref(self._handle))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    def __repr__(self):
        return (f"<sprc.Recovery {self.element_type}: {self.nodal_stress.shape[0]} nodes, {self.nelem} elements, "
                f"global_error={self.global_error:.6g}, eta={self.eta:.6g}>")


def _facets(boundary, dim, nfn):
    """(facet_nodes [nfacet, nfn], kinds [nfacet], tractions [nfacet, dim] or None)."""
    if isinstance(boundary, dict):
        if "nodes" not in boundary or "kind" not in boundary:
            raise ValueError("boundary as a dict needs 'nodes' [nfacet, nfacet_nodes] and 'kind'")
        nodes = _ints("boundary['nodes']", np.atleast_2d(boundary["nodes"]), (None, nfn))
        nf = nodes.shape[0]
        kind = boundary["kind"]
        kinds = [kind] * nf if isinstance(kind, str) else list(kind)
        traction = boundary.get("traction")
        if traction is not None:
            traction = np.asarray(traction, dtype=np.float64)
            if traction.shape == (dim,):
                traction = np.broadcast_to(traction, (nf, dim))
        pressure = boundary.get("pressure")
        if pressure is not None:
            if np.ndim(pressure) == 0:
                pressure = np.full(nf, pressure, dtype=np.float64)
            pressure = _doubles("boundary['pressure']", pressure, (nf,))
    else:
        try:
            facets = list(boundary)
        except TypeError:
            raise ValueError("boundary must be a dict of arrays or a list of facet dicts") from None
        for f in facets:
            if not isinstance(f, dict) or "nodes" not in f or "kind" not in f:
                raise ValueError("each facet of boundary must be a dict with 'nodes' and 'kind' (and 'traction')")
        nodes = _ints("boundary nodes", np.array([f["nodes"] for f in facets]).reshape(len(facets), -1),
                      (None, nfn))
        nf = nodes.shape[0]
        kinds = [f["kind"] for f in facets]
        traction = None
        if any(f.get("traction") is not None for f in facets):
            traction = np.zeros((nf, dim))
            for i, f in enumerate(facets):
                if f.get("traction") is not None:
                    traction[i] = _doubles(f"boundary[{i}]['traction']", f["traction"], (dim,))
        pressure = None
        if any(f.get("pressure") is not None for f in facets):
            pressure = np.zeros(nf)
            for i, f in enumerate(facets):
                if f.get("pressure") is not None:
                    pressure[i] = _doubles(f"boundary[{i}]['pressure']", np.atleast_1d(f["pressure"]), (1,))[0]
    if len(kinds) != nf:
        raise ValueError(f"boundary has {nf} facets but {len(kinds)} kinds")
    codes = np.array([_code("boundary kind", k, FACET_KINDS) for k in kinds], dtype=np.intc)
    if traction is not None:
        traction = _doubles("boundary traction", traction, (nf, dim))
    if traction is None and (codes == FACET_KINDS["traction"]).any():
        raise ValueError("boundary has traction facets but no 'traction'")
    is_pressure = codes == FACET_KINDS["pressure"]
    if is_pressure.any():
        if pressure is None:
            raise ValueError("boundary has pressure facets but no 'pressure'")
        # The C API takes a pressure facet's p in facet_traction[f][0].
        traction = np.zeros((nf, dim)) if traction is None else traction.copy()
        traction[is_pressure, 0] = pressure[is_pressure]
    return nodes, codes, traction


def recover(nodes, elements, element_type, gauss_points, gauss_weights, gauss_stress, *, young, poisson,
            analysis=None, method="sprc", body_force=None, boundary=None, degree="auto", gauss_xi=None,
            reference="unit"):
    """Recover the stresses of a finite-element solution on your own mesh
    and estimate its error (SPR or SPR-C with the ZZ estimate).

    nodes          [nnode, dim] coordinates.
    elements       [nelem, nen] 0-based node indices, VTK node order.
    element_type   'tri3', 'quad4', 'quad9' (2D), 'tet4', 'hex8', 'hex27' (3D);
                   one type for the whole mesh.
    gauss_points   [nelem, ngp, dim] integration points (physical coordinates,
                   inside their element).
    gauss_weights  [nelem, ngp] quadrature weight times |J| (> 0).
    gauss_stress   [nelem, ngp, nstress] FE stresses at the points, Voigt order:
                   2D (xx, yy, xy), 3D (xx, yy, zz, xy, yz, xz).
    young, poisson the material (isotropic, linear elastic).
    analysis       'plane_stress' or 'plane_strain' in 2D, 'solid' in 3D
                   (default: 'plane_stress' in 2D, 'solid' in 3D).
    method         'sprc' (default) or 'spr'.
    degree         'auto' (default: SPR at the element's degree p, 1, or 2 for
                   quad9 and hex27; SPR-C at p+1 for quad9 and hex27, p for the
                   linear elements), 'p' (the element's degree) or 'p+1' (one more).
    body_force     [dim] constant body force b with div(sigma) + b = 0, or None.
    boundary       boundary facets for SPR-C (SPR validates and ignores them):
                   either a dict of arrays
                       {"nodes": [nfacet, nfn] 0-based,
                        "kind": "traction" | "symmetry" | "free" | "pressure"
                                (or one per facet),
                        "traction": [nfacet, dim] or [dim] for all (traction facets),
                        "pressure": [nfacet] or one value for all (pressure facets)}
                   or a list of facets
                       [{"nodes": [...], "kind": "traction", "traction": [tx, ty]},
                        {"nodes": [...], "kind": "pressure", "pressure": p},
                        {"nodes": [...], "kind": "symmetry"}, ...].
                   A facet is a side (face) of exactly one element, its nodes in
                   any order (nfn nodes: 2 for tri3 and quad4, 3 for quad9 and
                   tet4, 4 for hex8, 9 for hex27); anything else (a diagonal, an
                   interior side, nodes of no one element) raises SprcError
                   naming boundary["nodes"][i]. "free" means zero traction, "symmetry" zero shear,
                   "pressure" t = -p n with the facet's own outward normal at
                   each of its points (right on curved facets, where the
                   traction turns). Only the facets given are constrained.
    gauss_xi       [nelem, ngp, dim] reference coordinates of the points in
                   their elements, as your FE code has them, or None (default:
                   derived by Newton's method). Checked, not trusted: inside the
                   reference cell and mapped onto the point (tolerance 1e-6 in
                   [0, 1] units); the message of a point outside names the
                   convention.
    reference      the convention of gauss_xi for quads and hexes: "unit"
                   (default, [0, 1]^dim) or "symmetric" ([-1, 1]^dim, as most
                   FE codes). tri3 and tet4 use the unit simplex (xi >= 0,
                   sum xi <= 1) either way.

    Returns a :class:`Recovery`. Raises ValueError for arrays of the wrong
    shape or type and unknown names, :class:`SprcError` with the library's
    message for what the library rejects (node indices out of range,
    non-finite values, points outside their element, duplicate nodes or
    elements, an invalid material, a patch that stays rank deficient); its
    message names entries 0-based in C order with the C argument names
    (``gauss_weights[e][q]``, ``connectivity[e][a]`` for ``elements[e, a]``).
    """
    etype, edim, nen, nfn = _code("element_type", element_type, ELEMENT_TYPES)
    x = _doubles("nodes", nodes, (None, edim))
    nnode = x.shape[0]
    conn = _ints("elements", elements, (None, nen))
    nelem = conn.shape[0]
    if analysis is None:
        analysis = "plane_stress" if edim == 2 else "solid"
    acode = _code("analysis", analysis, ANALYSES)
    mcode = _code("method", method, METHODS) | _code("degree", degree, DEGREES)
    nstress = 3 if edim == 2 else 6
    gp = _doubles("gauss_points", gauss_points, (nelem, None, edim))
    ngp = gp.shape[1]
    gw = _doubles("gauss_weights", gauss_weights, (nelem, ngp))
    gs = _doubles("gauss_stress", gauss_stress, (nelem, ngp, nstress))
    bf = None if body_force is None else _doubles("body_force", body_force, (edim,))
    gxi = None if gauss_xi is None else _doubles("gauss_xi", gauss_xi, (nelem, ngp, edim))
    rcode = _code("reference", reference, REFERENCES)
    fn = fk = ft = None
    nfacet = 0
    if boundary is not None:
        fn, fk, ft = _facets(boundary, edim, nfn)
        nfacet = fn.shape[0]
        if nfacet == 0:
            fn = fk = ft = None
    try:
        handle = library.recover_reference(edim, acode, nnode, _ptr(x, _c_double_p), etype, nen, nelem,
                                           _ptr(conn, _c_int_p), ngp, _ptr(gp, _c_double_p), _ptr(gw, _c_double_p),
                                           _ptr(gs, _c_double_p), float(young), float(poisson), mcode,
                                           _ptr(bf, _c_double_p), nfacet, nfn, _ptr(fn, _c_int_p), _ptr(fk, _c_int_p),
                                           _ptr(ft, _c_double_p), _ptr(gxi, _c_double_p), rcode)
    except library.SprcError as e:
        # The library names the C array; the caller wrote boundary["nodes"].
        message = str(e).replace("facet_nodes[", 'boundary["nodes"][')
        raise library.SprcError(message, e.status) from None
    return Recovery(handle, element_type, edim, nstress, nnode, nelem)
