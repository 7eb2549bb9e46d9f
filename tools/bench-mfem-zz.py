#!/usr/bin/env python3
"""Optional yardstick (never in `make test`): MFEM's Zienkiewicz-Zhu estimator, timed on the
quarter annulus 5 <= r <= 20 of N x N quad4 elements used by example/bench/bench_mesh_recovery,
or (word `square`) on its axis-aligned N x N unit square (`quad4 squareN` there), or (word
`cube`) on its N^3 hex8 lattice of the unit cube (`hex8 cubeN` there: ties in every coordinate).

Needs PyMFEM (`pip install mfem`, serial). The displacement is the Lame solution interpolated at
the nodes (pressure 1 inside, E = 1000, nu = 0.3, plane strain), so the estimator sees the same
kind of field as sprc's benchmark. MFEM's flux space is H1 of the same order, as in its example 21.
On the square the displacement is the smooth field u = 1e-3 (x^2 y, x y^2 + x) (no Lame solution
there: the square holds the origin); on the cube u = 1e-3 (x^2 y, y^2 z + x, z^2 x + y).
Usage: OMP_NUM_THREADS=1 python3 tools/bench-mfem-zz.py [N [RUNS [annulus|square|cube]]]  (an N x N mesh;
default 512, 5 runs, the annulus).
Compare its cpu median with the cpu column of bench_mesh_recovery: on a shared machine CPU time is
the figure that load does not inflate.

Scope of the clock: only est.GetLocalErrors(), i.e. ZZErrorEstimator (fem/gridfunc.cpp): the FE
flux of every element from u (ComputeElementFlux), its average at the flux space's nodes
(ComputeFlux: nodal averaging, no least squares) and each element's energy of the difference
(ComputeFluxEnergy). The mesh's topology (FinalizeQuadMesh: edges, element-to-vertex tables), the
FE spaces' dof tables and the displacement are built before the clock starts, and MFEM checks no
input. sprc's recover_on_mesh starts from raw arrays: its cpu column includes the input checks and
the topology it builds; its cpu-set column leaves them out (the like-for-like figure).
"""
import sys
import time

import mfem.ser as mfem
import numpy as np

R_IN, R_OUT, YOUNG, NU = 5.0, 20.0, 1000.0, 0.3


def annulus(nr, nt):
    mesh = mfem.Mesh(2, (nr + 1) * (nt + 1), nr * nt, 0, 2)
    for j in range(nt + 1):
        t = 0.5 * np.pi * j / nt
        for i in range(nr + 1):
            r = R_IN + (R_OUT - R_IN) * i / nr
            mesh.AddVertex([r * np.cos(t), r * np.sin(t)])
    for j in range(nt):
        for i in range(nr):
            n0 = j * (nr + 1) + i
            mesh.AddQuad([n0, n0 + 1, n0 + nr + 2, n0 + nr + 1])
    mesh.FinalizeQuadMesh(1, 1, True)
    return mesh


def square(n):
    mesh = mfem.Mesh(2, (n + 1) * (n + 1), n * n, 0, 2)
    for j in range(n + 1):
        for i in range(n + 1):
            mesh.AddVertex([i / n, j / n])
    for j in range(n):
        for i in range(n):
            n0 = j * (n + 1) + i
            mesh.AddQuad([n0, n0 + 1, n0 + n + 2, n0 + n + 1])
    mesh.FinalizeQuadMesh(1, 1, True)
    return mesh


class Smooth(mfem.VectorPyCoefficient):
    """A smooth displacement on the unit square."""

    def EvalValue(self, x):
        return [1e-3 * x[0] ** 2 * x[1], 1e-3 * (x[0] * x[1] ** 2 + x[0])]


def cube(n):
    return mfem.Mesh.MakeCartesian3D(n, n, n, mfem.Element.HEXAHEDRON, 1.0, 1.0, 1.0)


class Smooth3(mfem.VectorPyCoefficient):
    """A smooth displacement on the unit cube."""

    def EvalValue(self, x):
        return [1e-3 * x[0] ** 2 * x[1], 1e-3 * (x[1] ** 2 * x[2] + x[0]), 1e-3 * (x[2] ** 2 * x[0] + x[1])]


class Lame(mfem.VectorPyCoefficient):
    """Plane-strain Lame displacement of the thick cylinder under unit inner pressure."""

    def EvalValue(self, x):
        a = R_IN**2 / (R_OUT**2 - R_IN**2)
        b = a * R_OUT**2
        r = np.hypot(x[0], x[1])
        ur = (1 + NU) / YOUNG * ((1 - 2 * NU) * a * r + b / r)
        return [ur * x[0] / r, ur * x[1] / r]


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 512
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    kind = sys.argv[3] if len(sys.argv) > 3 else "annulus"
    dim = 3 if kind == "cube" else 2
    mesh = {"square": square, "cube": cube}.get(kind, lambda m: annulus(m, m))(n)
    fec = mfem.H1_FECollection(1, dim)
    fes = mfem.FiniteElementSpace(mesh, fec, dim)
    u = mfem.GridFunction(fes)
    u.ProjectCoefficient({"square": Smooth(2), "cube": Smooth3(3)}.get(kind, Lame(2)))
    lam = YOUNG * NU / ((1 + NU) * (1 - 2 * NU))
    mu = YOUNG / (2 * (1 + NU))
    lam_c, mu_c = mfem.ConstantCoefficient(lam), mfem.ConstantCoefficient(mu)
    integ = mfem.ElasticityIntegrator(lam_c, mu_c)
    flux_fes = mfem.FiniteElementSpace(mesh, fec, dim * (dim + 1) // 2)
    times, cpus = [], []
    for _ in range(runs):
        est = mfem.ZienkiewiczZhuEstimator(integ, u, flux_fes)
        t0, c0 = time.perf_counter(), time.process_time()
        est.GetLocalErrors()  # computes the flux, its H1 projection and the element errors
        times.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        total = est.GetTotalError()
    print("scope: est.GetLocalErrors() only (element fluxes from u, nodal averaging, element errors); "
          "mesh topology, FE spaces and u built before the clock")
    print(f"MFEM ZZ, {kind}, {mesh.GetNE()} {'hex8' if dim == 3 else 'quad4'}: median {1e3 * float(np.median(times)):.1f} ms "
          f"(min {1e3 * min(times):.1f}, max {1e3 * max(times):.1f}), cpu median {1e3 * float(np.median(cpus)):.1f} ms, "
          f"over {runs} runs; eta = {total:.6e}")


if __name__ == "__main__":
    main()
