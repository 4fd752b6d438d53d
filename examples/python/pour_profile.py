#!/usr/bin/python3
"""Pours balls into the pit from Python, lets them settle, and plots the pile's height profile.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/pour_profile.py pile.png
    PYTHONPATH=build/python /usr/bin/python3 examples/python/pour_profile.py pile.png --spheres 20000 --steps 900

The top of the pile is measured on a grid of columns across the floor: in each column, the
highest ball's top (centre + radius). The figure shows that height map from above and the
profile along x (the mean over z of each column's top, with the lowest and highest column).
"""
import argparse
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed: the figure goes to a file
import matplotlib.pyplot as plt
import numpy as np

import ballpit


def pile_tops(positions, radii, half_width, cells):
    """Height of the pile's top (unit: m) in each of cells x cells columns of the floor."""
    edges = np.linspace(-half_width, half_width, cells + 1)
    ix = np.clip(np.searchsorted(edges, positions[:, 0]) - 1, 0, cells - 1)
    iz = np.clip(np.searchsorted(edges, positions[:, 2]) - 1, 0, cells - 1)
    tops = np.zeros((cells, cells))
    np.maximum.at(tops, (iz, ix), positions[:, 1] + radii)
    return edges, tops


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("png", help="where to write the figure (PNG)")
    parser.add_argument("--spheres", type=int, default=4000)
    parser.add_argument("--steps", type=int, default=600, help="steps of 1/60 s (600: 10 s, settled)")
    parser.add_argument("--threads", type=int, default=0, help="OpenMP threads (0: OpenMP's default)")
    args = parser.parse_args()

    sim = ballpit.Simulation.from_scene("pour", [f"populations.0.count={args.spheres}"], threads=args.threads)
    sim.step(args.steps)
    report = sim.report()
    print(f"{report['spheres']} balls, {report['time_s']:.1f} s: kinetic energy {report['kinetic_energy_j']:.2e} J, "
          f"deepest overlap {report['max_penetration_r']:.4f} r, escaped {report['escaped']}, "
          f"state hash {report['state_hash_hex']}")

    positions, radii = sim.positions, sim.radii  # views of the engine's columns: no copy
    half_width = float(np.abs(positions[:, [0, 2]]).max() + radii.max())
    cells = max(8, int(2 * half_width / (4 * float(radii.mean()))))  # columns about two balls wide
    edges, tops = pile_tops(positions, radii, half_width, cells)
    centres = 0.5 * (edges[:-1] + edges[1:])

    fig, (top_view, profile) = plt.subplots(1, 2, figsize=(11, 4.5), gridspec_kw={"width_ratios": [1, 1.4]})
    image = top_view.imshow(tops, origin="lower", extent=(edges[0], edges[-1], edges[0], edges[-1]), cmap="viridis")
    fig.colorbar(image, ax=top_view, label="top of the pile (m)")
    top_view.set(title="the pile from above", xlabel="x (m)", ylabel="z (m)")
    profile.fill_between(centres, tops.min(axis=0), tops.max(axis=0), alpha=0.3, label="lowest to highest column")
    profile.plot(centres, tops.mean(axis=0), lw=2, label="mean over z")
    profile.set(title=f"height profile after {report['time_s']:.0f} s ({report['spheres']} balls)",
                xlabel="x (m)", ylabel="height (m)", ylim=(0, 1.2 * tops.max()))
    profile.legend(loc="lower center")
    profile.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    print(f"wrote {args.png}")


if __name__ == "__main__":
    sys.exit(main())
