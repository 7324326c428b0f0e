"""The physics runs of the documentation: the shipped Panda scenarios and the UR5 example on
their MuJoCo plants, every method, with noise and latency on and off, and without the drift
correction; prints the table of docs/physics.md and writes its figures.

    python codegen/python/bench/physics_results.py [--out docs/figures] [--short]

``--short`` runs 2 s of each (a check that the script works, not the documented figures).
"""

import argparse
import pathlib
import platform
import sys

import numpy as np

import trocar
from machine import cpu
from trocar import physics

ROOT = pathlib.Path(__file__).resolve().parents[3]
RUNS = [
    ("panda-laparoscope", None),
    ("panda-laparoscope-limits", None),
    (str(ROOT / "examples" / "robots" / "ur5_trocar.toml"), "ur5_trocar"),
]
METHODS = ["pinv", "dls", "fi", "qp"]


def row(name, method, conditions, s):
    # An excess within rounding (1e-9 of the limit, at most 1e-8) is no excess.
    excess = {
        "position": s["position_limit_excess"],
        "speed": max(s["speed_limit_excess"], s["measured_speed_excess"]),
        "acceleration": max(s["acceleration_limit_excess"], s["measured_acceleration_excess"]),
    }
    over = [f"{k} +{v:.2g}" for k, v in excess.items() if v > 1e-8]
    if s["yielded_steps"]:
        over.append(f"trocar gave way in {s['yielded_steps']} steps")
    held = "yes" if not over else "no: " + ", ".join(over)
    return (
        f"| {name} | {method} | {conditions} | {1e3 * s['max_drift']:.3f} | {1e3 * s['rms_drift']:.3f} "
        f"| {s['peak_port_force']:.3f} | {s['rms_port_force']:.3f} | {1e3 * s['max_tip_error']:.2f} "
        f"| {1e3 * s['final_tip_error']:.2f} | {held} | {s['real_time_factor']:.1f} |"
    )


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", default=str(ROOT / "docs" / "figures"))
    parser.add_argument("--short", action="store_true")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    duration = 2.0 if args.short else None
    print(f"CPU: {cpu()}; MuJoCo {physics._mujoco().__version__}; Python {platform.python_version()}")
    print()
    print("| run | method | noise, latency | max drift (mm) | RMS drift (mm) | peak port force (N) "
          "| RMS port force (N) | max tip error (mm) | final tip error (mm) | limits held | real-time factor |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, short in RUNS:
        label = short or name
        figure_runs = {}
        for method in METHODS:
            for noise, latency in [(physics.DEFAULT_NOISE, 1), (0.0, 0)]:
                try:
                    c = physics.simulate(name, method=method, noise=noise, latency=latency, duration=duration)
                except ValueError as e:
                    print(f"| {label} | {method} | {noise:g} rad, {latency} | failed: {e} |||||||||")
                    continue
                conditions = f"{noise:g} rad, {latency}" if noise else "none, 0"
                print(row(label, method, conditions, c["summary"]))
                if noise:
                    figure_runs[method] = c
            sys.stdout.flush()
        c = physics.simulate(name, noise=physics.DEFAULT_NOISE, latency=1, duration=duration,
                             drift_correction=False)
        print(row(label, c["summary"]["method"], "1e-05 rad, 1, no drift correction", c["summary"]))
        figure_runs[f"{c['summary']['method']}, no drift correction"] = c
        physics.figure(out / f"physics-{label}.png", figure_runs,
                       f"{label} on its MuJoCo plant: noise 1e-5 rad, one sample of latency")


if __name__ == "__main__":
    main()
