"""Tests of sprc.recover_contact: two bodies in contact on non-matching meshes.

The meshes are those of test_recovery.py (perturbed lattices of the unit
square): body 0 (slave) moved below y = 0 with m cells per side, body 1
(master) above it with m + 1. The stress field (x tangent, y normal to the
contact line; the same in both bodies, so continuous across it):
    sigma_xx = -delta x + alpha y, sigma_yy = -p + beta x - gamma y,
    sigma_xy = tau + gamma x + delta y,
is in equilibrium without body force, linear (compatible), and satisfies on
y = 0 the law: frictionless tau = gamma = 0; slip of the slave along +x with
|t_t| = mu p against it: tau = -mu p, gamma = mu beta; stick any. Both
recovered fields, both pressures and their jump are exact to round-off
(tolerance 1e-10 of the field's scale, as test_recovery.py's).
"""

import numpy as np
import pytest

import sprc
from test_recovery import build_case

TOL = 1e-10
MU = 0.3


def field(law, x):
    p, alpha, beta, gamma, delta, tau = 2.0, 0.7, 0.4, -0.3, 0.5, 0.6
    if law == "frictionless":
        gamma = tau = 0.0
    elif law == "slip":
        tau, gamma = -MU * p, MU * beta
    t, y = x[..., 0], x[..., 1]
    return np.stack([-delta * t + alpha * y, -p + beta * t - gamma * y, tau + gamma * t + delta * y], axis=-1)


def body(etype, m, law, shift, noise=0.0):
    case = build_case(etype, m, "linear")
    nodes = case["nodes"].copy()
    nodes[:, 1] += shift
    gp = case["gauss_points"].copy()
    gp[..., 1] += shift
    gs = field(law, gp) + noise * np.sin(7 * gp[..., :1] + 3 * gp[..., 1:2] + np.arange(3))
    return dict(nodes=nodes, elements=case["elements"], element_type=etype, gauss_points=gp,
                gauss_weights=case["gauss_weights"], gauss_stress=gs, young=1000.0, poisson=0.3)


def line_facets(b, y):
    """The element sides of a linear 2D mesh on the line y (vertex pairs)."""
    on = np.abs(b["nodes"][:, 1] - y) < 1e-12
    facets = []
    for e in b["elements"]:
        n = len(e)
        for a in range(n):
            i, j = e[a], e[(a + 1) % n]
            if on[i] and on[j]:
                facets.append([i, j])
    return np.array(facets)


def problem(law, e0="quad4", e1="tri3", m=3, noise=0.0):
    b0, b1 = body(e0, m, law, -1.0, noise), body(e1, m + 1, law, 0.0, noise)
    pair = dict(slave=0, master=1, slave_facets=line_facets(b0, 0.0), master_facets=line_facets(b1, 0.0), law=law)
    if law == "slip":
        pair.update(mu=MU, slip_direction=[1.0, 0.0])
    return [b0, b1], [pair]


@pytest.mark.parametrize("law,e0,e1", [("frictionless", "quad4", "tri3"), ("slip", "quad4", "quad4"),
                                       ("stick", "tri3", "quad4")])
def test_two_bodies_recovered_exactly(law, e0, e1):
    bodies, pairs = problem(law, e0, e1)
    res = sprc.recover_contact(bodies, pairs)
    scale = 2.0
    for b, rec in zip(bodies, res.bodies):
        assert np.abs(rec.nodal_stress - field(law, b["nodes"])).max() < TOL * scale
        assert rec.eta < TOL
    pr = res.pairs[0]
    exact_p = -field(law, pr.points)[:, 1]
    assert np.abs(pr.points[:, 1]).max() < 1e-14
    assert np.allclose(pr.normals, [0.0, 1.0])
    assert np.abs(pr.pressure - exact_p).max() < TOL * scale
    assert np.abs(pr.pressure_master - exact_p).max() < TOL * scale
    assert np.abs(pr.jump).max() < TOL * scale
    assert np.abs(pr.traction_tangential[:, 0] - field(law, pr.points)[:, 2]).max() < TOL * scale


def test_frictionless_rows_act_on_noisy_data():
    """Noisy stresses: with contact the tangential traction at the contact points is zero, without it is not."""
    bodies, pairs = problem("frictionless", "quad4", "quad4", m=4, noise=0.3)
    res = sprc.recover_contact(bodies, pairs)
    pr = res.pairs[0]
    assert np.abs(pr.traction_tangential).max() < TOL
    assert np.abs(pr.traction_tangential_master).max() < TOL
    plain = sprc.recover_contact(bodies, pairs, method="spr").pairs[0]
    assert np.abs(plain.traction_tangential).max() > 1e-3


def test_pressure_fe_kept():
    bodies, pairs = problem("frictionless")
    n = 2 * len(pairs[0]["slave_facets"])
    pairs[0]["pressure"] = np.linspace(1.0, 2.0, n)
    pr = sprc.recover_contact(bodies, pairs).pairs[0]
    assert np.array_equal(pr.pressure_fe, np.linspace(1.0, 2.0, n))


def _bad(change):
    bodies, pairs = problem("slip")
    change(bodies, pairs)
    return bodies, pairs


BAD_VALUE = [
    (lambda b, p: b.pop(), "need at least 2 bodies"),
    (lambda b, p: p.clear(), "1 pair"),
    (lambda b, p: b[1].update(element_type="quad5"), r"bodies\[1\]\['element_type'\] = 'quad5'"),
    (lambda b, p: b[0].update(gauss_weights=b[0]["gauss_weights"][:, :2]), r"bodies\[0\]\['gauss_weights'\] has shape"),
    (lambda b, p: b[0].update(colour="red"), r"bodies\[0\] has unknown keys \['colour'\]"),
    (lambda b, p: p[0].update(slave=2), r"pairs\[0\]\['slave'\] = 2 is not a body index"),
    (lambda b, p: p[0].update(master=0), "same body"),
    (lambda b, p: p[0].update(law="glued"), r"pairs\[0\]\['law'\]\[0\] = 'glued' is not one of"),
    (lambda b, p: p[0].update(law=["slip"]), r"pairs\[0\]\['law'\] has 1 entries"),
    (lambda b, p: p[0].pop("mu"), "slip facets but no 'mu'"),
    (lambda b, p: p[0].pop("slip_direction"), "slip facets but no 'slip_direction'"),
    (lambda b, p: p[0].update(slip_direction=[1.0, 0.0, 0.0]), r"slip_direction'\] has shape"),
    (lambda b, p: p[0].update(master_facets=np.zeros((0, 2), int)), "contact facets on both sides"),
    (lambda b, p: p[0].update(slave_facets=[[0, 1, 2]]), r"pairs\[0\]\['slave_facets'\] has shape"),
    (lambda b, p: p[0].update(pressure=[1.0, 2.0]), r"pairs\[0\]\['pressure'\] has shape"),
]


@pytest.mark.parametrize("change,text", BAD_VALUE)
def test_bad_arguments_raise_value_error(change, text):
    bodies, pairs = _bad(change)
    with pytest.raises(ValueError, match=text):
        sprc.recover_contact(bodies, pairs)


BAD_LIBRARY = [
    (lambda b, p: p[0].update(mu=-0.2), r"pairs\[0\]\.mu must be finite and >= 0"),
    (lambda b, p: p[0].update(mu=float("nan")), r"pairs\[0\]\.mu must be finite"),
    (lambda b, p: p[0].update(slip_direction=[float("nan"), 0.0]), r"pairs\[0\]\.slave_slip is not finite"),
    (lambda b, p: p[0].update(slave_facets=[[0, 10**6]]), r"pairs\[0\]\.slave_facets\[0\]\[1\] = 1000000"),
    (lambda b, p: p[0].update(slave_facets=[[0, 5]]),
     r"not a side of any element: pairs\[0\]\.slave_facets\[0\] = \(0 5\)"),
    (lambda b, p: p[0].update(master_facets=line_facets(b[1], 1.0)), "do not face each other"),
    (lambda b, p: b[1]["gauss_stress"].__setitem__((2, 1, 0), np.nan), r"bodies\[1\]: .*gauss_stress\[2\]\[1\]"),
    (lambda b, p: b[0].update(poisson=0.7), r"bodies\[0\]: .*poisson"),
    (lambda b, p: p[0].update(slip_direction=[0.0, 1.0]), "no part tangent"),
]


@pytest.mark.parametrize("change,text", BAD_LIBRARY)
def test_library_errors_raise_sprc_error(change, text):
    bodies, pairs = _bad(change)
    with pytest.raises(sprc.SprcError, match=text) as info:
        sprc.recover_contact(bodies, pairs)
    assert info.value.status == 1


def test_unknown_method():
    bodies, pairs = problem("frictionless")
    with pytest.raises(ValueError, match="method = 'zz'"):
        sprc.recover_contact(bodies, pairs, method="zz")


def quadratic_field(x):
    """Airy phi = x^2 y^2 - x^4 / 3 (biharmonic): sigma_xx = 2x^2, sigma_yy = 2y^2 - 4x^2,
    sigma_xy = -4xy; equilibrium, compatibility, and sigma_xy = 0 on y = 0 (frictionless)."""
    t, y = x[..., 0], x[..., 1]
    return np.stack([2 * t**2, 2 * y**2 - 4 * t**2, -4 * t * y], axis=-1)


def test_degree_p_plus_1_recovers_a_quadratic_field():
    """A quadratic field of the frictionless law on quad4 bodies: in the recovery space at
    degree 'p+1' (2), so recovered to round-off; at 'auto' (1, quad4's) it is not."""
    bodies, pairs = problem("frictionless", "quad4", "quad4", m=4)
    for b in bodies:
        b["gauss_stress"] = quadratic_field(b["gauss_points"])
    res = sprc.recover_contact(bodies, pairs, degree="p+1")
    scale = 4.0
    for b, rec in zip(bodies, res.bodies):
        assert np.abs(rec.nodal_stress - quadratic_field(b["nodes"])).max() < TOL * scale
    pr = res.pairs[0]
    assert np.abs(pr.pressure + quadratic_field(pr.points)[:, 1]).max() < TOL * scale
    assert np.abs(pr.jump).max() < TOL * scale
    low = sprc.recover_contact(bodies, pairs, degree="auto")
    assert np.abs(low.bodies[0].nodal_stress - quadratic_field(bodies[0]["nodes"])).max() > 1e-3 * scale
    assert np.array_equal(sprc.recover_contact(bodies, pairs, degree="p").bodies[0].nodal_stress,
                          low.bodies[0].nodal_stress)


def test_unknown_degree():
    bodies, pairs = problem("frictionless")
    with pytest.raises(ValueError, match=r"degree = 'p\+2'"):
        sprc.recover_contact(bodies, pairs, degree="p+2")


def edge_field(x, xe, normal):
    """Westergaard's field Z = -i sqrt(z) of a frictionless contact edge at (xe, 0), the tangent
    +x pointing from the closed side (x < xe) to the open one, the body's outward normal
    (0, normal): pressure sqrt(xe - x) on the closed side, free on the open side. Written
    here from the formulas (and checked by finite differences in the test), apart from the
    library's."""
    xi, eta = x[..., 0] - xe, np.minimum(normal * x[..., 1], 0.0)
    sq = np.conj(np.sqrt(xi + 1j * np.abs(eta)))
    at_edge = sq == 0  # the field vanishes there (eta Z' -> 0)
    z, zp = -1j * sq, np.where(at_edge, 0.0, -1j / (2 * np.where(at_edge, 1.0, sq)))
    sxx, syy, sxy = z.real - eta * zp.imag, z.real + eta * zp.imag, -eta * zp.real
    return np.stack([sxx, syy, normal * sxy], axis=-1)


def test_edge_field_is_an_elastic_contact_edge():
    """The test's edge field: equilibrium and compatibility (plane strain, by central
    differences, truncation O(d^2) against the field's scale), shear free on y = 0, pressure
    sqrt(xe - x) on the closed side and free on the open side."""
    xe, d = 0.3, 1e-4
    pts = np.array([[0.1, -0.2], [0.5, -0.05], [0.35, -0.4], [0.0, -0.01]])
    ex, ey = np.array([d, 0.0]), np.array([0.0, d])

    def f(p):
        return edge_field(p, xe, 1.0)

    div = np.stack([(f(pts + ex)[:, 0] - f(pts - ex)[:, 0] + f(pts + ey)[:, 2] - f(pts - ey)[:, 2]) / (2 * d),
                    (f(pts + ex)[:, 2] - f(pts - ex)[:, 2] + f(pts + ey)[:, 1] - f(pts - ey)[:, 1]) / (2 * d)])
    assert np.abs(div).max() < 1e-6
    # compatibility of plane strain without body force: laplacian(sxx + syy) = 0
    tr = lambda p: f(p)[:, 0] + f(p)[:, 1]  # noqa: E731
    lap = (tr(pts + ex) + tr(pts - ex) + tr(pts + ey) + tr(pts - ey) - 4 * tr(pts)) / d**2
    assert np.abs(lap).max() < 1e-4
    s = np.linspace(-0.5, 0.5, 11)
    surf = f(np.stack([xe + s, np.zeros_like(s)], axis=1))
    assert np.abs(surf[:, 2]).max() == 0.0
    assert np.allclose(-surf[:, 1], np.sqrt(np.maximum(-s, 0.0)), rtol=0, atol=1e-15)
    # the master's (outward normal -y, the body above): the same pressure, its shear sign flipped
    up = edge_field(np.stack([xe + s, np.zeros_like(s)], axis=1), xe, -1.0)
    assert np.array_equal(up[:, :2], surf[:, :2])


def test_contact_edge_field_recovered():
    """Two quad4 bodies, the contact closed for x < xe = 0.55 (inside a slave facet), open
    beyond; the FE stresses are the edge field plus a uniform sigma_xx (free on the open
    side). The edge's point is fitted by golden sections to |delta| <= 0.25 L 0.618^30 =
    7e-8 L, so the pressure on the closed facets near the edge (within 2 L of the facet's
    vertex) is exact up to sqrt(|delta|) = 2.6e-4 sqrt(L) (the square root is 1/2-Hoelder,
    K = 1): checked at 1e-3 sqrt(L). Without the edge field the linear patches miss the
    square root by much more (the best line through sqrt on [0, L] is off by sqrt(L)/8):
    checked above 1e-2 sqrt(L)."""
    xe, m = 0.55, 6
    b0, b1 = body("quad4", m, "frictionless", -1.0), body("quad4", m + 1, "frictionless", 0.0)
    for b, nrm in ((b0, 1.0), (b1, -1.0)):
        b["gauss_stress"] = edge_field(b["gauss_points"], xe, nrm) + np.array([0.2, 0.0, 0.0])
    sf, mf = line_facets(b0, 0.0), line_facets(b1, 0.0)
    length = 1.0 / m
    law = ["frictionless" if b0["nodes"][f, 0].min() < xe else "open" for f in sf]
    vertex = max(b0["nodes"][f, 0].max() for f, lw in zip(sf, law) if lw != "open")
    mlaw = ["frictionless" if b1["nodes"][f, 0].min() < vertex else "open" for f in mf]
    pairs = [dict(slave=0, master=1, slave_facets=sf, master_facets=mf, law=law, master_law=mlaw)]
    errs = []
    for edges in (True, False):
        pr = sprc.recover_contact([b0, b1], pairs, edges=edges).pairs[0]
        x = pr.points[:, 0]
        near = (x < vertex) & (x > vertex - 2 * length)
        errs.append(np.abs(pr.pressure - np.sqrt(np.maximum(xe - x, 0.0)))[near].max() / np.sqrt(length))
    assert errs[0] < 1e-3, errs
    assert errs[1] > 1e-2, errs


def test_edges_must_be_bool():
    bodies, pairs = problem("frictionless")
    with pytest.raises(ValueError, match="edges = 'no'"):
        sprc.recover_contact(bodies, pairs, edges="no")
