"""Run the Lamé cylinder example at a few levels from Python and show the
convergence of the FE error and of the ZZ estimates (SPR, SPR-C) against the
number of unknowns: a log-log plot (run_scene.png) when matplotlib is
importable, otherwise a table.

    python3 example/python/run_scene.py [LEVEL ...]     (default levels 3 4 5)
"""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))
import sprc  # noqa: E402

levels = [int(a) for a in sys.argv[1:]] or [3, 4, 5]
rows = sprc.run_scene(ROOT / "example" / "scenes" / "lame_cylinder.nml", levels=levels)
columns = ("level", "dofs", "err_fe", "eta_spr", "eta_sprc", "theta_spr", "theta_sprc")

print(" ".join(f"{c:>11}" for c in columns))
for row in rows:
    print(" ".join(f"{row[c]:>11d}" if isinstance(row[c], int) else
                   f"{'-':>11}" if row[c] is None else f"{row[c]:11.4e}" for c in columns))

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: table only")
else:
    dofs = [r["dofs"] for r in rows]
    fig, ax = plt.subplots()
    for key, label in (("err_fe", "FE error (exact)"), ("eta_spr", "ZZ estimate, SPR"),
                       ("eta_sprc", "ZZ estimate, SPR-C")):
        ax.loglog(dofs, [r[key] for r in rows], "o-", label=label)
    ax.set_xlabel("degrees of freedom")
    ax.set_ylabel("relative error (energy norm)")
    ax.set_title("Lamé cylinder")
    ax.legend()
    out = Path.cwd() / "run_scene.png"
    fig.savefig(out, dpi=100)
    print(f"plot written to {out}")
