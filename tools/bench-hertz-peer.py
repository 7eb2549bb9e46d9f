#!/usr/bin/env python3
"""Benchmark (never in `make test`): a peer FE code's Hertz roller fed to sprc's caller's-mesh
contact recovery. Kratos Multiphysics (ALM mortar contact, Q4, a conforming mesh graded towards
the contact; tools/hertz-peer-kratos.py) solves the roller of example/scenes/hertz_cylinder.nml;
its integration-point stresses go to `sprc.recover_contact` (SPR-C, both bodies, the contact
facets frictionless where Kratos' contact is active, open elsewhere) and to `sprc.recover`
(plain SPR of the roller). Printed per mesh size h = a/N: the relative L2 error of the contact
pressure against Hertz over the slave contact facets (the rim within 4a of the first point of
contact; Hertz is 0 beyond a) of Kratos' own pressure (its nodal ALM pressure, linear along
the facets), of SPR's and of SPR-C's (-n.sigma*.n at the facets' Gauss points), and the cost:
median wall time of the contact recovery against the two bodies' SPR-C recoveries without
contact (the same calls without the pairs), with the thread count.

Usage: python3 tools/bench-hertz-peer.py [N ...] [--runs R] [--degree D] [--bands] [--fixture PATH]
  N          mesh sizes h = a/N (default 6 12 24);
  --runs     timing repetitions (default 7);
  --degree   SPR-C's patch degree, sprc.recover_contact's: auto (default), p or p+1;
  --bands    also the squared errors per band of x/a (where the error sits: the
             contact edge x -> a against the interior);
  --fixture  also write the fixture of the first N there (write_fixture;
             python/tests/data/hertz_kratos_a12.npz is N = 12).
Needs libsprc (`make lib`) and a Python with Kratos: $KRATOS_PYTHON, default
.kratos-venv/bin/python (python3 -m venv .kratos-venv; .kratos-venv/bin/pip install
KratosMultiphysics KratosStructuralMechanicsApplication
KratosContactStructuralMechanicsApplication KratosLinearSolversApplication). Kratos' data are
cached in build/bench-hertz-peer/.
"""
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))
import sprc  # noqa: E402

E, NU, P_HALF = 1000.0, 0.3, 0.54


def hertz(x, a):
    p0 = 2.0 * (2.0 * P_HALF) / (np.pi * a)
    return p0 * np.sqrt(np.maximum(0.0, 1.0 - (x / a) ** 2))


def bodies_and_pair(d):
    """sprc's arguments from the peer's data (module notes)."""
    def facets(name):
        return np.asarray(d[name], dtype=np.int64).reshape(-1, 2)

    def body(name, boundary):
        return dict(nodes=d[f"{name}_nodes"], elements=d[f"{name}_elements"], element_type="quad4",
                    gauss_points=d[f"{name}_gauss_points"], gauss_weights=d[f"{name}_gauss_weights"],
                    gauss_stress=d[f"{name}_gauss_stress"], young=E, poisson=NU, analysis="plane_strain",
                    boundary=boundary)

    rb = [facets("roller_sym"), facets("roller_top"), facets("roller_free")]
    roller = body("roller", {"nodes": np.vstack(rb), "kind": ["symmetry"] * len(rb[0]) + ["traction"] * len(rb[1])
                             + ["free"] * len(rb[2]),
                             "traction": np.vstack([np.zeros((len(rb[0]), 2)), np.tile([0.0, -P_HALF], (len(rb[1]), 1)),
                                                    np.zeros((len(rb[2]), 2))])})
    bb = [facets("block_sym"), facets("block_right"), facets("block_free")]
    block = body("block", {"nodes": np.vstack(bb), "kind": ["symmetry"] * len(bb[0]) + ["free"] * (len(bb[1])
                                                                                               + len(bb[2]))})
    p_node = fe_nodal_pressure(d)
    sf, mf = facets("roller_contact"), facets("block_contact")
    # Kratos' active zone: slave facets with a node in contact; master facets under them
    active = (p_node[sf] > 0).any(axis=1)
    reach = d["roller_nodes"][sf[active]][:, :, 0].max()
    law = ["frictionless" if a else "open" for a in active]
    master_law = ["frictionless" if d["block_nodes"][f, 0].min() < reach else "open" for f in mf]
    pair = dict(slave=0, master=1, slave_facets=sf, master_facets=mf, law=law, master_law=master_law)
    return roller, block, pair


def fe_nodal_pressure(d):
    """Kratos' contact pressure at the roller's nodes (compression positive)."""
    return d["roller_pressure"]


def fe_pressure_at(d, facets, points):
    """Kratos' nodal pressure, linear along each slave facet, at the facets' points (in order)."""
    p_node = fe_nodal_pressure(d)
    x = d["roller_nodes"]
    nq = len(points) // len(facets)
    out = np.empty(len(points))
    for f, (i, j) in enumerate(facets):
        for q in range(nq):
            y = points[f * nq + q]
            t = np.dot(y - x[i], x[j] - x[i]) / np.dot(x[j] - x[i], x[j] - x[i])
            out[f * nq + q] = (1 - t) * p_node[i] + t * p_node[j]
    return out


def rel_l2(p, p_ex, w):
    return np.sqrt(np.sum(w * (p - p_ex) ** 2) / np.sum(w * p_ex**2))


BANDS = (0.0, 0.5, 0.8, 0.9, 1.0, 1.1, 1.3, 4.0)


def errors(d, degree="auto", bands=False):
    """Relative L2 errors of the pressure: Kratos', SPR's, SPR-C's; and the max |p_s - p_m|.
    With `bands`, also the rows of the squared relative errors per band of x/a."""
    roller, block, pair = bodies_and_pair(d)
    res = sprc.recover_contact([roller, block], [pair], method="sprc", degree=degree)
    c = res.pairs[0]
    p_ex = hertz(c.points[:, 0], float(d["a"]))
    spr = sprc.recover(**{k: v for k, v in roller.items() if k != "boundary"}, method="spr")
    s = spr.evaluate(c.points)
    n = c.normals
    p_spr = -(s[:, 0] * n[:, 0] ** 2 + s[:, 1] * n[:, 1] ** 2 + 2 * s[:, 2] * n[:, 0] * n[:, 1])
    p_fe = fe_pressure_at(d, pair["slave_facets"], c.points)
    out = (rel_l2(p_fe, p_ex, c.weights), rel_l2(p_spr, p_ex, c.weights), rel_l2(c.pressure, p_ex, c.weights),
           np.max(np.abs(c.pressure - c.pressure_master)) / p_ex.max())
    if not bands:
        return out
    s = c.points[:, 0] / float(d["a"])
    den = np.sum(c.weights * p_ex**2)
    rows = []
    for lo, hi in zip(BANDS[:-1], BANDS[1:]):
        m = (s >= lo) & (s < hi)
        rows.append((lo, hi) + tuple(np.sum(c.weights[m] * (p - p_ex)[m] ** 2) / den for p in (p_fe, p_spr,
                                                                                              c.pressure)))
    return out, rows


def timing(d, runs, degree="auto"):


    """Median wall times: the contact recovery; the two bodies' SPR-C recoveries without contact."""
    roller, block, pair = bodies_and_pair(d)
    t_contact, t_plain = [], []
    for _ in range(runs):
        t0 = time.perf_counter()
        sprc.recover_contact([roller, block], [pair], method="sprc", degree=degree)
        t1 = time.perf_counter()
        sprc.recover(**roller, method="sprc")
        sprc.recover(**block, method="sprc")
        t2 = time.perf_counter()
        t_contact.append(t1 - t0)
        t_plain.append(t2 - t1)
    return np.median(t_contact), np.median(t_plain)


def write_fixture(d, path, radius=0.3):
    """The fixture of python/tests/test_hertz_peer.py: the elements of both bodies within
    `radius` of the first point of contact (6a: the patches, and their Omega_aux, of the
    points in the 4a window lie well inside), Kratos' stresses in single precision, the
    facets cut to the subset, and Kratos' pressure at the roller's contact nodes. The test
    rebuilds the 2x2 Gauss points and weights from the nodes (Kratos' points are those of
    that rule, matched at 1e-9 by tools/hertz-peer-kratos.py)."""
    out = {"a": d["a"], "h": d["h"]}
    for name in ("roller", "block"):
        x, el = d[f"{name}_nodes"], d[f"{name}_elements"]
        keep = np.linalg.norm(x[el], axis=2).max(axis=1) < radius
        used = np.unique(el[keep])
        new = -np.ones(len(x), dtype=np.int64)
        new[used] = np.arange(len(used))
        out[f"{name}_nodes"] = x[used]
        out[f"{name}_elements"] = new[el[keep]].astype(np.int32)
        out[f"{name}_gauss_stress"] = d[f"{name}_gauss_stress"][keep].astype(np.float32)
        for key in [k for k in d.files if k.startswith(name + "_") and k[len(name) + 1:] in
                    ("sym", "top", "free", "right", "contact")]:
            f = np.asarray(d[key]).reshape(-1, 2)
            f = f[(new[f] >= 0).all(axis=1)] if len(f) else f
            out[key] = new[f].astype(np.int32).reshape(-1, 2)
        if name == "roller":
            out["roller_pressure"] = d["roller_pressure"][used]
    np.savez_compressed(path, **out)


def peer_data(n, cache):
    path = cache / f"hertz_kratos_a{n}.npz"
    if not path.exists():
        py = os.environ.get("KRATOS_PYTHON", str(ROOT / ".kratos-venv" / "bin" / "python"))
        out = subprocess.run([py, str(ROOT / "tools" / "hertz-peer-kratos.py"), str(n), str(path)],
                             capture_output=True, text=True)
        if out.returncode != 0:
            sys.exit(f"Kratos run failed (h = a/{n}):\n{out.stdout[-2000:]}\n{out.stderr[-2000:]}")
        print(out.stdout.strip().splitlines()[-1])
    return path


def main():
    args, runs, fixture, degree, bands = [], 7, None, "auto", False
    argv = sys.argv[1:]
    while argv:
        a = argv.pop(0)
        if a == "--runs":
            runs = int(argv.pop(0))
        elif a == "--degree":
            degree = argv.pop(0)
        elif a == "--bands":
            bands = True
        elif a == "--fixture":
            fixture = argv.pop(0)
        else:
            args.append(int(a))
    sizes = args or [6, 12, 24]
    cache = ROOT / "build" / "bench-hertz-peer"
    cache.mkdir(parents=True, exist_ok=True)
    threads = os.environ.get("OMP_NUM_THREADS", "all")
    print(f"Hertz roller, Kratos ALM mortar (Q4, graded) -> sprc (degree {degree}); OMP_NUM_THREADS={threads}, "
          f"{runs} runs")
    print("| h | Q4 (roller + block) | err_p Kratos | err_p SPR | err_p SPR-C | max|p_s-p_m|/p0 | contact [ms] "
          "| 2 bodies [ms] | ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    band_rows = []
    for n in sizes:
        path = peer_data(n, cache)
        d = np.load(path)
        if fixture and n == sizes[0]:
            write_fixture(d, fixture)
        if bands:
            (e_fe, e_spr, e_sprc, jump), rows = errors(d, degree, bands=True)
            band_rows.append((n, rows))
        else:
            e_fe, e_spr, e_sprc, jump = errors(d, degree)
        tc, tp = timing(d, runs, degree)
        ne = f"{len(d['roller_elements'])} + {len(d['block_elements'])}"
        print(f"| a/{n} | {ne} | {100 * e_fe:.2f} % | {100 * e_spr:.2f} % | {100 * e_sprc:.2f} % | {jump:.2e} "
              f"| {1e3 * tc:.1f} | {1e3 * tp:.1f} | {tc / tp:.2f} |")


    for n, rows in band_rows:
        print(f"\nh = a/{n}: squared relative L2 error x 1e4 per band of x/a (they sum to the squares above)")
        print("| x/a | Kratos | SPR | SPR-C |")
        print("|---|---|---|---|")
        for lo, hi, e1, e2, e3 in rows:
            print(f"| [{lo:g}, {hi:g}) | {1e4 * e1:.3f} | {1e4 * e2:.3f} | {1e4 * e3:.3f} |")


if __name__ == "__main__":
    main()
