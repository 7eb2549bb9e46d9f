"""SPR-C recovery of two bodies in contact, each on its own mesh, from Python:
a block [0,2] x [-1,0] (4 x 2 quad4) pressed against a block [0,2] x [0,1]
(5 x 3 quad4, so the meshes do not match on y = 0), frictionless. The FE
stresses at the 2x2 Gauss points are a compression sigma_yy = -1 plus a
bending sigma_xx = -3 y plus an element-wise jump (as a piecewise FE field
has). Prints the recovered contact pressure of both bodies along the
interface, their jump and each body's ZZ estimate.

    python3 example/python/contact_recovery.py      (after `make lib`, or with SPRC_LIBRARY set)
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
import sprc  # noqa: E402


def block(nx, ny, y0, y1):
    """A quad4 mesh of [0, 2] x [y0, y1], its 2x2 Gauss points and FE stresses."""
    x, y = np.meshgrid(np.linspace(0, 2, nx + 1), np.linspace(y0, y1, ny + 1))
    nodes = np.column_stack([x.ravel(), y.ravel()])
    n = (np.arange(nx)[None, :] + (nx + 1) * np.arange(ny)[:, None]).ravel()
    elements = np.column_stack([n, n + 1, n + nx + 2, n + nx + 1])     # counter-clockwise (VTK), 0-based
    g = 0.5 / np.sqrt(3.0)
    r, t = np.array([0.5 - g, 0.5 + g, 0.5 + g, 0.5 - g]), np.array([0.5 - g, 0.5 - g, 0.5 + g, 0.5 + g])
    shape = np.column_stack([(1 - r) * (1 - t), r * (1 - t), r * t, (1 - r) * t])
    gauss_points = np.einsum("ga,ead->egd", shape, nodes[elements])
    area = (2.0 / nx) * ((y1 - y0) / ny)
    gauss_weights = np.full(gauss_points.shape[:2], area / 4)
    e = np.arange(len(elements))[:, None]
    py = gauss_points[..., 1]
    gauss_stress = np.stack([-3 * py + 0.05 * (e % 2), -1 + 0 * py - 0.03 * (e % 3), 0.02 * (e % 2) + 0 * py],
                            axis=-1)
    body = dict(nodes=nodes, elements=elements, element_type="quad4", gauss_points=gauss_points,
                gauss_weights=gauss_weights, gauss_stress=gauss_stress, young=210e3, poisson=0.3,
                analysis="plane_strain")
    return body, nx


def sides_on(body, nx, row):
    """The element sides along node row `row` (0: bottom), as [n, 2] node pairs."""
    first = row * (nx + 1)
    return np.column_stack([np.arange(first, first + nx), np.arange(first + 1, first + nx + 1)])


lower, nx0 = block(4, 2, -1.0, 0.0)
upper, nx1 = block(5, 3, 0.0, 1.0)
res = sprc.recover_contact(
    [lower, upper],
    [{"slave": 0, "master": 1, "slave_facets": sides_on(lower, nx0, 2), "master_facets": sides_on(upper, nx1, 0),
      "law": "frictionless"}])
pair = res.pairs[0]
print("      x   p (slave)  p (master)   jump_x     jump_y")
for x, p, pm, j in zip(pair.points, pair.pressure, pair.pressure_master, pair.jump):
    print(f"{x[0]:7.4f} {p:10.6f} {pm:10.6f} {j[0]:10.2e} {j[1]:10.2e}")
print(f"largest tangential traction (slave): {np.abs(pair.traction_tangential).max():.2e}")
for i, b in enumerate(res.bodies):
    print(f"body {i}: global error estimate {b.global_error:.6e}, eta {b.eta:.6e}")
