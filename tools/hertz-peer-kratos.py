#!/usr/bin/env python3
"""The peer's side of tools/bench-hertz-peer (never in `make test`): the Hertz roller of
example/scenes/hertz_cylinder.nml solved by Kratos Multiphysics (ALM mortar contact,
frictionless, small-displacement Q4 elements, plane strain) on a conforming Q4 mesh graded
towards the contact, written to an .npz as a caller's FE code would hand its data to sprc:
nodes, elements, integration points, weight*|J|, Cauchy stresses at the points (Kratos'
CAUCHY_STRESS_VECTOR), boundary and contact facets, and Kratos' own contact pressure at the
slave nodes.

Run it with a Python that has Kratos (pip install KratosMultiphysics
KratosStructuralMechanicsApplication KratosContactStructuralMechanicsApplication
KratosLinearSolversApplication, in its own venv):
    .kratos-venv/bin/python tools/hertz-peer-kratos.py H_OVER_A OUT.npz [GROWTH]
H_OVER_A = 12 gives h = a/12 at the contact.

The set-up (hertz_cylinder.nml): roller = the quarter of the disk of centre (0, 1), radius 1,
with x >= 0 and y <= 1, traction (0, -0.54) on its top y = 1; block [0, 1] x [-1, 0], fixed at
y = -1; symmetry (u_x = 0) on x = 0 of both; E = 1000, nu = 0.3; the roller (slave) is held in
y only by the contact. Hertz: a = 0.05003, p0 = 13.74.

Mesh: the block is a tensor product of graded spacings (h up to 2a from the contact point,
then growing by GROWTH, default 1.15); the roller a transfinite (Coons) map of the same
spacings onto its four sides (the arc split at 45 degrees), so that the rim's nodes near the
contact lie over the block's (h along the arc). Far from the contact the cells are long
and thin (aspect ratio up to ~1/(GROWTH-1)h); the contact zone has square cells of size h.
"""
import json
import os
import sys
import tempfile

import numpy as np

E, NU, P_HALF, R = 1000.0, 0.3, 0.54, 1.0
#: Pseudo-time steps, each with the whole load: Kratos' first Newton solve may stop on an
#: active set that leaves penetrating nodes inactive (at h = a/12: active up to 0.83a, a
#: pressure spike at its edge, 1e-4 penetration beyond); each step restarts the active-set
#: iteration from the last one, and four give the same active set as eight.
STEPS = 4
E_STAR = E / (2.0 * (1.0 - NU**2))
A_HERTZ = np.sqrt(4.0 * (2.0 * P_HALF) * R / (np.pi * E_STAR))


def graded(length, h, fine, growth):
    """Node positions 0 .. length: steps h up to `fine`, then growing by `growth`."""
    x = [0.0]
    while x[-1] < fine - 1e-12 * fine:
        x.append(x[-1] + h)
    nf = len(x) - 1
    step = h
    while x[-1] < length:
        step *= growth
        x.append(x[-1] + step)
    x = np.array(x)
    x[nf:] = x[nf] + (x[nf:] - x[nf]) * (length - x[nf]) / (x[-1] - x[nf])
    return x


def quads(ni, nj, offset=0):
    """Counter-clockwise quads of an (ni+1) x (nj+1) lattice numbered i + (ni+1) j."""
    el = []
    for j in range(nj):
        for i in range(ni):
            n0 = offset + i + (ni + 1) * j
            el.append([n0, n0 + 1, n0 + ni + 2, n0 + ni + 1])
    return np.array(el, dtype=np.int64)


def build_mesh(h, growth, window):
    """Both bodies' nodes, quads and facets (0-based node numbers of each body)."""
    fine = 2.0 * A_HERTZ
    # roller: Coons map with corners A = (0,0), P = arc at 45 deg, B = (1,1), C = (0,1)
    s = graded(np.pi / 4, h, fine, growth)
    u = s / s[-1]
    v = graded(1.0, h, fine, growth)
    v = v / v[-1]
    arc = lambda phi: np.stack([np.sin(phi), 1.0 - np.cos(phi)], axis=-1)
    A, P, B, C = np.array([0.0, 0.0]), arc(np.pi / 4), np.array([1.0, 1.0]), np.array([0.0, 1.0])
    AP, PB = arc(u * np.pi / 4), arc(np.pi / 4 + v * np.pi / 4)
    CB = np.stack([u, np.ones_like(u)], axis=-1)
    AC = np.stack([np.zeros_like(v), v], axis=-1)
    U, V = np.meshgrid(u, v)  # [j, i]
    U, V = U[..., None], V[..., None]
    X = ((1 - V) * AP[None, :, :] + V * CB[None, :, :] + (1 - U) * AC[:, None, :] + U * PB[:, None, :]
         - ((1 - U) * (1 - V) * A + U * (1 - V) * P + U * V * B + (1 - U) * V * C))
    ni, nj = len(u) - 1, len(v) - 1
    rn = X.reshape(-1, 2)
    rn[np.abs(rn[:, 0]) < 1e-15, 0] = 0.0
    rel = quads(ni, nj)
    lat = lambda i, j: i + (ni + 1) * j
    rim = [[lat(i, 0), lat(i + 1, 0)] for i in range(ni)] + [[lat(ni, j), lat(ni, j + 1)] for j in range(nj)]
    roller = dict(nodes=rn, elements=rel,
                  sym=[[lat(0, j + 1), lat(0, j)] for j in range(nj)],
                  top=[[lat(i + 1, nj), lat(i, nj)] for i in range(ni)],
                  contact=[f for f in rim if rn[f, 0].max() <= window],
                  free=[f for f in rim if rn[f, 0].max() > window])
    # block: tensor product, x graded from 0, y graded down from 0
    xs = graded(1.0, h, fine, growth)
    ys = -graded(1.0, h, fine, growth)[::-1]
    mi, mj = len(xs) - 1, len(ys) - 1
    bn = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    bel = quads(mi, mj)
    latb = lambda i, j: i + (mi + 1) * j
    top = [[latb(i + 1, mj), latb(i, mj)] for i in range(mi)]
    block = dict(nodes=bn, elements=bel,
                 sym=[[latb(0, j + 1), latb(0, j)] for j in range(mj)],
                 right=[[latb(mi, j), latb(mi, j + 1)] for j in range(mj)],
                 bottom=[[latb(i, 0), latb(i + 1, 0)] for i in range(mi)],
                 contact=[f for f in top if bn[f, 0].max() <= window],
                 free=[f for f in top if bn[f, 0].max() > window])
    for b in (roller, block):
        x = b["nodes"][b["elements"]]
        area = 0.5 * ((x[:, 2, 0] - x[:, 0, 0]) * (x[:, 3, 1] - x[:, 1, 1])
                      - (x[:, 3, 0] - x[:, 1, 0]) * (x[:, 2, 1] - x[:, 0, 1]))
        assert np.all(area > 0), "mesh: a quad is not counter-clockwise"
    return roller, block


def gauss_2x2(x):
    """Points and weight*|J| of the 2x2 Gauss rule in quads x [ne, 4, 2]."""
    g = 1.0 / np.sqrt(3.0)
    pts, wts = [], []
    for xi, eta in [(-g, -g), (g, -g), (g, g), (-g, g)]:
        N = 0.25 * np.array([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta), (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)])
        dxi = 0.25 * np.array([-(1 - eta), (1 - eta), (1 + eta), -(1 + eta)])
        deta = 0.25 * np.array([-(1 - xi), -(1 + xi), (1 + xi), (1 - xi)])
        pts.append(np.einsum("a,ead->ed", N, x))
        jx, jy = np.einsum("a,ead->ed", dxi, x), np.einsum("a,ead->ed", deta, x)
        wts.append(jx[:, 0] * jy[:, 1] - jx[:, 1] * jy[:, 0])
    return np.stack(pts, axis=1), np.stack(wts, axis=1)


def write_mdpa(path, roller, block):
    nr = len(roller["nodes"])
    lines = ["Begin ModelPartData", "End ModelPartData", "Begin Properties 1", "End Properties",
             "Begin Properties 2", "End Properties", "Begin Nodes"]
    for k, x in enumerate(np.vstack([roller["nodes"], block["nodes"]])):
        lines.append(f"{k + 1} {x[0]:.17g} {x[1]:.17g} 0.0")
    lines += ["End Nodes", "Begin Elements SmallDisplacementElement2D4N"]
    ne_r = len(roller["elements"])
    for k, e in enumerate(roller["elements"]):
        lines.append(f"{k + 1} 1 " + " ".join(str(n + 1) for n in e))
    for k, e in enumerate(block["elements"]):
        lines.append(f"{ne_r + k + 1} 2 " + " ".join(str(n + nr + 1) for n in e))
    lines += ["End Elements", "Begin Conditions LineLoadCondition2D2N"]
    for k, f in enumerate(roller["top"]):
        lines.append(f"{k + 1} 1 {f[0] + 1} {f[1] + 1}")
    lines.append("End Conditions")

    def smp(name, nodes, elements=(), conditions=()):
        out = [f"Begin SubModelPart {name}", "Begin SubModelPartNodes"]
        out += [str(n + 1) for n in sorted(set(nodes))]
        out += ["End SubModelPartNodes", "Begin SubModelPartElements"]
        out += [str(e + 1) for e in elements]
        out += ["End SubModelPartElements", "Begin SubModelPartConditions"]
        out += [str(c + 1) for c in conditions]
        out += ["End SubModelPartConditions", f"End SubModelPart"]
        return out

    flat = lambda facets, off=0: [n + off for f in facets for n in f]
    lines += smp("Parts_roller", range(nr), range(ne_r))
    lines += smp("Parts_block", range(nr, nr + len(block["nodes"])), range(ne_r, ne_r + len(block["elements"])))
    lines += smp("Symmetry", flat(roller["sym"]) + flat(block["sym"], nr))
    lines += smp("Fixed", flat(block["bottom"], nr))
    lines += smp("Load", flat(roller["top"]), (), range(len(roller["top"])))
    # Kratos' contact surfaces: a wider window than the recovery's (its search needs room)
    lines += smp("Contact_Part", flat(roller["contact"] + roller["free"][:8]) + flat(block["contact"] + block["free"][:8], nr))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def parameters(mdpa, materials):
    return {
        "problem_data": {"problem_name": "hertz_peer", "parallel_type": "OpenMP", "start_time": 0.0,
                         "end_time": 1.0, "echo_level": 0},
        "solver_settings": {
            "model_part_name": "Structure", "domain_size": 2, "solver_type": "Static", "echo_level": 0,
            "analysis_type": "non_linear",
            "model_import_settings": {"input_type": "mdpa", "input_filename": mdpa},
            "material_import_settings": {"materials_filename": materials},
            "contact_settings": {"mortar_type": "ALMContactFrictionless"},
            "time_stepping": {"time_step": 1.01},
            "block_builder": True, "line_search": False, "clear_storage": True, "reform_dofs_at_each_step": True,
            "convergence_criterion": "contact_residual_criterion",
            "displacement_relative_tolerance": 1e-6, "displacement_absolute_tolerance": 1e-12,
            "residual_relative_tolerance": 1e-6, "residual_absolute_tolerance": 1e-12, "max_iteration": 30,
            "linear_solver_settings": {"solver_type": "LinearSolversApplication.sparse_lu"},
            "problem_domain_sub_model_part_list": ["Parts_roller", "Parts_block"],
            "processes_sub_model_part_list": ["Contact_Part", "Symmetry", "Fixed", "Load"],
            "rotation_dofs": False},
        "processes": {
            "constraints_process_list": [
                {"python_module": "assign_vector_variable_process", "kratos_module": "KratosMultiphysics",
                 "Parameters": {"model_part_name": "Structure.Fixed", "variable_name": "DISPLACEMENT",
                                "constrained": [True, True, True], "value": [0.0, 0.0, 0.0]}},
                {"python_module": "assign_vector_variable_process", "kratos_module": "KratosMultiphysics",
                 "Parameters": {"model_part_name": "Structure.Symmetry", "variable_name": "DISPLACEMENT",
                                "constrained": [True, False, True], "value": [0.0, None, 0.0]}}],
            "loads_process_list": [
                {"python_module": "assign_vector_variable_to_conditions_process", "kratos_module": "KratosMultiphysics",
                 "Parameters": {"model_part_name": "Structure.Load", "variable_name": "LINE_LOAD",
                                "value": [0.0, -P_HALF, 0.0]}}],
            "contact_process_list": [
                {"python_module": "alm_contact_process",
                 "kratos_module": "KratosMultiphysics.ContactStructuralMechanicsApplication",
                 "Parameters": {"model_part_name": "Structure", "assume_master_slave": {"0": ["Parts_roller"]},
                                "contact_model_part": {"0": ["Contact_Part"]}, "contact_type": "Frictionless"}}]},
    }


def materials():
    law = {"name": "LinearElasticPlaneStrain2DLaw"}
    var = {"YOUNG_MODULUS": E, "POISSON_RATIO": NU, "THICKNESS": 1.0, "DENSITY": 1.0}
    return {"properties": [
        {"model_part_name": f"Structure.{p}", "properties_id": k + 1,
         "Material": {"constitutive_law": law, "Variables": var}} for k, p in enumerate(["Parts_roller", "Parts_block"])]}


def solve(roller, block, work):
    import KratosMultiphysics as KM
    import KratosMultiphysics.StructuralMechanicsApplication  # noqa: F401
    import KratosMultiphysics.ContactStructuralMechanicsApplication  # noqa: F401
    import KratosMultiphysics.LinearSolversApplication  # noqa: F401
    from KratosMultiphysics.StructuralMechanicsApplication.structural_mechanics_analysis import \
        StructuralMechanicsAnalysis

    mdpa = os.path.join(work, "hertz_peer")
    write_mdpa(mdpa + ".mdpa", roller, block)
    with open(os.path.join(work, "materials.json"), "w") as f:
        json.dump(materials(), f)
    prm = parameters(mdpa, os.path.join(work, "materials.json"))
    extra = json.loads(os.environ.get("HERTZ_KRATOS_CONTACT", "{}"))
    prm["processes"]["contact_process_list"][0]["Parameters"].update(extra)
    steps = int(os.environ.get("HERTZ_KRATOS_STEPS", str(STEPS)))
    prm["solver_settings"]["time_stepping"]["time_step"] = 1.0 / steps if steps > 1 else 1.01
    text = json.dumps(prm)
    KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
    model = KM.Model()
    sim = StructuralMechanicsAnalysis(model, KM.Parameters(text))
    sim.Run()
    mp = model["Structure"]
    info = mp.ProcessInfo
    nr = len(roller["nodes"])
    out = {}
    for name, body, off_e, off_n in (("roller", roller, 0, 0), ("block", block, len(roller["elements"]), nr)):
        ne = len(body["elements"])
        xg, wg = gauss_2x2(body["nodes"][body["elements"]])
        u = np.array([[mp.GetNode(off_n + k + 1).GetSolutionStepValue(KM.DISPLACEMENT)[c] for c in range(2)]
                      for k in range(len(body["nodes"]))])
        # Kratos gives its points on the mesh its contact solver moved: ours there, to match
        xm, _ = gauss_2x2((body["nodes"] + u)[body["elements"]])
        sg = np.empty((ne, 4, 3))
        for e in range(ne):
            el = mp.GetElement(off_e + e + 1)
            xk = np.array([[c[0], c[1]] for c in el.CalculateOnIntegrationPoints(KM.INTEGRATION_COORDINATES, info)])
            sk = np.array([[s[0], s[1], s[2]] for s in el.CalculateOnIntegrationPoints(KM.CAUCHY_STRESS_VECTOR, info)])
            # Kratos' points in our rule's order (its order is its own)
            d = np.linalg.norm(xm[e][:, None, :] - xk[None, :, :], axis=2)
            perm = d.argmin(axis=1)
            assert len(set(perm)) == 4 and d.min(axis=1).max() < 1e-9, (e, d)
            sg[e] = sk[perm]
        out[name] = dict(gauss_points=xg, gauss_weights=wg, gauss_stress=sg, displacement=u)
    import KratosMultiphysics.ContactStructuralMechanicsApplication as CSMA
    # The ALM multiplier is stored divided by the scale factor; the contact pressure is
    # -SCALE_FACTOR * multiplier at the ACTIVE slave nodes (the augmented pressure of an
    # inactive node is the penalised gap, not a pressure).
    lm, aug, active = np.zeros(nr), np.zeros(nr), np.zeros(nr, dtype=bool)
    scale = info[KM.SCALE_FACTOR] if info.Has(KM.SCALE_FACTOR) else 1.0
    for k in range(nr):
        node = mp.GetNode(k + 1)
        if node.SolutionStepsDataHas(CSMA.LAGRANGE_MULTIPLIER_CONTACT_PRESSURE):
            lm[k] = node.GetSolutionStepValue(CSMA.LAGRANGE_MULTIPLIER_CONTACT_PRESSURE)
        if node.Has(CSMA.AUGMENTED_NORMAL_CONTACT_PRESSURE):
            aug[k] = node.GetValue(CSMA.AUGMENTED_NORMAL_CONTACT_PRESSURE)
        active[k] = node.Is(KM.ACTIVE)
    out["roller"]["lm_pressure"] = lm
    out["roller"]["augmented_pressure"] = aug
    out["roller"]["scale_factor"] = np.array(scale)
    out["roller"]["active"] = active
    out["roller"]["pressure"] = np.where(active, -scale * lm, 0.0)
    return out


def main():
    h_over_a = float(sys.argv[1])
    path = sys.argv[2]
    growth = float(sys.argv[3]) if len(sys.argv) > 3 else 1.15
    h = A_HERTZ / h_over_a
    roller, block = build_mesh(h, growth, 4.0 * A_HERTZ)
    with tempfile.TemporaryDirectory() as work:
        res = solve(roller, block, work)
    arrays = {"h": h, "a": A_HERTZ, "growth": growth}
    for name, body in (("roller", roller), ("block", block)):
        for key, val in body.items():
            arrays[f"{name}_{key}"] = np.asarray(val)
        for key, val in res[name].items():
            arrays[f"{name}_{key}"] = val
    np.savez_compressed(path, **arrays)
    p = res["roller"]["pressure"]
    print(f"h = a/{h_over_a:g}: roller {len(roller['elements'])} + block {len(block['elements'])} quads, "
          f"{2 * (len(roller['nodes']) + len(block['nodes']))} displacement dofs; Kratos p_max = {p.max():.4f} "
          f"(Hertz p0 = {2 * 2 * P_HALF / (np.pi * A_HERTZ):.4f}) -> {path}")


if __name__ == "__main__":
    main()
