#!/usr/bin/env python3
"""Writes the long and generic chains of BENCHMARKS.md's generation-time table as descriptions.

    python3 bench/chains.py OUT_DIR

- `aN` (N = 8 … 32): N revolute joints whose axes cycle through y, z, x, about 0.1 m apart
  along y, `l_a` a parameter, `H = (x_r, z_r)` at link `max(6, N/2)` (a30: link 15).
- `obliqueN` (N = 8 … 32): N revolute joints with oblique unit axes and offsets written as
  floats to 17 significant digits (a calibrated robot's geometry), constraint at link
  `max(6, N/2)` with `H` given as two explicit numeric rows.

The geometry is pseudo-random with a fixed seed, so the files are the same on every machine.

    python3 bench/chains.py --peers FILE

writes the generic 7-DOF chain of bench/peers.sh (`oblique7`, its own seed): 7 revolute joints with
oblique unit axes and offsets as 17-digit floats, the constraint on link 6 (the rule i ≥ 6) with `H` as two explicit
numeric rows, and a `[task]` of 5 rows (the admission rule n − r ≥ t: 7 − 2 = 5).
"""
import math
import random
import sys
from pathlib import Path

AXES = [(0, 1, 0), (0, 0, 1), (1, 0, 0)]
OFFSETS = [(0.02, 0.12, 0), (0, 0.11, 0.01), (-0.01, 0.1, 0.02), (0.015, 0.13, 0), (0, 0.09, -0.02), (0.01, 0.12, 0.01)]


def fmt(x):
    return repr(float(x))


def chain(name, n, link, axes, offsets, h, task=None):
    lines = [
        f"# A generated benchmark chain (bench/chains.py): {n} revolute joints, constraint at link {link}.",
        "",
        "[robot]",
        f'name = "{name}"',
        "",
        "[parameters]",
        "l_a = 0.11",
        "",
    ]
    for k in range(n):
        x, y, z = offsets[k]
        ax = axes[k]
        lines += [
            "[[joints]]",
            f'name = "j{k + 1}"',
            'type = "revolute"',
            f"xyz = [{fmt(x)}, {fmt(y)}, {fmt(z)}]",
            f"axis = [{fmt(ax[0])}, {fmt(ax[1])}, {fmt(ax[2])}]",
            "",
        ]
    lines += [
        "[end_effector]",
        'name = "tool"',
        "xyz = [0, 0.09, 0]",
        "",
        "[constraint]",
        f"link = {link}",
        'xyz = [0, "l_a", 0]',
        f"h = {h}",
        "",
    ]
    if task is not None:
        lines += ["[task]", f"select = {task}", ""]
    return "\n".join(lines)


def oblique_geometry(rng, n):
    axes, offsets = [], []
    for _ in range(n):
        v = [rng.gauss(0, 1) for _ in range(3)]
        norm = math.sqrt(sum(c * c for c in v))
        axes.append([c / norm for c in v])
        offsets.append([rng.uniform(-0.03, 0.03), rng.uniform(0.08, 0.14), rng.uniform(-0.03, 0.03)])
    return axes, offsets


def peers_oblique7(path):
    axes, offsets = oblique_geometry(random.Random(7), 7)
    h = "[[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]]"
    task = '["x", "y", "z", "rx", "rz"]'
    Path(path).write_text(chain("oblique7", 7, 6, axes, offsets, h, task))


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--peers":
        peers_oblique7(sys.argv[2])
        return
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "bench/out/chains")
    out.mkdir(parents=True, exist_ok=True)
    rng = random.Random(14)
    for n in (8, 9, 12, 16, 20, 24, 28, 30, 32):
        link = 15 if n == 30 else max(6, n // 2)
        axes = [AXES[k % 3] for k in range(n)]
        offsets = [OFFSETS[k % 6] for k in range(n)]
        (out / f"a{n}.toml").write_text(chain(f"a{n}", n, link, axes, offsets, '["x", "z"]'))
    for n in (8, 9, 12, 16, 20, 24, 28, 30, 32):
        link = 15 if n == 30 else max(6, n // 2)
        axes, offsets = oblique_geometry(rng, n)
        h = "[[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]]"
        (out / f"oblique{n}.toml").write_text(chain(f"oblique{n}", n, link, axes, offsets, h))


if __name__ == "__main__":
    main()
