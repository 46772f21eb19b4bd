#!/usr/bin/env python3
"""How far one log's `coverage_90` strays from 0.90 when the band is exactly right (docs/skill.md,
"The band and the span"). The error is a sum of a slow part (a first-order Gauss-Markov process of
correlation time TAU, as an IMU's drift) and a white part, of total variance 1; the band is the
normal 90 % band of that variance; a log of DURATION seconds scored once a second. Prints, over RUNS
draws, the mean coverage, its 5-95 % range, and how often it falls inside 0.85-0.95 and above 0.95.

Usage: python3 tools/skill/coverage_spread.py [--duration 1800] [--tau 600] [--slow 1.0,0.8,0.5]
                                              [--runs 2000] [--seed 1]

Standard library only."""

import argparse
import math
import random

Z90 = 1.6448536269514722


def coverage(rng, duration_s, tau_s, slow_share):
    a = math.exp(-1.0 / tau_s)
    b = math.sqrt(1.0 - a * a)
    fast = math.sqrt(1.0 - slow_share)
    slow = math.sqrt(slow_share)
    x = rng.gauss(0.0, 1.0)
    inside = 0
    n = int(duration_s)
    for _ in range(n):
        e = slow * x + fast * rng.gauss(0.0, 1.0)
        inside += abs(e) <= Z90
        x = a * x + b * rng.gauss(0.0, 1.0)
    return inside / n


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--duration", type=float, default=1800.0, help="the log's length, s")
    ap.add_argument("--tau", type=float, default=600.0, help="the slow part's correlation time, s")
    ap.add_argument("--slow", default="1.0,0.8,0.5", help="the slow part's shares of the variance")
    ap.add_argument("--runs", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    print(f"| slow share | mean | 5-95 % | inside 0.85-0.95 | above 0.95 |  ({a.duration:.0f} s, tau {a.tau:.0f} s, {a.runs} draws)")
    print("|---|---|---|---|---|")
    for share in (float(s) for s in a.slow.split(",")):
        c = sorted(coverage(rng, a.duration, a.tau, share) for _ in range(a.runs))
        q = lambda p: c[min(len(c) - 1, int(p * len(c)))]
        inside = sum(0.85 <= x <= 0.95 for x in c) / len(c)
        above = sum(x > 0.95 for x in c) / len(c)
        print(f"| {share:.1f} | {sum(c) / len(c):.3f} | {q(0.05):.2f}-{q(0.95):.2f} | {inside:.2f} | {above:.2f} |")


if __name__ == "__main__":
    main()
