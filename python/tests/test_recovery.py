"""Tests of sprc.recover: recovery on a caller's mesh through the C API.

The meshes, isoparametric maps and Gauss rules are built here in numpy (as
test/unit/recovery_caller_mesh.f90 builds them in Fortran), not with the
library: node (i, j, k) of a (q m + 1)^dim lattice on [0,1]^dim, vertex nodes
(indices multiples of q) moved by a smooth perturbation of 0.2 cell in their
interior components (sides stay planar), other nodes at the multilinear
average of their cell's vertices (straight-sided quad9 / hex27, so the
isoparametric image of a quadratic field is in Q2). Cells map by tensor
Lagrange interpolation of their lattice nodes; simplices are the Kuhn splits
of the cells, mapped affinely. The library sees the elements through the VTK
tables below: a wrong table or a wrong C-order convention breaks exactness.

Exact fields: linear (with its constant body force b = -div sigma) and
quadratic sigma = Hess(phi) + const with phi harmonic (div sigma =
grad(lap phi) = 0, compatible). Tolerance 1e-10 of the field's magnitude:
the patch solves are small least-squares / KKT systems on scaled coordinates
(condition numbers far below 1e4), so round-off stays near 1e-13.
"""

import itertools

import numpy as np
import pytest

import sprc

TOL = 1e-10

VTK = {
    "quad4": [(0, 0), (1, 0), (1, 1), (0, 1)],
    "quad9": [(0, 0), (2, 0), (2, 2), (0, 2), (1, 0), (2, 1), (1, 2), (0, 1), (1, 1)],
    "hex8": [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)],
    "hex27": [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0), (0, 0, 2), (2, 0, 2), (2, 2, 2), (0, 2, 2),
              (1, 0, 0), (2, 1, 0), (1, 2, 0), (0, 1, 0), (1, 0, 2), (2, 1, 2), (1, 2, 2), (0, 1, 2),
              (0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1),
              (0, 1, 1), (2, 1, 1), (1, 0, 1), (1, 2, 1), (1, 1, 0), (1, 1, 2), (1, 1, 1)],
}


# ---------------------------------------------------------------- exact fields

def exact(field, x):
    """Exact stress (Voigt) of a field at points x [..., dim]."""
    x = np.asarray(x, dtype=float)
    a, b = x[..., 0], x[..., 1]
    dim = x.shape[-1]
    c = x[..., 2] if dim == 3 else 0.0 * a
    if field == "linear" and dim == 2:
        s = [1 + 2 * a + 3 * b, -2 + 0.5 * a - b, 0.7 - 1.5 * a + 0.25 * b]
    elif field == "linear":
        s = [1 + 2 * a + 3 * b - c, -2 + 0.5 * a - b + 2 * c, 0.5 - a + b + 1.5 * c,
             0.7 - 1.5 * a + 0.25 * b + c, 0.3 + a - 0.5 * b + 0.2 * c, -0.4 + 0.6 * a + b - c]
    elif field == "quadratic" and dim == 2:
        # phi = x^4 - 6 x^2 y^2 + y^4 + x^3 - 3 x y^2 (harmonic); sigma = (phi_xx, phi_yy, phi_xy) + const.
        s = [12 * a**2 - 12 * b**2 + 6 * a + 1, -12 * a**2 + 12 * b**2 - 6 * a + 2, -24 * a * b - 6 * b + 0.5]
    elif field == "quadratic":
        # phi = x^4 - 6x^2y^2 + y^4 + (y^4 - 6y^2z^2 + z^4)/2 + xyz (harmonic).
        s = [12 * a**2 - 12 * b**2 + 1, -12 * a**2 + 18 * b**2 - 6 * c**2 + 2, -6 * b**2 + 6 * c**2 - 1,
             -24 * a * b + c, -12 * b * c + a + 0.5, b - 0.3]
    elif field == "traction":
        # sigma_xx, sigma_xy depend on x only: constant tractions on x = 0 and x = 1.
        s = [1 + 2 * a, -2 + 0.5 * a - b, 0.5 - a]
    else:
        raise ValueError(field)
    return np.stack(np.broadcast_arrays(*s), axis=-1)


VOIGT = {2: [[0, 2], [2, 1]], 3: [[0, 3, 5], [3, 1, 4], [5, 4, 2]]}


def body_force(field, dim):
    """b = -div sigma by central differences (exact for fields of degree <= 2)."""
    h, x0 = 0.25, np.full(dim, 0.3)
    b = np.zeros(dim)
    for j in range(dim):
        e = np.eye(dim)[j] * h
        ds = (exact(field, x0 + e) - exact(field, x0 - e)) / (2 * h)
        for i in range(dim):
            b[i] -= ds[VOIGT[dim][i][j]]
    return b


# ---------------------------------------------------------------- meshes

def gauss_1d(n):
    if n == 2:
        return 0.5 + np.array([-0.5, 0.5]) / np.sqrt(3.0), np.array([0.5, 0.5])
    return 0.5 + np.array([-0.5, 0.0, 0.5]) * np.sqrt(0.6), np.array([5.0, 8.0, 5.0]) / 18


def lagrange(q, t):
    """1D Lagrange basis on the nodes 0, 1/q, ..., 1 and its derivative."""
    if q == 1:
        return np.array([1 - t, t]), np.array([-1.0, 1.0])
    return (np.array([2 * (t - 0.5) * (t - 1), -4 * t * (t - 1), 2 * t * (t - 0.5)]),
            np.array([4 * t - 3, 4 - 8 * t, 4 * t - 1]))


def build_case(etype, m, field):
    """Mesh, points, weights*|J|, exact FE stresses and body force of a case (a dict)."""
    dim = 3 if etype in ("hex8", "hex27", "tet4") else 2
    q = 2 if etype in ("quad9", "hex27") else 1
    n = q * m + 1
    h = 1.0 / m

    def nid(ijk):
        ijk = list(ijk) + [0] * (3 - len(ijk))
        return ijk[0] + n * (ijk[1] + n * ijk[2])

    x = np.zeros((n**dim, dim))
    lattice = list(itertools.product(range(n), repeat=dim))
    for ijk in lattice:
        p = np.array(ijk, dtype=float) / (q * m)
        if all(i % q == 0 for i in ijk):
            v = [i // q for i in ijk] + [0] * (3 - dim)
            for l in range(dim):
                if 0 < v[l] < m:
                    p[l] += 0.2 * np.sin(1.7 * v[0] + 2.3 * v[1] + 3.1 * v[2] + l + 1) * h
        x[nid(ijk[::-1])] = p[::-1]   # product() varies the last index fastest: reverse to (i, j, k)
    if q == 2:
        for ijk in lattice:
            ijk = ijk[::-1]
            if all(i % 2 == 0 for i in ijk):
                continue
            around = itertools.product(*[(i,) if i % 2 == 0 else (i - 1, i + 1) for i in ijk])
            x[nid(ijk)] = np.mean([x[nid(v)] for v in around], axis=0)

    cells = [c[::-1] for c in itertools.product(range(m), repeat=dim)]
    conn, gp, gw, gxi = [], [], [], []
    if etype in VTK:
        rx, rw = gauss_1d(q + 1)
        rule = [(np.array(p[::-1]), np.prod(w)) for p, w in
                zip(itertools.product(rx, repeat=dim), itertools.product(rw, repeat=dim))]
        for cell in cells:
            o = np.array(cell) * q
            conn.append([nid(o + np.array(t)) for t in VTK[etype]])
            pts, wts = [], []
            for xi, w in rule:
                basis = [lagrange(q, t) for t in xi]
                xp, jac = np.zeros(dim), np.zeros((dim, dim))
                for loc in itertools.product(range(q + 1), repeat=dim):
                    node = x[nid(o + np.array(loc))]
                    val = np.prod([basis[r][0][loc[r]] for r in range(dim)])
                    grad = [np.prod([basis[r][1 if r == t else 0][loc[r]] for r in range(dim)])
                            for t in range(dim)]
                    xp += val * node
                    jac += np.outer(node, grad)
                pts.append(xp)
                wts.append(w * abs(np.linalg.det(jac)))
            gp.append(pts)
            gw.append(wts)
            gxi.append([xi for xi, _ in rule])
    else:
        if dim == 2:
            splits = [[(0, 0), (1, 0), (1, 1)], [(0, 0), (1, 1), (0, 1)]]
            rx = np.array([[1 / 6, 1 / 6], [2 / 3, 1 / 6], [1 / 6, 2 / 3]])
            rw = np.full(3, 1 / 6)
        else:
            splits = []
            for perm in itertools.permutations(range(3)):
                v = [np.zeros(3, int)]
                for axis in perm:
                    v.append(v[-1] + np.eye(3, dtype=int)[axis])
                splits.append([tuple(p) for p in v])
            ta, tb = 0.5854101966249685, 0.1381966011250105
            rx = np.array([[tb, tb, tb], [ta, tb, tb], [tb, ta, tb], [tb, tb, ta]])
            rw = np.full(4, 1 / 24)
        for cell in cells:
            for split in splits:
                ids = [nid(np.array(cell) + np.array(v)) for v in split]
                xs = x[ids]
                jac = (xs[1:] - xs[0]).T
                conn.append(ids)
                gp.append(xs[0] + rx @ jac.T)
                gw.append(rw * abs(np.linalg.det(jac)))
    gp = np.array(gp)
    gs = exact(field, gp)
    return dict(nodes=x, elements=np.array(conn), element_type=etype, gauss_points=gp,
                gauss_weights=np.array(gw), gauss_stress=gs, body_force=body_force(field, dim),
                field=field, dim=dim, scale=np.abs(gs).max(), gauss_xi=np.array(gxi) if gxi else None)


def recover(case, **kw):
    args = dict(young=1000.0, poisson=0.3, body_force=case["body_force"])
    args.update(kw)
    return sprc.recover(case["nodes"], case["elements"], case["element_type"], case["gauss_points"],
                        case["gauss_weights"], case["gauss_stress"], **args)


def nodal_deviation(case, rec):
    used = np.unique(case["elements"])
    return np.abs(rec.nodal_stress[used] - exact(case["field"], case["nodes"][used])).max() / case["scale"]


# ---------------------------------------------------------------- exactness

CASES = [("quad4", 4, "linear"), ("tri3", 4, "linear"), ("hex8", 3, "linear"), ("tet4", 2, "linear"),
         ("quad9", 3, "quadratic"), ("hex27", 2, "quadratic")]


@pytest.mark.parametrize("method", ["spr", "sprc"])
@pytest.mark.parametrize("etype,m,field", CASES)
def test_equilibrated_field_recovered_exactly(etype, m, field, method):
    """An equilibrated linear field on distorted quad4, hex8, tri3, tet4 meshes,
    a quadratic one on quad9 and hex27 (p = 2, the element degree): nodal
    stresses, the field at points and the estimate exact to 1e-10."""
    case = build_case(etype, m, field)
    rec = recover(case, method=method)
    nelem, nnode = len(case["elements"]), len(case["nodes"])
    assert rec.nodal_stress.shape == (nnode, 3 if case["dim"] == 2 else 6)
    assert rec.element_error.shape == (nelem,)
    assert nodal_deviation(case, rec) <= TOL
    assert rec.global_error <= TOL * case["scale"]
    assert 0.0 <= rec.eta <= TOL
    assert np.all(rec.element_error >= 0.0)
    # The field at the first point of every element: searched, and with the element named.
    pts = case["gauss_points"][:, 0, :]
    want = exact(field, pts)
    assert np.abs(rec.evaluate(pts) - want).max() <= TOL * case["scale"]
    assert np.abs(rec.evaluate(pts, elements=np.arange(nelem)) - want).max() <= TOL * case["scale"]
    assert np.abs(rec.evaluate(pts[0]) - want[0]).max() <= TOL * case["scale"]


@pytest.mark.parametrize("method", ["spr", "sprc"])
def test_degree_p_plus_1(method):
    """degree='p+1': a quadratic equilibrated field on a distorted quad4 mesh is
    recovered exactly by quadratic patches (1e-10), while the element's degree
    (linear patches) cannot represent it."""
    case = build_case("quad4", 4, "quadratic")
    assert nodal_deviation(case, recover(case, method=method, degree="p+1")) <= TOL
    assert nodal_deviation(case, recover(case, method=method)) > 1e-3


def test_degree_auto_default():
    """The default degree is 'auto': on quad9 SPR-C recovers at p+1 (the same bits as
    degree='p+1', not those of 'p'), SPR at p; on quad4 SPR-C stays at p."""
    case = build_case("quad9", 3, "quadratic")
    case["gauss_stress"] = case["gauss_stress"] + 0.05 * np.sin(5 * case["gauss_points"][..., :1])
    auto = recover(case, method="sprc")
    assert np.array_equal(auto.nodal_stress, recover(case, method="sprc", degree="p+1").nodal_stress)
    assert not np.array_equal(auto.nodal_stress, recover(case, method="sprc", degree="p").nodal_stress)
    assert np.array_equal(recover(case, method="spr").nodal_stress, recover(case, method="spr", degree="p").nodal_stress)
    quad = build_case("quad4", 3, "linear")
    quad["gauss_stress"] = quad["gauss_stress"] + 0.05 * np.sin(5 * quad["gauss_points"][..., :1])
    assert np.array_equal(recover(quad, method="sprc").nodal_stress,
                          recover(quad, method="sprc", degree="p").nodal_stress)


@pytest.mark.parametrize("etype", ["quad4", "hex8"])
def test_given_reference_coordinates(etype):
    """gauss_xi (the rule's coordinates) gives the exact field as Newton's do; a moved one
    is named in C notation; a wrong shape is a ValueError."""
    case = build_case(etype, 3, "linear")
    rec = recover(case, gauss_xi=case["gauss_xi"])
    assert nodal_deviation(case, rec) <= TOL
    bad = case["gauss_xi"].copy()
    bad[4, 1, 0] += 1e-3
    with pytest.raises(sprc.SprcError, match=r"gauss_xi\[4\]\[1\] = "):
        recover(case, gauss_xi=bad)
    with pytest.raises(ValueError, match="gauss_xi has shape"):
        recover(case, gauss_xi=case["gauss_xi"][:, 1:])
    # The same points on [-1, 1]^dim, reference="symmetric": exact as well; read as the
    # default "unit" they are outside [0, 1]^dim and the message says the convention.
    symmetric = 2.0 * case["gauss_xi"] - 1.0
    assert nodal_deviation(case, recover(case, gauss_xi=symmetric, reference="symmetric")) <= TOL
    with pytest.raises(sprc.SprcError, match=r"gauss_xi\[0\]\[0\] = .* is outside the reference cell "
                                             r"\[0, 1\]\^. \(reference 'unit', the default; 'symmetric' takes"):
        recover(case, gauss_xi=symmetric)
    outside = symmetric.copy()
    outside[0, 0, 0] = 1.5
    with pytest.raises(sprc.SprcError, match=r"outside the reference cell \[-1, 1\]\^. \(reference 'symmetric'"):
        recover(case, gauss_xi=outside, reference="symmetric")
    with pytest.raises(ValueError, match="reference = 'signed' is not one of 'unit', 'symmetric'"):
        recover(case, gauss_xi=symmetric, reference="signed")


def test_inexact_data_gives_positive_estimate():
    """The estimate is not trivially zero: a perturbed field gives eta in (0, 1)
    and element errors that sum in squares to the global error."""
    case = build_case("quad4", 4, "linear")
    case["gauss_stress"] = case["gauss_stress"] + 0.1 * np.sin(7 * case["gauss_points"][..., :1])
    rec = recover(case)
    assert 1e-4 < rec.eta < 1.0
    assert rec.global_error == pytest.approx(np.sqrt(np.sum(rec.element_error**2)), rel=1e-12)


def side_facets(case, x_value):
    """quad4 facets (line2) on the side x = x_value of the lattice mesh."""
    nodes = case["nodes"]
    on = np.flatnonzero(np.abs(nodes[:, 0] - x_value) < 1e-12)
    on = on[np.argsort(nodes[on, 1])]
    return np.stack([on[:-1], on[1:]], axis=1)


def test_traction_boundary_both_forms():
    """SPR-C with traction facets on x = 0 (t = -(1, 0.5)) and x = 1 (t = (3, -0.5)):
    exact; the dict-of-arrays and list-of-facets forms agree bit for bit; a wrong
    traction makes the estimate positive (the facets reach the library)."""
    case = build_case("quad4", 4, "traction")
    left, right = side_facets(case, 0.0), side_facets(case, 1.0)
    nodes = np.vstack([left, right[:, ::-1]])
    traction = np.vstack([np.tile([-1.0, -0.5], (len(left), 1)), np.tile([3.0, -0.5], (len(right), 1))])
    rec = recover(case, analysis="plane_strain", boundary={"nodes": nodes, "kind": "traction", "traction": traction})
    assert nodal_deviation(case, rec) <= TOL
    assert rec.eta <= TOL
    facets = [{"nodes": f, "kind": "traction", "traction": t} for f, t in zip(nodes, traction)]
    rec2 = recover(case, analysis="plane_strain", boundary=facets)
    assert np.array_equal(rec.nodal_stress, rec2.nodal_stress)
    wrong = recover(case, analysis="plane_strain", boundary={"nodes": left, "kind": "traction", "traction": [0, 0]})
    assert wrong.eta > 1e-3
    free = recover(case, analysis="plane_strain", boundary={"nodes": left, "kind": ["free"] * len(left)})
    assert free.eta > 1e-3
    # SPR ignores the facets.
    spr = recover(case, method="spr", boundary={"nodes": left, "kind": "free"})
    assert nodal_deviation(case, spr) <= TOL


def test_pressure_on_curved_facets():
    """Pressure facets (t = -p n with the facet's own normal at each point) on the
    curved outer arc of a quarter annulus of quad9 (nodes on the circles): the
    hydrostatic field -p I is recovered exactly by SPR-C, in both boundary forms;
    the best constant traction per facet (the only way before) is not exact."""
    m, p = 4, 3.0
    case = build_case("quad9", m, "linear")
    n = 2 * m + 1
    r = 1.0 + np.arange(n) / (n - 1)
    t = 0.5 * np.pi * np.arange(n) / (n - 1)
    polar = np.array([[ri * np.cos(tj), ri * np.sin(tj)] for tj in t for ri in r])
    # Rebuild points and weights on the curved mesh: the same isoparametric quad9 map.
    case["nodes"] = polar
    rx, rw = gauss_1d(3)
    gp, gw = [], []
    for el in case["elements"]:
        xe = polar[el]
        pts, wts = [], []
        for j in range(3):
            for i in range(3):
                (li, di), (lj, dj) = lagrange(2, rx[i]), lagrange(2, rx[j])
                val = np.zeros(len(el))
                grad = np.zeros((len(el), 2))
                for a, (u, v) in enumerate(VTK["quad9"]):
                    val[a] = li[u] * lj[v]
                    grad[a] = [di[u] * lj[v], li[u] * dj[v]]
                pts.append(val @ xe)
                wts.append(rw[i] * rw[j] * abs(np.linalg.det(xe.T @ grad)))
        gp.append(pts)
        gw.append(wts)
    gp, gw = np.array(gp), np.array(gw)
    gs = np.zeros(gp.shape[:2] + (3,))
    gs[..., :2] = -p
    outer = [[(n - 1) + n * 2 * k, (n - 1) + n * (2 * k + 2), (n - 1) + n * (2 * k + 1)] for k in range(m)]
    args = (polar, case["elements"], "quad9", gp, gw, gs)
    kw = dict(young=1000.0, poisson=0.3, analysis="plane_strain")
    rec = sprc.recover(*args, **kw, boundary={"nodes": outer, "kind": "pressure", "pressure": p})
    assert np.abs(rec.nodal_stress - [-p, -p, 0.0]).max() <= TOL * p
    rec2 = sprc.recover(*args, **kw, boundary=[{"nodes": f, "kind": "pressure", "pressure": p} for f in outer])
    assert np.array_equal(rec.nodal_stress, rec2.nodal_stress)
    chord = np.array([polar[f[1]] - polar[f[0]] for f in outer])
    normal = np.stack([chord[:, 1], -chord[:, 0]], axis=1) / np.linalg.norm(chord, axis=1)[:, None]
    const = sprc.recover(*args, **kw, boundary={"nodes": outer, "kind": "traction", "traction": -p * normal})
    assert np.abs(const.nodal_stress - [-p, -p, 0.0]).max() > 1e-6 * p
    with pytest.raises(ValueError, match="no 'pressure'"):
        sprc.recover(*args, **kw, boundary={"nodes": outer, "kind": "pressure"})


def test_far_from_origin():
    """Elements small against their distance from the origin (|x|/h = 1e5 here): the
    inverse map stops at its own round-off; a linear field is recovered (tolerance
    TOL times |x|/h, the round-off of the patch coordinates) and the points evaluate."""
    case = build_case("quad4", 4, "linear")
    side, shift = 1e-4, np.array([10.0, -5.0])
    rec = sprc.recover(shift + side * case["nodes"], case["elements"], "quad4", shift + side * case["gauss_points"],
                       side**2 * case["gauss_weights"], case["gauss_stress"], young=1000.0, poisson=0.3,
                       body_force=case["body_force"] / side)
    assert nodal_deviation(case, rec) <= 1e5 * TOL
    pts = shift + side * case["gauss_points"].reshape(-1, 2)
    rec.evaluate(pts, elements=np.repeat(np.arange(len(case["elements"])), 4))


# ---------------------------------------------------------------- errors

@pytest.fixture(scope="module")
def quad():
    return build_case("quad4", 2, "linear")


def call(case, **changes):
    args = {k: case[k] for k in ("nodes", "elements", "element_type", "gauss_points", "gauss_weights",
                                  "gauss_stress")}
    kw = dict(young=1000.0, poisson=0.3)
    for key, value in changes.items():
        (args if key in args else kw)[key] = value
    return sprc.recover(**args, **kw)


@pytest.mark.parametrize("changes,text", [
    (dict(element_type="quad5"), "element_type = 'quad5'"),
    (dict(element_type="hex8"), "nodes has shape [9, 2], need [*, 3]"),
    (dict(nodes=np.zeros((9, 3))), "nodes has shape [9, 3], need [*, 2]"),
    (dict(elements=np.zeros((4, 3), int)), "elements has shape [4, 3], need [*, 4]"),
    (dict(elements=np.zeros((4, 4))), "elements must hold integers"),
    (dict(elements=np.full((4, 4), 2**40)), "outside the range of a C int"),
    (dict(gauss_points=np.zeros((3, 4, 2))), "gauss_points has shape [3, 4, 2], need [4, *, 2]"),
    (dict(gauss_weights=np.ones((4, 3))), "gauss_weights has shape [4, 3], need [4, 4]"),
    (dict(gauss_stress=np.zeros((4, 4, 6))), "gauss_stress has shape [4, 4, 6], need [4, 4, 3]"),
    (dict(gauss_stress="abc"), "gauss_stress must be an array of numbers"),
    (dict(analysis="plane"), "analysis = 'plane'"),
    (dict(method="zz"), "method = 'zz'"),
    (dict(degree="p+2"), "degree = 'p+2'"),
    (dict(body_force=[1.0, 2.0, 3.0]), "body_force has shape [3], need [2]"),
    (dict(boundary={"nodes": [[0, 1]], "kind": "glued"}), "boundary kind = 'glued'"),
    (dict(boundary={"nodes": [[0, 1, 2]], "kind": "free"}), "has shape [1, 3], need [*, 2]"),
    (dict(boundary={"nodes": [[0, 1]], "kind": "traction"}), "no 'traction'"),
    (dict(boundary={"nodes": [[0, 1]], "kind": ["free", "free"]}), "1 facets but 2 kinds"),
    (dict(boundary=[{"nodes": [0, 1]}]), "'nodes' and 'kind'"),
    (dict(boundary=3), "dict of arrays or a list"),
])
def test_bad_arguments_raise_value_error(quad, changes, text):
    with pytest.raises(ValueError) as info:
        call(quad, **changes)
    assert text in str(info.value)


def test_library_errors_raise_sprc_error(quad):
    """What the library rejects arrives as SprcError with its message and status."""
    bad = quad["elements"].copy()
    bad[1, 2] = 9
    with pytest.raises(sprc.SprcError) as info:
        call(quad, elements=bad)
    assert "connectivity[1][2] = 9 is not a node in 0..8" in str(info.value)
    assert info.value.status == 1 and info.value.status_name == "invalid input"
    bad[1, 2] = -1
    with pytest.raises(sprc.SprcError, match=r"connectivity\[1\]\[2\] = -1"):
        call(quad, elements=bad)
    gs = quad["gauss_stress"].copy()
    gs[2, 1, 0] = np.nan
    with pytest.raises(sprc.SprcError, match=r"gauss_stress\[2\]\[1\] is not finite"):
        call(quad, gauss_stress=gs)
    gw = quad["gauss_weights"].copy()
    gw[0, 2] = -1.0
    # The caller's gw[0, 2], 0-based in C order (issue 13: it was named gw(3, 1)).
    with pytest.raises(sprc.SprcError, match=r"gauss_weights\[0\]\[2\] = .* must be finite and > 0"):
        call(quad, gauss_weights=gw)
    gp = quad["gauss_points"].copy()
    gp[3, 0] = gp[0, 0]  # a point of element 0 given to element 3
    with pytest.raises(sprc.SprcError, match=r"gauss_points\[3\]\[0\] is not inside element 3 "):
        call(quad, gauss_points=gp)
    nodes = np.vstack([quad["nodes"], quad["nodes"][4]])  # node 9 at node 4, used by element 3
    elements = quad["elements"].copy()
    elements[3][elements[3] == 4] = 9
    with pytest.raises(sprc.SprcError, match="nodes 4 and 9 are at the same point"):
        call(quad, nodes=nodes, elements=elements)
    elements = quad["elements"].copy()
    elements[2] = elements[0][::-1]
    with pytest.raises(sprc.SprcError, match="elements 0 and 2 have the same vertices"):
        call(quad, elements=elements)
    with pytest.raises(sprc.SprcError, match="analysis = 3 does not fit dim = 2"):
        call(quad, analysis="solid")
    with pytest.raises(sprc.SprcError, match="poisson"):
        call(quad, poisson=0.5)
    with pytest.raises(sprc.SprcError, match=r'boundary\["nodes"\]\[0\]\[1\] = 99'):
        call(quad, boundary={"nodes": [[0, 99]], "kind": "free"})
    with pytest.raises(sprc.SprcError, match="is not a side of any element"):
        call(quad, boundary={"nodes": [[0, 8]], "kind": "free"})


@pytest.mark.parametrize("facet", [[0, 4], [4, 0]])
def test_diagonal_facet_is_an_error(quad, facet):
    """Nodes 0 and 4 are opposite corners of element 0: a diagonal, not a side. It was
    accepted (and changed eta); now an error naming the caller's boundary["nodes"][i].
    A real side in either order is accepted."""
    with pytest.raises(sprc.SprcError, match=r'facet 1 is not a side of any element: boundary\["nodes"\]\[1\] = '
                                             rf'\({facet[0]} {facet[1]}\) are nodes of element 0 but not one of its '
                                             'sides'):
        call(quad, boundary={"nodes": [[1, 0], facet], "kind": "free"})
    eta = [call(quad, boundary={"nodes": [side], "kind": "free"}).eta for side in ([0, 1], [1, 0])]
    assert eta[0] == eta[1]


def test_thin_layer_reports_unknown_element_code(quad):
    """Names are checked in Python; a raw code the C API does not know (through
    sprc.library, the 1:1 layer) comes back as SprcError naming it."""
    import ctypes
    d = ctypes.POINTER(ctypes.c_double)
    arrays = [np.ascontiguousarray(quad[k], dtype=float) for k in ("nodes", "gauss_points", "gauss_weights",
                                                                   "gauss_stress")]
    conn = np.ascontiguousarray(quad["elements"], dtype=np.intc)
    x, gp, gw, gs = (a.ctypes.data_as(d) for a in arrays)
    with pytest.raises(sprc.SprcError, match="element_type = 99 is unknown"):
        sprc.library.recover(2, 1, 9, x, 99, 4, 4, conn.ctypes.data_as(ctypes.POINTER(ctypes.c_int)), 4, gp, gw, gs,
                             1000.0, 0.3, 2, None, 0, 2, None, None, None)


def test_evaluate_errors(quad):
    rec = call(quad)
    with pytest.raises(sprc.SprcError, match=r"points\[1\] = .* is in no element"):
        rec.evaluate([[0.5, 0.5], [3.0, 3.0]])
    with pytest.raises(sprc.SprcError, match=r"points\[0\] = .* is not in element 3"):
        rec.evaluate([[0.1, 0.1]], elements=[3])
    with pytest.raises(sprc.SprcError, match=r"elements\[0\] = 7 is not -1 \(search\) or an element in 0..3"):
        rec.evaluate([[0.5, 0.5]], elements=[7])
    with pytest.raises(ValueError, match=r"points has shape \[1, 3\], need \[\*, 2\]"):
        rec.evaluate([[0.5, 0.5, 0.5]])
    with pytest.raises(ValueError, match=r"elements has shape \[2\], need \[1\]"):
        rec.evaluate([[0.5, 0.5]], elements=[0, 1])
    assert rec.evaluate(np.zeros((0, 2))).shape == (0, 3)
    rec.close()
    rec.close()
    with pytest.raises(ValueError, match="closed"):
        rec.evaluate([[0.5, 0.5]])
