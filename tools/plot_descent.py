#!/usr/bin/python3
"""Plot of `batchcol descent` (issue 18, the seed talk's Part III example) from its CSV, as PNG and SVG.

Usage: /usr/bin/python3 tools/plot_descent.py DIR/descent.csv OUT_DIR

Needs Debian's python3-matplotlib. Writes OUT_DIR/descent.{png,svg}: one panel per case (ellipsoids, hulls), the
cost C(T) per iteration (log scale) for finite differences, 0th-order and 1st-order randomized smoothing.
Each file is written to a temporary name and renamed, so a failure never leaves a half-written figure.
"""
import csv
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("plot_descent.py: matplotlib is missing; install it with: "
                     "sudo apt-get install -y python3-matplotlib\n")
    sys.exit(2)

LABELS = {"finite_differences": "finite differences", "smoothed0": "0th order", "smoothed1": "1st order"}


def main():
    if len(sys.argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    curves = {}
    with open(sys.argv[1], newline="") as f:
        for row in csv.DictReader(f):
            if row["cost"]:
                curves.setdefault(row["case"], {}).setdefault(row["method"], []).append(
                    (int(row["iteration"]), float(row["cost"])))
    cases = sorted(curves)
    fig, axes = plt.subplots(1, len(cases), figsize=(5.5 * len(cases), 4), squeeze=False)
    for ax, case in zip(axes[0], cases):
        for method in ("finite_differences", "smoothed0", "smoothed1"):
            points = curves[case].get(method, [])
            ax.plot([p[0] for p in points], [p[1] for p in points], label=LABELS[method])
        ax.set_yscale("log")
        ax.set_xlabel("iteration")
        ax.set_ylabel("cost C(T) [m^2]")
        ax.set_title(case)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.tight_layout()
    os.makedirs(sys.argv[2], exist_ok=True)
    for extension in ("png", "svg"):
        path = os.path.join(sys.argv[2], "descent." + extension)
        temporary = path + ".tmp." + extension
        fig.savefig(temporary, dpi=120)
        os.replace(temporary, path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
