#!/usr/bin/env python3
"""How long a forecast takes from the newest motion sample to a subscriber, live (issue 53, item 1).

Runs `shipcast run` and `shipcast simulate --publish` on a config (the simulator paces its samples at
their stamps, on the wall clock) and `shipcast watch --json` as the subscriber, for DURATION seconds;
for every forecast received after WARMUP seconds, the latency is the wall time it was received less its
issue time (the stamp of the newest motion it starts from), and its compute time the daemon's own
(`compute_ms`). Prints the median, p90, p99 and largest of each, and the count; then the breakdown by
stage the daemon's status gives for each forecast (`latency.stages_ms`: received, waited, queued,
forecast, band, handed; src/engine/latency.rs), with `delivered` the rest (the output thread,
iceoryx2, the subscriber's wake-up), and the daemon's own running p50 / p99.

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
    ap.add_argument("--apart", action="store_true",
                    help="the daemon on CPU 0, the simulated sensors and the subscriber on CPU 1 (taskset): "
                         "on board the radar processor and the motion sensors are other computers")
    a = ap.parse_args()
    on = lambda cpu: (["taskset", "-c", str(cpu)] if a.apart else [])
    # a prefix of its own: nothing else on the host is measured
    env = dict(os.environ, SHIPCAST_IPC__SERVICE_PREFIX=f"shipcast-latency-{os.getpid()}")
    logs = tempfile.mkdtemp(prefix="shipcast-latency-")
    err = lambda name: open(os.path.join(logs, name), "w")
    daemon = subprocess.Popen(on(0) + [a.shipcast, "run", "--config", a.config], env=env, stderr=err("run.log"))
    time.sleep(3.0)
    sim = subprocess.Popen(on(1) + [a.shipcast, "simulate", "--publish", "--config", a.config, "--duration",
                            str(a.duration + 30)], env=env, stderr=err("simulate.log"), stdout=subprocess.DEVNULL)
    watch = subprocess.Popen(on(1) + [a.shipcast, "watch", "--json", "--config", a.config], env=env,
                             stdout=subprocess.PIPE, stderr=err("watch.log"), text=True)
    start = time.time()
    latency_ms, compute_ms = [], []
    received = {}  # issue time -> latency at the subscriber, ms
    stages = {}  # issue time -> the daemon's stages, ms
    last_status = None
    try:
        for line in watch.stdout:
            if time.time() - start > a.duration:
                break
            m = json.loads(line)
            if time.time() - start < a.warmup:
                continue
            if m.get("kind") == "status":
                # a status carries the stages of the last forecast published before it
                if m.get("latency") and m.get("last_forecast_time_s") is not None:
                    stages[m["last_forecast_time_s"]] = m["latency"]["stages_ms"]
                    last_status = m
                continue
            if m.get("kind") != "forecast":
                continue
            latency_ms.append(1e3 * (m["received_wall_s"] - m["issue_time_s"]))
            received[m["issue_time_s"]] = latency_ms[-1]
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
    both = [t for t in received if t in stages]
    if both:
        print(f"by stage ({len(both)} forecasts): median / p90 / p99 / largest, ms")
        names = list(stages[both[0]].keys()) + ["delivered"]
        for name in names:
            if name == "delivered":
                xs = [max(0.0, received[t] - sum(v or 0.0 for v in stages[t].values())) for t in both]
            else:
                xs = [stages[t][name] or 0.0 for t in both]
            print(f"  {name:10s} {statistics.median(xs):7.1f} {quantile(xs, 0.9):7.1f} "
                  f"{quantile(xs, 0.99):7.1f} {max(xs):7.1f}")
        # the forecasts whose latency was in the top 1 %: which stage took their time
        worst = sorted(both, key=lambda t: -received[t])[:max(1, len(both) // 100)]
        for t in worst:
            parts = ", ".join(f"{k} {v or 0.0:.1f}" for k, v in stages[t].items())
            print(f"  slowest: {received[t]:.1f} ms ({parts})")
    if last_status:
        lat = last_status["latency"]
        print(f"the daemon's own running figures (stamp to hand-over): p50 {lat['p50_ms']} ms, p99 {lat['p99_ms']} ms")


if __name__ == "__main__":
    main()
