#!/usr/bin/env python3
"""Checks random states of a planning problem and shows which link pairs collide, and how often.

    python3 examples/python/random_states.py [SCENE] [--count 100000] [--seed 1] [--plot pairs.png]

SCENE defaults to the shared Panda problem box_panda_0001 (../shared next to the repository). States are
uniform within the scene's limits. Each colliding state names the pair the check found first (the
environment is checked before self-collision), so the fractions below add up to the colliding fraction.
With matplotlib installed, --plot draws them as a bar chart.
"""
import argparse
import collections
import pathlib
import time

import numpy as np

import clearway

REPO = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_SCENE = REPO.parent / "shared" / "scenes" / "box_panda" / "box_panda_0001.yaml"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", nargs="?", default=str(DEFAULT_SCENE))
    parser.add_argument("--count", type=int, default=100000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--plot", help="write a bar chart of the fraction per pair to this PNG (needs matplotlib)")
    args = parser.parse_args()

    scene = clearway.Scene.load(args.scene)
    limits = scene.limits
    if not np.isfinite(limits).all():
        raise SystemExit(f"{args.scene}: some joint is unbounded; give it bounds in the scene to sample it")
    states = np.random.default_rng(args.seed).uniform(limits[:, 0], limits[:, 1], size=(args.count, scene.dof))

    start = time.perf_counter()
    free, pairs = scene.check(states, report=True)
    seconds = time.perf_counter() - start
    counts = collections.Counter(" / ".join(p) for p in pairs if p is not None)

    print(f"{scene.name}: {args.count} states in {seconds:.2f} s ({1e6 * seconds / args.count:.1f} us per state), "
          f"{1 - free.mean():.4f} colliding")
    for pair, n in counts.most_common():
        print(f"  {n / args.count:8.4f}  {pair}")

    if args.plot:
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("matplotlib is not installed (Debian: python3-matplotlib): no plot")
            return
        top = counts.most_common(25)
        fig, ax = plt.subplots(figsize=(8, 0.3 * len(top) + 1.5))
        ax.barh([p for p, _ in reversed(top)], [n / args.count for _, n in reversed(top)])
        ax.set_xlabel("fraction of states (the pair each colliding state names first)")
        ax.set_title(f"{scene.name}: {args.count} random states, {1 - free.mean():.1%} colliding")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
