#!/usr/bin/env python3
"""The cost of calling Clearway from Python: one Scene.check of a batch against the same loop in C++.

    python3 examples/python/batch_overhead.py [SCENE] [--count 10000] [--rounds 5] [--timer PATH]

The C++ side is clearway_batch_timer (python/benchmarks/batch_timer.cpp, built with the module): a loop
over Scene::isFree in one context (Clearway has no batch API of its own). Both check the same states
(written to a file the timer reads); each round runs the C++ loop 3 times and the Python call 3 times,
and the best time of each over all rounds is kept (a shared machine only ever adds time).
"""
import argparse
import os
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import clearway

REPO = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_SCENE = REPO.parent / "shared" / "scenes" / "box_panda" / "box_panda_0001.yaml"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", nargs="?", default=str(DEFAULT_SCENE))
    parser.add_argument("--count", type=int, default=10000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--timer", default=os.environ.get("CLEARWAY_BATCH_TIMER", str(REPO / "build" / "python" / "clearway_batch_timer")))
    args = parser.parse_args()

    scene = clearway.Scene.load(args.scene)
    limits = scene.limits
    states = np.random.default_rng(args.seed).uniform(limits[:, 0], limits[:, 1], size=(args.count, scene.dof))
    with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
        for q in states:
            f.write(" ".join(repr(float(x)) for x in q) + "\n")
        path = f.name
    try:
        cpp, py, free = float("inf"), float("inf"), None
        for _ in range(args.rounds):
            out = subprocess.run([args.timer, args.scene, path, "3"], capture_output=True, text=True, check=True).stdout
            fields = out.split()
            cpp = min(cpp, float(fields[fields.index("best_ns_per_state") + 1]))
            cpp_free = int(fields[fields.index("free") + 1])
            for _ in range(3):
                start = time.perf_counter()
                free = scene.check(states)
                py = min(py, 1e9 * (time.perf_counter() - start) / args.count)
        assert int(free.sum()) == cpp_free, "Python and C++ disagree on the states"
    finally:
        os.unlink(path)
    print(f"{scene.name}: {args.count} states, {cpp_free} free")
    print(f"  C++ loop over Scene::isFree:  {cpp:9.1f} ns per state")
    print(f"  Python Scene.check (batch):   {py:9.1f} ns per state")
    print(f"  overhead:                     {py - cpp:9.1f} ns per state ({100 * (py - cpp) / cpp:+.1f}%)")


if __name__ == "__main__":
    main()
