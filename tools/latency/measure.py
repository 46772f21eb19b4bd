#!/usr/bin/env python3
"""How long a forecast takes from the newest motion sample to a subscriber, live (issue 53, item 1).

Runs `shipcast run` and `shipcast simulate --publish` on a config (the simulator paces its samples at
their stamps, on the wall clock) and `shipcast watch --json` as the subscriber, for DURATION seconds;
for every forecast received after WARMUP seconds, the latency is the wall time it was received less its
issue time (the stamp of the newest motion it starts from), and its compute time the daemon's own
(`compute_ms`). Prints the median, p90, p99 and largest of each, and the count.

Usage: cargo build --release, then
       python3 tools/latency/measure.py [--shipcast target/release/shipcast] [--config config/shipcast.toml]
                                        [--duration 600] [--warmup 60]

Standard library only."""

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time


def quantile(xs, q):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(q * (len(xs) - 1) + 0.5))]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--shipcast", default="target/release/shipcast")
    ap.add_argument("--config", default="config/shipcast.toml")
    ap.add_argument("--duration", type=float, default=600.0)
    ap.add_argument("--warmup", type=float, default=60.0)
    a = ap.parse_args()
    # a prefix of its own: nothing else on the host is measured
    env = dict(os.environ, SHIPCAST_IPC__SERVICE_PREFIX=f"shipcast-latency-{os.getpid()}")
    logs = tempfile.mkdtemp(prefix="shipcast-latency-")
    err = lambda name: open(os.path.join(logs, name), "w")
    daemon = subprocess.Popen([a.shipcast, "run", "--config", a.config], env=env, stderr=err("run.log"))
    time.sleep(3.0)
    sim = subprocess.Popen([a.shipcast, "simulate", "--publish", "--config", a.config, "--duration",
                            str(a.duration + 30)], env=env, stderr=err("simulate.log"), stdout=subprocess.DEVNULL)
    watch = subprocess.Popen([a.shipcast, "watch", "--json", "--config", a.config], env=env,
                             stdout=subprocess.PIPE, stderr=err("watch.log"), text=True)
    start = time.time()
    latency_ms, compute_ms = [], []
    try:
        for line in watch.stdout:
            if time.time() - start > a.duration:
                break
            m = json.loads(line)
            if m.get("kind") != "forecast" or time.time() - start < a.warmup:
                continue
            latency_ms.append(1e3 * (m["received_wall_s"] - m["issue_time_s"]))
            compute_ms.append(m["compute_ms"])
    finally:
        for p in (watch, sim, daemon):
            p.send_signal(signal.SIGINT)
        for p in (watch, sim, daemon):
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
    if not latency_ms:
        sys.exit(f"no forecast received (logs in {logs})")
    for name, xs in (("newest sample to received", latency_ms), ("compute (the daemon's)", compute_ms)):
        print(f"{name}: median {statistics.median(xs):.1f} ms, p90 {quantile(xs, 0.9):.1f} ms, "
              f"p99 {quantile(xs, 0.99):.1f} ms, largest {max(xs):.1f} ms ({len(xs)} forecasts)")


if __name__ == "__main__":
    main()
