"""Writes the batch files the README's shape-form ray instruction counts are measured on (issue #19): N rays against
one posed shape each, random poses (uniform quaternions, translations in a 10 m cube), rays from 3 m around the
shape aimed at a uniform point within 0.6 m of its centre (per axis), unit directions, t_max 10.

    python3 bench/python/ray_shape_batch.py --shape hull --rays 20000 --out /tmp/hull20k.json
    valgrind --tool=callgrind --toggle-collect='batchcol::cast_rays*' build/batchcol rays --batch /tmp/hull20k.json --threads 1

Shapes: sphere (r 0.5), box (half extents 0.4, 0.3, 0.2), capsule (r 0.25, half length 0.25), hull (250 points on a
0.5 m sphere). Seeded (--seed): the same file every time.
"""

import argparse
import json
import math
import random


def unit(rng):
    while True:
        v = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if n > 1e-9:
            return [x / n for x in v]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--shape", choices=["sphere", "box", "capsule", "hull"], default="hull")
    p.add_argument("--rays", type=int, default=20000)
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("--out", required=True)
    a = p.parse_args()
    rng = random.Random(a.seed)
    shape = {
        "sphere": {"type": "sphere", "radius": 0.5},
        "box": {"type": "box", "half_extents": [0.4, 0.3, 0.2]},
        "capsule": {"type": "capsule", "radius": 0.25, "half_length": 0.25},
        "hull": {"type": "convex", "vertices": [[0.5 * x for x in unit(rng)] for _ in range(250)]},
    }[a.shape]
    rays = []
    for _ in range(a.rays):
        q = [rng.gauss(0, 1) for _ in range(4)]
        n = math.sqrt(sum(x * x for x in q))
        q = [x / n for x in q]
        c = [rng.uniform(-5, 5) for _ in range(3)]
        o = [c[k] + 3 * u for k, u in enumerate(unit(rng))]
        target = [c[k] + rng.uniform(-0.6, 0.6) for k in range(3)]
        d = [target[k] - o[k] for k in range(3)]
        n = math.sqrt(sum(x * x for x in d))
        rays.append({"shape": 0, "pose": {"translation": c, "quaternion": q}, "origin": o,
                     "direction": [x / n for x in d], "t_max": 10})
    with open(a.out, "w") as f:
        json.dump({"shapes": [shape], "rays": rays}, f)


if __name__ == "__main__":
    main()
