#!/usr/bin/python3
"""Plots of `batchcol accuracy` (issue 5) from its accuracy.csv, as PNG and SVG.

Usage: /usr/bin/python3 tools/plot_accuracy.py DIR/accuracy.csv OUT_DIR

Needs Debian's python3-matplotlib (apt-get install -y python3-matplotlib); `batchcol accuracy` runs this script
itself. Writes, for each regime present in the CSV:
  speed_vs_error_REGIME.{png,svg}  one panel per case: pairs/s against the max |distance error| over the pairs,
                                   one curve per solver x precision, one point per tolerance;
and over all regimes (double precision, in the spirit of the iterations table of Montaut et al.'s talk
"Collision detection: an optimization perspective", GJK vs Nesterov-accelerated GJK per regime):
  iterations.{png,svg}             mean iterations per regime and solver at the tolerance nearest 1e-8, for the cases
                                   with a curved shape and the cases of two polytopes;
  iterations_vs_tolerance.{png,svg} mean iterations against the tolerance, per regime and solver.
Each file is written to a temporary name and renamed, so a failure never leaves a half-written figure.
"""
import csv
import math
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker as ticker
except ImportError:
    sys.stderr.write("plot_accuracy.py: matplotlib is missing; install it with: "
                     "sudo apt-get install -y python3-matplotlib\n")
    sys.exit(3)

REGIMES = ["distant", "close", "overlap"]
SOLVERS = ["gjk", "nesterov", "polyak"]
COLORS = {"gjk": "tab:blue", "nesterov": "tab:orange", "polyak": "tab:green"}
STYLES = {"double": "-", "float": "--"}
MARKERS = {"double": "o", "float": "s"}
POLYTOPES = ("box", "convex")
# Errors of exactly 0 cannot sit on a log axis: they are drawn at this floor (below double rounding of metres).
ERROR_FLOOR = 1e-17

NUMERIC = {"tolerance", "pairs_per_second", "distance_error_max", "iterations_mean", "iterations_max"}
REQUIRED = {"case", "regime", "solver", "precision"} | NUMERIC


def read_rows(path):
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = REQUIRED - set(reader.fieldnames or [])
        if missing:
            raise ValueError(f"{path}: missing columns: {', '.join(sorted(missing))}")
        rows = []
        for line, row in enumerate(reader, start=2):
            try:
                for key in NUMERIC:
                    row[key] = float(row[key])
            except ValueError as e:
                raise ValueError(f"{path}:{line}: {e}") from None
            rows.append(row)
    if not rows:
        raise ValueError(f"{path}: no data rows")
    return rows


def save(fig, out_dir, name):
    for fmt in ("png", "svg"):
        final = os.path.join(out_dir, f"{name}.{fmt}")
        tmp = final + ".tmp"
        try:
            metadata = {"Date": None} if fmt == "svg" else {"Software": None}
            fig.savefig(tmp, format=fmt, dpi=90, metadata=metadata, bbox_inches="tight")
            os.replace(tmp, final)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
    plt.close(fig)


def ordered(values, order):
    return [v for v in order if v in values] + sorted(v for v in values if v not in order)


def speed_vs_error(rows, regime, out_dir):
    subset = [r for r in rows if r["regime"] == regime]
    cases = list(dict.fromkeys(r["case"] for r in subset))
    cols = min(6, len(cases))
    nrows = math.ceil(len(cases) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(3.2 * cols, 2.6 * nrows + 0.8), squeeze=False)
    for ax, case in zip(axes.flat, cases):
        mine = [r for r in subset if r["case"] == case]
        for solver in ordered({r["solver"] for r in mine}, SOLVERS):
            for precision in ordered({r["precision"] for r in mine}, ["double", "float"]):
                curve = sorted((r for r in mine if r["solver"] == solver and r["precision"] == precision),
                               key=lambda r: -r["tolerance"])
                if not curve:
                    continue
                ax.plot([max(r["distance_error_max"], ERROR_FLOOR) for r in curve],
                        [r["pairs_per_second"] for r in curve], STYLES.get(precision, ":"),
                        marker=MARKERS.get(precision, "x"), markersize=3, linewidth=1,
                        color=COLORS.get(solver, "black"), label=f"{solver} {precision}")
        ax.set_xscale("log")
        ax.xaxis.set_minor_locator(ticker.NullLocator())
        ax.set_ylim(bottom=0)
        ax.yaxis.set_major_formatter(ticker.FuncFormatter(pairs_per_second_label))
        ax.set_title(case, fontsize=9)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="major", linewidth=0.3)
    for ax in list(axes.flat)[len(cases):]:
        ax.set_visible(False)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.supxlabel(f"max |distance error| over the pairs (m, log; 0 drawn at {ERROR_FLOOR:g})", fontsize=9)
    fig.supylabel("pairs/s", fontsize=9)
    fig.suptitle(f"batchcol accuracy: speed vs error, {regime} regime (one point per tolerance)", fontsize=11)
    top = 1 - 0.9 / fig.get_figheight()  # room for the title and the legend, in figure coordinates
    fig.tight_layout(rect=(0, 0, 1, top))
    fig.legend(handles, labels, loc="lower center", bbox_to_anchor=(0.5, top), ncol=6, fontsize=8, frameon=False)
    save(fig, out_dir, f"speed_vs_error_{regime}")


def pairs_per_second_label(value, _position):
    if value >= 1e6:
        return f"{value / 1e6:g}M"
    return f"{value / 1e3:g}k" if value > 0 else "0"


def nearest_tolerance(rows, target=1e-8):
    return min({r["tolerance"] for r in rows}, key=lambda t: abs(math.log10(t) - math.log10(target)))


def is_polytope_case(case):
    return all(side.startswith(POLYTOPES) for side in case.split("-"))


def mean(values):
    return sum(values) / len(values) if values else float("nan")


def iterations_bars(rows, regimes, out_dir):
    double = [r for r in rows if r["precision"] == "double"] or rows
    tol = nearest_tolerance(double)
    at_tol = [r for r in double if r["tolerance"] == tol]
    groups = [("cases with a curved shape", lambda c: not is_polytope_case(c)),
              ("polytope-polytope cases", is_polytope_case)]
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), squeeze=False)
    solvers = ordered({r["solver"] for r in at_tol}, SOLVERS)
    width = 0.8 / max(1, len(solvers))
    for ax, (title, keep) in zip(axes.flat, groups):
        ax.set_title(title, fontsize=10)
        if not any(keep(r["case"]) for r in at_tol):
            ax.text(0.5, 0.5, "no such case in the CSV", ha="center", va="center", transform=ax.transAxes)
            ax.set_xticks([])
            ax.set_yticks([])
            continue
        for k, solver in enumerate(solvers):
            heights, tops = [], []
            for regime in regimes:
                sel = [r for r in at_tol if r["regime"] == regime and r["solver"] == solver and keep(r["case"])]
                heights.append(mean([r["iterations_mean"] for r in sel]))
                tops.append(max([r["iterations_max"] for r in sel], default=float("nan")))
            xs = [i + (k - (len(solvers) - 1) / 2) * width for i in range(len(regimes))]
            bars = ax.bar(xs, heights, width, color=COLORS.get(solver, "gray"), label=solver)
            ax.bar_label(bars, labels=[f"{h:.1f}" if h == h else "" for h in heights], fontsize=7)
            ax.plot(xs, tops, "v", color=COLORS.get(solver, "gray"), markersize=4)
        ax.set_xticks(range(len(regimes)), regimes)
        ax.set_ylim(bottom=0)
        ax.set_ylabel("iterations per pair")
        ax.grid(True, axis="y", linewidth=0.3)
    for ax in axes.flat:
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
            break
    fig.suptitle(f"Iterations per regime (double, tolerance {tol:g}): bars = mean over the cases of the mean "
                 "per pair, triangles = max", fontsize=10)
    save(fig, out_dir, "iterations")


def iterations_vs_tolerance(rows, regimes, out_dir):
    fig, axes = plt.subplots(1, len(regimes), figsize=(4.2 * len(regimes), 3.6), squeeze=False)
    for ax, regime in zip(axes.flat, regimes):
        subset = [r for r in rows if r["regime"] == regime]
        for solver in ordered({r["solver"] for r in subset}, SOLVERS):
            for precision in ordered({r["precision"] for r in subset}, ["double", "float"]):
                sel = [r for r in subset if r["solver"] == solver and r["precision"] == precision]
                tols = sorted({r["tolerance"] for r in sel}, reverse=True)
                ys = [mean([r["iterations_mean"] for r in sel if r["tolerance"] == t]) for t in tols]
                ax.plot(tols, ys, STYLES.get(precision, ":"), marker=MARKERS.get(precision, "x"), markersize=3,
                        linewidth=1, color=COLORS.get(solver, "black"), label=f"{solver} {precision}")
        ax.set_xscale("log")
        ax.invert_xaxis()
        ax.set_title(regime, fontsize=10)
        ax.set_xlabel("tolerance (m, tighter to the right)")
        ax.grid(True, linewidth=0.3)
    axes.flat[0].set_ylabel("mean iterations per pair (over cases)")
    axes.flat[0].legend(fontsize=7)
    save(fig, out_dir, "iterations_vs_tolerance")


def main(argv):
    if len(argv) != 3:
        sys.stderr.write("usage: plot_accuracy.py ACCURACY.csv OUT_DIR\n")
        return 2
    csv_path, out_dir = argv[1], argv[2]
    try:
        rows = read_rows(csv_path)
    except (OSError, ValueError) as e:
        sys.stderr.write(f"plot_accuracy.py: {e}\n")
        return 2
    if not os.path.isdir(out_dir):
        sys.stderr.write(f"plot_accuracy.py: {out_dir}: not a directory\n")
        return 2
    plt.rcParams["svg.fonttype"] = "none"  # text stays text: small SVGs
    plt.rcParams["svg.hashsalt"] = "batchcol"  # deterministic ids: a regenerated SVG only differs by its data
    plt.rcParams["font.sans-serif"] = ["DejaVu Sans"]  # one font name per SVG text element, not a list of ten
    regimes = ordered({r["regime"] for r in rows}, REGIMES)
    for regime in regimes:
        speed_vs_error(rows, regime, out_dir)
    iterations_bars(rows, regimes, out_dir)
    iterations_vs_tolerance(rows, regimes, out_dir)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
