"""``python -m sprc SCENE.nml [--levels 3,4] [--threads N] [--csv]``: run the
study of a scene as ``sprc run`` does (writing no files) and print its
report, a compact table (or every column as CSV with ``--csv``). Exit
status 0, 2 for bad input (as the driver), 1 for a failed run."""

import argparse
import sys

from . import SprcError, run_scene

#: The columns of the compact table (those present in the report).
COMPACT = ("level", "dofs", "err_fe", "eta_spr", "eta_sprc", "theta_spr", "theta_sprc", "err_p_fe", "err_p_sprc",
           "t_total")


def _levels(text):
    try:
        return [int(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"levels are integers separated by commas, got {text!r}") from None


def _text(value):
    if value is None:
        return "-"
    if isinstance(value, int):
        return str(value)
    return f"{value:.4e}"


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m sprc", description="Run the study of a scene file "
                                     "(SCENE.md) and print its report.")
    parser.add_argument("scene", help="the scene file (.nml)")
    parser.add_argument("--levels", type=_levels, help="levels to run, e.g. 3,4 (default: the scene's)")
    parser.add_argument("--threads", type=int, help="OpenMP threads (default: as the driver chooses)")
    parser.add_argument("--csv", action="store_true", help="print every report column as CSV")
    args = parser.parse_args(argv)
    try:
        rows = run_scene(args.scene, levels=args.levels, threads=args.threads)
    except SprcError as exc:
        print(f"sprc: error: {exc}", file=sys.stderr)
        return 2 if exc.status in (1, 5) else 1
    except ValueError as exc:
        print(f"sprc: error: {exc}", file=sys.stderr)
        return 2
    columns = list(rows[0]) if args.csv else [c for c in COMPACT if c in rows[0]]
    if args.csv:
        print(",".join(columns))
        for row in rows:
            print(",".join("" if row[c] is None else repr(row[c]) for c in columns))
        return 0
    cells = [[_text(row[c]) for c in columns] for row in rows]
    widths = [max(len(c), *(len(r[j]) for r in cells)) for j, c in enumerate(columns)]
    print("  ".join(c.rjust(w) for c, w in zip(columns, widths)))
    for r in cells:
        print("  ".join(v.rjust(w) for v, w in zip(r, widths)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
