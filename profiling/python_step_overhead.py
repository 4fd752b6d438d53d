#!/usr/bin/python3
"""What a Python step loop costs over `ballpit run`: the same pour, stepped one step per call
from Python (ballpit.Simulation.step(1), timed around the call) and by the CLI (its per-step
timing), at 1k and 100k balls. Both halves of the run (pour, then settled) are compared by
median ms per step; runs alternate CLI, Python, CLI, ... so drift hits both alike, and each
figure is the median over the repeats.

    OMP_WAIT_POLICY=passive PYTHONPATH=build/python /usr/bin/python3 profiling/python_step_overhead.py \\
        --cli build/app/ballpit [--repeats 3] [--threads 2]

Not in ctest: it measures, it does not check.
"""
import argparse
import json
import statistics
import subprocess
import time

import ballpit

CASES = [(1_000, 600), (100_000, 60)]  # (balls, steps): 100k steps cost tens of ms each


def cli_medians(cli, spheres, steps, threads):
    out = subprocess.run([cli, "run", "--scene", "pour", "--set", f"populations.0.count={spheres}",
                          "--set", f"steps={steps}", "--threads", str(threads), "--no-progress", "--no-table"],
                         check=True, capture_output=True, text=True).stdout
    report = json.loads(out.strip().splitlines()[-1])
    return report["ms_per_step_pour_median"], report["ms_per_step_settled_median"], report["state_hash"]


def python_medians(spheres, steps, threads):
    sim = ballpit.Simulation.from_scene("pour", [f"populations.0.count={spheres}"], threads=threads)
    step_ms = []
    for _ in range(steps):
        t0 = time.perf_counter()
        sim.step(1)
        step_ms.append(1000.0 * (time.perf_counter() - t0))
    split = 300 if steps == 600 else steps // 2  # as `ballpit run` splits its report
    return (statistics.median(step_ms[:split]), statistics.median(step_ms[split:]),
            sim.report()["state_hash_hex"])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default="build/app/ballpit")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()

    print("| balls | steps | phase | ballpit run (ms/step) | Python loop (ms/step) | overhead |")
    print("|---:|---:|---|---:|---:|---:|")
    for spheres, steps in CASES:
        cli, py = [], []
        for _ in range(args.repeats):
            cli.append(cli_medians(args.cli, spheres, steps, args.threads))
            py.append(python_medians(spheres, steps, args.threads))
        if {c[2] for c in cli} != {p[2] for p in py}:
            raise SystemExit(f"{spheres} balls: the states differ ({cli[0][2]} vs {py[0][2]}): not the same run")
        for phase, k in (("pour", 0), ("settled", 1)):
            c = statistics.median(r[k] for r in cli)
            p = statistics.median(r[k] for r in py)
            print(f"| {spheres:,} | {steps} | {phase} | {c:.3f} | {p:.3f} | {100.0 * (p / c - 1.0):+.1f}% |")


if __name__ == "__main__":
    main()
