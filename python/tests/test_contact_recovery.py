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
