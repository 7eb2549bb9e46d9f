"""The contact pressure of the shrink-fit example from the fields of a run
(sprc.run): FE, SPR-C and exact pressure along the shaft's surface at one
level, against the angle; a plot (contact_pressure.png) when matplotlib is
importable, otherwise a summary.

    python3 example/python/contact_pressure.py [LEVEL]     (default level 4)
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))
import sprc  # noqa: E402

level = int(sys.argv[1]) if len(sys.argv) > 1 else 4
study = sprc.run(ROOT / "example" / "scenes" / "shrink_fit.nml", levels=level)
contact = study.levels[0].contact
angle = np.degrees(np.arctan2(contact["points"][:, 1], contact["points"][:, 0]))
order = np.argsort(angle)
w = contact["weight"]
for name in ("p_fe", "p_sprc", "p_exact"):
    p = contact[name]
    print(f"{name:8s} mean {np.sum(w * p) / np.sum(w):.4f}  min {p.min():.4f}  max {p.max():.4f}")

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: summary only")
else:
    fig, ax = plt.subplots()
    for name, label in (("p_fe", "FE (multiplier)"), ("p_sprc", "SPR-C"), ("p_exact", "exact")):
        ax.plot(angle[order], contact[name][order], label=label)
    ax.set_xlabel("angle on the shaft surface (degrees)")
    ax.set_ylabel("contact pressure (MPa)")
    ax.set_title(f"Shrink fit, level {level}")
    ax.legend()
    out = Path.cwd() / "contact_pressure.png"
    fig.savefig(out, dpi=100)
    print(f"plot written to {out}")
