"""SPR-C recovery of bodies in contact on your own meshes (the C entries
``sprc_recover_contact`` and friends, include/sprc.h).

>>> res = sprc.recover_contact(
...     [body0, body1],                          # dicts of sprc.recover's arguments
...     [{"slave": 0, "master": 1, "slave_facets": top, "master_facets": bottom,
...       "law": "frictionless"}])               # doctest: +SKIP
>>> res.bodies[0].nodal_stress, res.pairs[0].pressure, res.pairs[0].jump  # doctest: +SKIP
"""

import ctypes

import numpy as np

from . import library
from .recovery import (ANALYSES, DEGREES, ELEMENT_TYPES, METHODS, REFERENCES, Recovery, _c_double_p, _c_int_p,
                       _code, _doubles, _facets, _ints, _ptr)

__all__ = ["recover_contact", "ContactRecovery", "ContactPair", "CONTACT_LAWS"]

#: Contact laws of a facet (SPRC_CONTACT_*): open (a free surface), frictionless, Coulomb slip, stick.
CONTACT_LAWS = {"open": 0, "frictionless": 1, "slip": 2, "stick": 3}

_BODY_KEYS = {"nodes", "elements", "element_type", "gauss_points", "gauss_weights", "gauss_stress", "young",
              "poisson", "analysis", "body_force", "boundary", "gauss_xi", "reference"}
_PAIR_KEYS = {"slave", "master", "slave_facets", "master_facets", "law", "master_law", "mu", "slip_direction",
              "master_slip_direction", "pressure"}
#: Quadrature points per facet (the library's facet rules): by element type.
_FACET_POINTS = {"tri3": 2, "quad4": 2, "quad9": 3, "tet4": 3, "hex8": 4, "hex27": 9}


class ContactPair:
    """One pair's recovered contact tractions at the quadrature points of its
    slave facets (in facet order): ``points`` [n, dim], ``weights`` [n]
    (surface measure), ``normals`` [n, dim] (the slave's outward unit normal
    n), ``pressure`` [n] (-n.sigma*.n of the slave), ``pressure_master`` [n]
    (the master's, -n.sigma*_m.n), ``traction_tangential`` and
    ``traction_tangential_master`` [n, dim] (each on its own body),
    ``jump`` [n, dim] ((sigma*_slave - sigma*_master) n: action-reaction),
    ``pressure_fe`` (the pressure given, or None), ``slave``, ``master``."""

    def __init__(self, handle, k, dim, pair):
        n = library.get_contact_points(handle, k)
        self.slave, self.master = pair["slave"], pair["master"]
        self.points, self.normals = np.empty((n, dim)), np.empty((n, dim))
        self.weights, self.pressure, self.pressure_master = np.empty(n), np.empty(n), np.empty(n)
        self.traction_tangential, self.traction_tangential_master = np.empty((n, dim)), np.empty((n, dim))
        self.jump = np.empty((n, dim))
        library.get_contact_pair(handle, k, n, *(_ptr(a, _c_double_p) for a in (
            self.points, self.weights, self.normals, self.pressure, self.pressure_master, self.traction_tangential,
            self.traction_tangential_master, self.jump)))
        self.pressure_fe = pair.get("_pressure")

    def __repr__(self):
        return (f"<sprc.ContactPair {self.slave}->{self.master}: {len(self.weights)} points, "
                f"max |p - p_master| = {np.max(np.abs(self.pressure - self.pressure_master), initial=0):.3g}>")


class ContactRecovery:
    """The result of :func:`recover_contact`: ``bodies[i]`` a :class:`Recovery`
    of body i (nodal_stress, element_error, global_error, eta, evaluate) and
    ``pairs[k]`` a :class:`ContactPair`."""

    def __init__(self, bodies, pairs):
        self.bodies, self.pairs = bodies, pairs

    def __repr__(self):
        return f"<sprc.ContactRecovery: {len(self.bodies)} bodies, {len(self.pairs)} pairs>"


def _body(i, body):
    """The C arguments of body i (arrays kept by the caller of add_body)."""
    if not isinstance(body, dict):
        raise ValueError(f"bodies[{i}] must be a dict of sprc.recover's arguments")
    unknown = set(body) - _BODY_KEYS
    if unknown:
        raise ValueError(f"bodies[{i}] has unknown keys {sorted(unknown)} (known: {sorted(_BODY_KEYS)})")
    missing = {"nodes", "elements", "element_type", "gauss_points", "gauss_weights", "gauss_stress", "young",
               "poisson"} - set(body)
    if missing:
        raise ValueError(f"bodies[{i}] lacks {sorted(missing)}")
    name = f"bodies[{i}]"
    etype, edim, nen, nfn = _code(f"{name}['element_type']", body["element_type"], ELEMENT_TYPES)
    x = _doubles(f"{name}['nodes']", body["nodes"], (None, edim))
    conn = _ints(f"{name}['elements']", body["elements"], (None, nen))
    nelem = conn.shape[0]
    analysis = body.get("analysis") or ("plane_stress" if edim == 2 else "solid")
    acode = _code(f"{name}['analysis']", analysis, ANALYSES)
    nstress = 3 if edim == 2 else 6
    gp = _doubles(f"{name}['gauss_points']", body["gauss_points"], (nelem, None, edim))
    ngp = gp.shape[1]
    gw = _doubles(f"{name}['gauss_weights']", body["gauss_weights"], (nelem, ngp))
    gs = _doubles(f"{name}['gauss_stress']", body["gauss_stress"], (nelem, ngp, nstress))
    bf = None if body.get("body_force") is None else _doubles(f"{name}['body_force']", body["body_force"], (edim,))
    gxi = None if body.get("gauss_xi") is None else _doubles(f"{name}['gauss_xi']", body["gauss_xi"],
                                                             (nelem, ngp, edim))
    rcode = _code(f"{name}['reference']", body.get("reference", "unit"), REFERENCES)
    fn = fk = ft = None
    if body.get("boundary") is not None:
        fn, fk, ft = _facets(body["boundary"], edim, nfn)
        if fn.shape[0] == 0:
            fn = fk = ft = None
    nfacet = 0 if fn is None else fn.shape[0]
    keep = (x, conn, gp, gw, gs, bf, gxi, fn, fk, ft)
    args = (edim, acode, x.shape[0], _ptr(x, _c_double_p), etype, nen, nelem, _ptr(conn, _c_int_p), ngp,
            _ptr(gp, _c_double_p), _ptr(gw, _c_double_p), _ptr(gs, _c_double_p), float(body["young"]),
            float(body["poisson"]), _ptr(bf, _c_double_p), nfacet, nfn, _ptr(fn, _c_int_p), _ptr(fk, _c_int_p),
            _ptr(ft, _c_double_p), _ptr(gxi, _c_double_p), rcode)
    return args, keep, (body["element_type"], edim, nstress, x.shape[0], nelem, nfn)


def _laws(name, law, n):
    """Law codes [n] from one name or one per facet."""
    if isinstance(law, str):
        law = [law] * n
    law = list(law)
    if len(law) != n:
        raise ValueError(f"{name} has {len(law)} entries, need one per facet ({n}) or one name")
    return np.array([_code(f"{name}[{j}]", v, CONTACT_LAWS) for j, v in enumerate(law)], dtype=np.intc)


def _slip(name, value, n, dim):
    """Slip directions [n, dim] from one direction [dim] or one per facet."""
    arr = _doubles(name, value, (None,) * np.ndim(value))
    if arr.shape == (dim,):
        return np.ascontiguousarray(np.broadcast_to(arr, (n, dim)))
    return _doubles(name, arr, (n, dim))


def _pair(k, pair, nbody, info):
    """The C arguments of pair k."""
    if not isinstance(pair, dict):
        raise ValueError(f"pairs[{k}] must be a dict")
    unknown = set(pair) - _PAIR_KEYS
    if unknown:
        raise ValueError(f"pairs[{k}] has unknown keys {sorted(unknown)} (known: {sorted(_PAIR_KEYS)})")
    missing = {"slave", "master", "slave_facets", "master_facets", "law"} - set(pair)
    if missing:
        raise ValueError(f"pairs[{k}] lacks {sorted(missing)}")
    name = f"pairs[{k}]"
    for side in ("slave", "master"):
        b = pair[side]
        if not isinstance(b, (int, np.integer)) or isinstance(b, bool) or not 0 <= b < nbody:
            raise ValueError(f"{name}['{side}'] = {b!r} is not a body index in 0..{nbody - 1}")
    if pair["slave"] == pair["master"]:
        raise ValueError(f"{name}: slave and master are the same body {pair['slave']}")
    s_info, m_info = info[pair["slave"]], info[pair["master"]]
    dim = s_info[1]
    sf = _ints(f"{name}['slave_facets']", np.atleast_2d(pair["slave_facets"]), (None, s_info[5]))
    mf = _ints(f"{name}['master_facets']", np.atleast_2d(pair["master_facets"]), (None, m_info[5]))
    if sf.shape[0] == 0 or mf.shape[0] == 0:
        raise ValueError(f"{name} needs contact facets on both sides (slave {sf.shape[0]}, master {mf.shape[0]})")
    law = pair["law"]
    sl = _laws(f"{name}['law']", law, sf.shape[0])
    master_law = pair.get("master_law")
    if master_law is None:
        if not isinstance(law, str) and len(set(law)) > 1:
            raise ValueError(f"{name}: 'law' differs from facet to facet: give 'master_law' for the master facets")
        master_law = law if isinstance(law, str) else law[0]
    ml = _laws(f"{name}['master_law']", master_law, mf.shape[0])
    slip_law = CONTACT_LAWS["slip"]
    mu = pair.get("mu")
    if mu is None:
        if (sl == slip_law).any() or (ml == slip_law).any():
            raise ValueError(f"{name} has slip facets but no 'mu'")
        mu = 0.0
    try:
        mu = float(mu)
    except (TypeError, ValueError):
        raise ValueError(f"{name}['mu'] = {mu!r} is not a number") from None
    ss = ms = None
    direction = pair.get("slip_direction")
    if direction is not None:
        ss = _slip(f"{name}['slip_direction']", direction, sf.shape[0], dim)
    master_direction = pair.get("master_slip_direction")
    if master_direction is not None:
        ms = _slip(f"{name}['master_slip_direction']", master_direction, mf.shape[0], dim)
    elif direction is not None and np.ndim(direction) == 1:
        ms = _slip(f"{name}['slip_direction']", -np.asarray(direction, dtype=float), mf.shape[0], dim)
    if (sl == slip_law).any() and ss is None:
        raise ValueError(f"{name} has slip facets but no 'slip_direction' (the slave's slip relative to the master)")
    if (ml == slip_law).any() and ms is None:
        raise ValueError(f"{name} has slip master facets but no 'master_slip_direction' (needed when "
                         "'slip_direction' is given per facet)")
    pressure = pair.get("pressure")
    if pressure is not None:
        pressure = _doubles(f"{name}['pressure']", pressure, (sf.shape[0] * _FACET_POINTS[s_info[0]],))
    keep = (sf, sl, ss, mf, ml, ms, pressure)
    args = (int(pair["slave"]), int(pair["master"]), sf.shape[0], _ptr(sf, _c_int_p), _ptr(sl, _c_int_p),
            _ptr(ss, _c_double_p), mf.shape[0], _ptr(mf, _c_int_p), _ptr(ml, _c_int_p), _ptr(ms, _c_double_p), mu,
            _ptr(pressure, _c_double_p))
    return args, keep, pressure


#: sprc.h SPRC_CONTACT_NO_EDGES.
_NO_EDGES = 1024


def recover_contact(bodies, pairs, method="sprc", degree="auto", edges=True):
    """Recover the stresses of bodies in contact, each on your own mesh (SPR-C
    with contact-aware patches on both sides of every pair, the seed's eqs.
    103-138), and the contact tractions on the slave facets.

    bodies   a list of dicts, each with the keyword arguments of
             :func:`sprc.recover` (``nodes``, ``elements``, ``element_type``,
             ``gauss_points``, ``gauss_weights``, ``gauss_stress``, ``young``,
             ``poisson``, optional ``analysis``, ``body_force``, ``boundary``
             (the body's other boundaries), ``gauss_xi``, ``reference``).
    pairs    a list of dicts:
             ``slave``, ``master``  indices into ``bodies``;
             ``slave_facets``, ``master_facets``  [n, nfn] 0-based nodes of that
                 body, sides of its elements (as ``boundary["nodes"]``);
             ``law``  'frictionless' | 'stick' | 'slip' | 'open' (a free
                 surface), or one per slave facet; ``master_law`` the master
                 facets' (default: ``law`` when it is one name);
             ``mu``  Coulomb coefficient (needed by slip facets);
             ``slip_direction``  the slave's slip relative to the master,
                 [dim] for all or [n, dim] per slave facet (needed by slip
                 facets); ``master_slip_direction`` the master's (default: the
                 opposite of a single ``slip_direction``);
             ``pressure``  optional: your FE contact pressure at the slave
                 points [n * points per facet], kept as ``pressure_fe``.
    method   'sprc' (default; contact-aware) or 'spr' (contact ignored).
    degree   each body's patch degree, as :func:`sprc.recover`'s: 'auto'
             (default), 'p' (its element's degree) or 'p+1' (one more).
    edges    True (default): in 2D, the patches near an edge of a contact zone
             (a closed frictionless slave facet next to an open one) add the
             edge field (the pressure falls like the square root of the
             distance to the edge; its point and amplitude fitted to both
             bodies' stresses); False: polynomials only.

    Several pairs and bodies per call; a patch whose contact points belong
    to two pairs raises (give the pairs' facets apart). Returns a
    :class:`ContactRecovery`. Raises ValueError for wrong shapes, types,
    keys and names, :class:`SprcError` with the library's message (entries
    named 0-based, ``bodies[i]: gauss_weights[e][q]``,
    ``pairs[k].slave_facets[f][a]``) for what the library rejects.
    """
    mcode = _code("method", method, METHODS) | _code("degree", degree, DEGREES)
    if not isinstance(edges, (bool, np.bool_)):
        raise ValueError(f"edges = {edges!r} must be True or False")
    if not edges:
        mcode |= _NO_EDGES
    try:
        bodies, pairs = list(bodies), list(pairs)
    except TypeError:
        raise ValueError("bodies and pairs must be lists of dicts") from None
    if len(bodies) < 2 or len(pairs) < 1:
        raise ValueError(f"need at least 2 bodies and 1 pair, got {len(bodies)} and {len(pairs)}")
    body_args = [_body(i, b) for i, b in enumerate(bodies)]
    info = [b[2] for b in body_args]
    dims = {i[1] for i in info}
    if len(dims) > 1:
        raise ValueError(f"the bodies mix 2D and 3D elements ({[i[0] for i in info]})")
    pair_args = [_pair(k, p, len(bodies), info) for k, p in enumerate(pairs)]
    handle = ctypes.c_void_p(library.new_contact_input())
    result = None
    try:
        for args, _keep, _info in body_args:
            library.contact_add_body(handle, *args)
        for args, _keep, _p in pair_args:
            library.contact_add_pair(handle, *args)
        result = ctypes.c_void_p(library.recover_contact(handle, mcode))
        out_bodies = []
        for i, (etype, dim, nstress, nnode, nelem, _nfn) in enumerate(info):
            out_bodies.append(Recovery(library.get_contact_body(result, i), etype, dim, nstress, nnode, nelem))
        out_pairs = []
        for k, p in enumerate(pairs):
            out_pairs.append(ContactPair(result, k, info[p["slave"]][1], {**p, "_pressure": pair_args[k][2]}))
    except library.SprcError as e:
        raise library.SprcError(str(e).replace("facet_nodes[", 'boundary["nodes"]['), e.status) from None
    finally:
        library.delete_contact_input(ctypes.byref(handle))
        if result is not None:
            library.delete_contact_recovery(ctypes.byref(result))
    return ContactRecovery(out_bodies, out_pairs)
