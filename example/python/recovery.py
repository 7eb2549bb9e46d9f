"""SPR-C recovery on your own mesh from Python: a distorted 4 x 2 quad4 mesh
of [0,2] x [0,1], 2x2 Gauss points, FE stresses given at the points (a smooth
field plus a jump between elements, as a piecewise FE field has). Prints the
recovered nodal stresses, the recovered field at a point and the global ZZ
estimate.

    python3 example/python/recovery.py      (after `make lib`, or with SPRC_LIBRARY set)
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
import sprc  # noqa: E402

nx, ny = 4, 2
x, y = np.meshgrid(np.linspace(0, 2, nx + 1), np.linspace(0, 1, ny + 1))
nodes = np.column_stack([x.ravel(), y.ravel()])
nodes[2 + (nx + 1) * 1] += [0.1, -0.05]                    # a distorted mesh
n = (np.arange(nx)[None, :] + (nx + 1) * np.arange(ny)[:, None]).ravel()
elements = np.column_stack([n, n + 1, n + nx + 2, n + nx + 1])   # counter-clockwise (VTK), 0-based

# 2x2 Gauss points: bilinear map of the reference points, weight * |J|.
g = 0.5 / np.sqrt(3.0)
xi = np.array([[0.5 - g, 0.5 - g], [0.5 + g, 0.5 - g], [0.5 + g, 0.5 + g], [0.5 - g, 0.5 + g]])
r, t = xi[:, 0], xi[:, 1]
shape = np.column_stack([(1 - r) * (1 - t), r * (1 - t), r * t, (1 - r) * t])          # [ngp, 4]
d_r = np.column_stack([-(1 - t), 1 - t, t, -t])
d_t = np.column_stack([-(1 - r), -r, r, 1 - r])
xe = nodes[elements]                                                                     # [nelem, 4, 2]
gauss_points = np.einsum("ga,ead->egd", shape, xe)
jac = np.stack([np.einsum("ga,ead->egd", d_r, xe), np.einsum("ga,ead->egd", d_t, xe)], axis=-1)
gauss_weights = 0.25 * np.abs(np.linalg.det(jac))

e = np.arange(len(elements))[:, None]
px, py = gauss_points[..., 0], gauss_points[..., 1]
gauss_stress = np.stack([1 + px * py + 0.05 * (e % 2), 0.5 - 0.5 * py**2 + 0 * px, 0.2 * px - 0.05 * (e % 3)],
                        axis=-1)

rec = sprc.recover(nodes, elements, "quad4", gauss_points, gauss_weights, gauss_stress,
                   young=210e3, poisson=0.3, analysis="plane_stress", method="sprc")
print("node        x        y       sxx       syy       sxy")
for i, (p, s) in enumerate(zip(nodes, rec.nodal_stress)):
    print(f"{i:4d} {p[0]:8.4f} {p[1]:8.4f} {s[0]:9.6f} {s[1]:9.6f} {s[2]:9.6f}")
print("element errors:", " ".join(f"{v:.3e}" for v in rec.element_error))
print("sigma* at (0.7, 0.4):", rec.evaluate([0.7, 0.4]))
print(f"global error estimate: {rec.global_error:.6e}")
print(f"relative error estimate (eta): {rec.eta:.6e}")
