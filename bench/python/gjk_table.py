#!/usr/bin/env python3
"""Ratios against the best peer from `batchcol bench --json` files (issue #15's README table).

usage: gjk_table.py BOOLEAN_DOUBLE.json BOOLEAN_FLOAT.json WITNESS_DOUBLE.json
Prints one row per case (ns per pair, best peer, ratio, float/double pairs/s) and the geometric means of the
ratios over the rows given in ROWS (the 25 type pairs that ran GJK when issue #15 was filed), then how many of the
75 cells meet issue #15's targets (TARGETS) and which do not. The best peer is the
fastest of every peer the bench timed on the same pairs and threads (FCL, Bullet, Coal collide/distance, Coal GJK
and Nesterov called directly); float is compared with the double peers timed in its own run.
"""
import json
import math
import sys

ROWS = ["sphere-cylinder", "sphere-cone", "sphere-ellipsoid", "sphere-convex8", "capsule-box", "capsule-cylinder",
        "capsule-cone", "capsule-ellipsoid", "capsule-convex8", "box-cylinder", "box-cone", "box-ellipsoid",
        "box-convex8", "cylinder-cylinder", "cylinder-cone", "cylinder-ellipsoid", "cylinder-convex8", "cone-cone",
        "cone-ellipsoid", "cone-convex8", "ellipsoid-ellipsoid", "ellipsoid-convex8", "convex8-convex8",
        "convex250-convex250", "convex940-convex940"]
# Issue #15's targets per column: boolean double >= 4x (>= 5x for the 250- and 940-vertex hulls), boolean float
# >= 6x, witness double >= 3x.
BIG_HULLS = ("convex250-convex250", "convex940-convex940")
TARGETS = {"boolean double": lambda name: 5.0 if name in BIG_HULLS else 4.0,
           "boolean float": lambda name: 6.0, "witness double": lambda name: 3.0}
SHORT = {"Coal GJK direct": "Coal GJK", "Coal Nesterov direct": "Coal Nest.", "Coal distance": "Coal dist.",
         "Coal collide": "Coal collide"}


def load(path):
    return {c["case"]: c for c in json.load(open(path))}


def best(case):
    peers = [p for p in case["peers"] if p.get("pairs_answered", 0) == case["pairs"]]
    return min(peers, key=lambda p: p["ns_per_pair"]) if peers else None


def main():
    bd, bf, wd = (load(p) for p in sys.argv[1:4])
    logs = {"boolean double": [], "boolean float": [], "witness double": []}
    short = []
    print("| case | kernel | iters b / w | boolean double: ns, best peer | ratio | boolean float: ns | ratio | "
          "float / double pairs/s | witness double: ns, best peer | ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in ROWS:
        b, f, w = bd[name], bf[name], wd[name]
        pb, pw = best(b), best(w)
        pf = best(f) or pb  # the float run's own (double) peers when it timed them
        rb, rf, rw = pb["ns_per_pair"] / b["ns_per_pair"], pf["ns_per_pair"] / f["ns_per_pair"], \
            pw["ns_per_pair"] / w["ns_per_pair"]
        logs["boolean double"].append(math.log(rb))
        logs["boolean float"].append(math.log(rf))
        logs["witness double"].append(math.log(rw))
        for column, ratio in (("boolean double", rb), ("boolean float", rf), ("witness double", rw)):
            if ratio < TARGETS[column](name):
                short.append(f"{name} {column} {ratio:.2f}x")
        print(f"| {name} | {b['kernel']} | {b['iterations_mean']:.1f} / {w['iterations_mean']:.1f} | "
              f"{b['ns_per_pair']:.0f}, {SHORT.get(pb['name'], pb['name'])} {pb['ns_per_pair']:.0f} | {rb:.1f}x | "
              f"{f['ns_per_pair']:.0f} | {rf:.1f}x | {b['ns_per_pair'] / f['ns_per_pair']:.2f} | "
              f"{w['ns_per_pair']:.0f}, {SHORT.get(pw['name'], pw['name'])} {pw['ns_per_pair']:.0f} | {rw:.1f}x |")
    for k, v in logs.items():
        print(f"geometric mean {k}: {math.exp(sum(v) / len(v)):.2f}x")
    print(f"cells meeting issue #15's targets: {3 * len(ROWS) - len(short)} of {3 * len(ROWS)}")
    for cell in short:
        print(f"  short: {cell}")


if __name__ == "__main__":
    main()
