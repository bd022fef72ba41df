#!/usr/bin/env python3
"""Audits a robot's self-collision pairs as MoveIt's Setup Assistant does, with evidence, and writes the SRDF.

    python3 examples/python/audit_srdf.py URDF [--srdf GIVEN.srdf] [--samples 10000] [--seed 1] [--out OUT.srdf]

Prints the pairs whose verdict may mislead (a disabled pair that collides, a checked pair that collides
in most samples), the count per verdict and, with --srdf, the pairs where the given SRDF disagrees.
"""
import argparse

import clearway


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("urdf")
    parser.add_argument("--srdf", help="an SRDF to compare with, kept in --out but for the pairs the audit decides (the audit itself ignores it)")
    parser.add_argument("--samples", type=int, default=10000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", help="write the audit's SRDF here")
    args = parser.parse_args()

    audit = clearway.audit(args.urdf, srdf=args.srdf, samples=args.samples, seed=args.seed)
    for p in audit.pairs:
        if p.warning:
            print(f"warning: {p.link_a} {p.link_b}: {p.warning}")
    counts = audit.counts()
    print(f"{audit.robot_name}: {len(audit.pairs)} pairs: " + ", ".join(f"{n} {r}" for r, n in counts.items()))
    if args.srdf:
        for p in audit.pairs:
            if p.srdf_reason != p.reason:
                evidence = f" ({p.colliding}/{p.samples} colliding, p <= {p.p_upper:.3g})" if p.samples else ""
                print(f"differs: {p.link_a} {p.link_b}: SRDF {p.srdf_reason or 'checked'}, "
                      f"audit {p.reason or 'checked'}{evidence}")
    if args.out:
        with open(args.out, "w") as f:
            f.write(audit.to_srdf())
        print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
