#!/usr/bin/env python3
"""A shipcast forecast subscriber in Python: the reference for console writers in other languages.

Reads the daemon's `<prefix>/forecast` service over iceoryx2 (pip package `iceoryx2`, the same version
as the crate: see requirements.txt) and decodes the payload documented in src/engine/message.rs:
a ForecastHeader user header and a slice of f64, series-major, series s = 6 v + d (vessel v, DOF d in
surge, sway, heave, roll, pitch, yaw), steps + 1 displacements each at issue_time_s + k dt_s, then
as many standard deviations (the forecast's band) in the same order.

    python3 tools/console/subscriber.py --prefix shipcast --count 3

Prints one JSON object per forecast: issue time, dt, the trusted span per vessel (from, to), flags,
and the heave of each vessel and its standard deviation at 0, 30 and 60 s ahead (a non-finite number
is written as null). Waits up to --timeout seconds
for the daemon's service to appear and for the forecasts; exits 1 with a one-line message if they do not,
and skips (with a line on stderr) a payload whose header does not fit its data.
"""

import argparse
import ctypes
import json
import math
import sys
import time

import iceoryx2 as iox2

SCHEMA_VERSION = 3
MAX_VESSELS = 4
DOFS = ["surge", "sway", "heave", "roll", "pitch", "yaw"]
FLAGS = [
    "stale_waves",
    "stale_motion",
    "history_short",
    "numerical_trouble",
    "no_waves",
    "history_gap",
    "no_motion",
    "wave_region_unknown",
    "no_wave_components",
    "waves_dropped",
    "clock_step",
    "clocks_disagree",
    "motion_implausible",
    "motion_restarted",
    "navigation_fallback",
    "quasi_static_waves",
    "model_error_unchecked",
    "waves_frozen",
    "waves_implausible",
    "model_speed_mismatch",
    "motion_settling",
    "motion_clock_apart",
]


class ForecastHeader(ctypes.Structure):
    """shipcast_ForecastHeader_v3 (512 bytes)."""

    _fields_ = [
        ("schema_version", ctypes.c_uint32),
        ("n_vessels", ctypes.c_uint32),
        ("issue_time_s", ctypes.c_double),
        ("dt_s", ctypes.c_double),
        ("steps", ctypes.c_uint32),
        ("n_series", ctypes.c_uint32),
        ("flags", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("wave_time_s", ctypes.c_double),
        ("motion_time_s", ctypes.c_double),
        ("compute_ms", ctypes.c_double),
        ("horizon_s", ctypes.c_double * MAX_VESSELS),
        ("trusted_from_s", ctypes.c_double * MAX_VESSELS),
        ("series_horizon_s", ctypes.c_double * (6 * MAX_VESSELS)),
        ("series_trusted_from_s", ctypes.c_double * (6 * MAX_VESSELS)),
    ]

    @staticmethod
    def type_name() -> str:
        return "shipcast_ForecastHeader_v3"


def decode(header, payload) -> dict:
    if header.schema_version != SCHEMA_VERSION:
        raise ValueError(f"schema version {header.schema_version}: this script reads {SCHEMA_VERSION}")
    if header.n_vessels > MAX_VESSELS:
        raise ValueError(f"n_vessels {header.n_vessels} > {MAX_VESSELS}")
    if header.n_series < 6 * header.n_vessels:
        raise ValueError(f"n_series {header.n_series} < 6 x n_vessels {header.n_vessels}")
    if not (math.isfinite(header.dt_s) and header.dt_s > 0.0):
        raise ValueError(f"dt_s {header.dt_s}")
    n = header.steps + 1
    # the displacements, then their standard deviations
    expected = 2 * header.n_series * n
    count = payload.len()
    # iceoryx2 0.10's Python binding reports the length of a Rust `[f64]` slice in bytes: accept both
    if count not in (expected, 8 * expected):
        raise ValueError(f"{count} values for {header.n_series} series of {n} and their standard deviations")
    values = list((ctypes.c_double * expected).from_address(payload.as_ptr()))
    sigma0 = header.n_series * n
    vessels = []
    for v in range(header.n_vessels):
        heave = values[(6 * v + 2) * n:(6 * v + 3) * n]
        heave_sd = values[sigma0 + (6 * v + 2) * n:sigma0 + (6 * v + 3) * n]
        at, sd = {}, {}
        for lead in (0.0, 30.0, 60.0):
            k = int(round(lead / header.dt_s))
            if k < n:
                at[f"{lead:.0f}"] = finite_or_none(heave[k])
                sd[f"{lead:.0f}"] = finite_or_none(heave_sd[k])
        vessels.append(
            {
                "trusted_from_s": finite_or_none(header.trusted_from_s[v]),
                "horizon_s": finite_or_none(header.horizon_s[v]),
                "dof_spans_s": {
                    dof: [
                        finite_or_none(header.series_trusted_from_s[6 * v + d]),
                        finite_or_none(header.series_horizon_s[6 * v + d]),
                    ]
                    for d, dof in enumerate(DOFS)
                },
                "heave_at_lead_s": at,
                "heave_sigma_at_lead_s": sd,
            }
        )
    return {
        "issue_time_s": header.issue_time_s,
        "dt_s": header.dt_s,
        "steps": header.steps,
        "compute_ms": header.compute_ms,
        "flags": [f for i, f in enumerate(FLAGS) if header.flags & (1 << i)],
        "vessels": vessels,
    }


def open_forecasts(node, prefix: str, timeout_s: float):
    """The daemon's forecast service, waited for up to timeout_s; None if it never appears."""
    t0 = time.monotonic()
    while True:
        try:
            return (
                node.service_builder(iox2.ServiceName.new(f"{prefix}/forecast"))
                .publish_subscribe(iox2.Slice[ctypes.c_double])
                .user_header(ForecastHeader)
                .open()
            )
        except iox2.PublishSubscribeOpenError as e:
            if "DoesNotExist" not in str(e) or time.monotonic() - t0 > timeout_s:
                if "DoesNotExist" not in str(e):
                    print(f"cannot open {prefix}/forecast: {e}", file=sys.stderr)
                return None
            time.sleep(0.2)


def finite_or_none(x: float):
    return x if math.isfinite(x) else None


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--prefix", default="shipcast")
    ap.add_argument("--count", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=30.0)
    a = ap.parse_args()
    iox2.set_log_level_from_env_or(iox2.LogLevel.Error)
    node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
    t0 = time.monotonic()
    service = open_forecasts(node, a.prefix, a.timeout)
    if service is None:
        print(
            f"no shipcast daemon publishes {a.prefix}/forecast (waited {a.timeout:g} s): start `shipcast run`, "
            "or give its [ipc] service_prefix with --prefix",
            file=sys.stderr,
        )
        return 1
    subscriber = service.subscriber_builder().create()
    seen = 0
    while seen < a.count:
        if time.monotonic() - t0 > a.timeout:
            print(f"no forecast within {a.timeout} s", file=sys.stderr)
            return 1
        sample = subscriber.receive()
        if sample is None:
            time.sleep(0.05)
            continue
        try:
            decoded = decode(sample.user_header().contents, sample.payload())
        except ValueError as e:
            print(f"forecast refused: {e}", file=sys.stderr)
            continue
        print(json.dumps(decoded, allow_nan=False), flush=True)
        seen += 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
