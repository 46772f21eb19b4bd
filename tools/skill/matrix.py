#!/usr/bin/env python3
"""The skill of shipcast's forecasts over a matrix of synthetic sea states (issue 28; docs/skill.md,
"The sea-state matrix"). Each case is `shipcast simulate --record` of the config with some keys changed
(SHIPCAST_* environment variables), then `shipcast replay --report`; the table is Markdown, printed and
written to OUTDIR/matrix.md, each case's report kept in OUTDIR/<case>.

Usage: cargo build --release, then
       python3 tools/skill/matrix.py [--shipcast target/release/shipcast] [--config config/shipcast.toml]
                                     [--duration 1800] [--only CASE,CASE] [--tables-only] OUTDIR

Standard library only. What is scored against what: see `shipcast replay --help` (the truth motion the
simulator recorded)."""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

# (name, what it is, the keys changed). The descriptions are config/shipcast.toml's (another config's
# heading makes them wrong): Hs 2 m, Tp 9 s, long-crested, travelling north with the ships heading
# east (beam seas from starboard), radar blind zone 200 m, range 1 km, sector 160-200 deg masked.
CASES = [
    ("default", "the config's: beam seas from starboard, Hs 2 m, Tp 9 s, long-crested", {}),
    ("short-crested", "the same, cos-2s spreading s = 8", {"SIMULATE__SEA__SPREADING_S": "8"}),
    ("steep", "beam, Hs 3.5 m, Tp 11 s", {"SIMULATE__SEA__HS_M": "3.5", "SIMULATE__SEA__TP_S": "11"}),
    ("short-period", "beam, Hs 1.2 m, Tp 7 s", {"SIMULATE__SEA__HS_M": "1.2", "SIMULATE__SEA__TP_S": "7"}),
    ("head", "head seas (from the bow), Hs 2 m, Tp 9 s", {"SIMULATE__SEA__TOWARDS_DEG": "270"}),
    ("masked", "following seas, from inside the masked sector", {"SIMULATE__SEA__TOWARDS_DEG": "90"}),
    ("quartering", "bow-quartering from starboard, spreading s = 4",
     {"SIMULATE__SEA__TOWARDS_DEG": "315", "SIMULATE__SEA__SPREADING_S": "4"}),
]
DOFS = ["heave", "roll", "pitch"]


def run(cmd, env):
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr[-2000:]}")


def at_lead(curve, leads, lead):
    """The value at the scored lead nearest `lead`."""
    i = min(range(len(leads)), key=lambda j: abs(leads[j] - lead))
    return curve[i]


def at_end(curve, leads, lead):
    """The value at `lead`, linear between the scored leads around it."""
    for i in range(1, len(leads)):
        if leads[i] >= lead:
            a = (lead - leads[i - 1]) / (leads[i] - leads[i - 1])
            return curve[i - 1] + a * (curve[i] - curve[i - 1])
    return curve[-1]


def summarize(j):
    """Per vessel: heave's and roll's own trusted spans (median, `spans_s`), correlations at 30 / 60 s,
    each channel's NRMSE at its span's end and coverage inside its span, and coverage at every lead."""
    leads = j["lead_s"]
    rows = []
    for vessel, dofs in j["vessels"].items():
        spans = {d: tuple(j["spans_s"][vessel][d]) for d in DOFS}
        past_zero = [i for i, l in enumerate(leads) if l > 0]
        cov, cov_all, nrmse_end = {}, {}, {}
        for d in DOFS:
            span = spans[d]
            inside = [i for i, l in enumerate(leads) if span[0] <= l <= span[1]] if span[1] > 0 else []
            finite = lambda idx: [dofs[d]["coverage_90"][i] for i in idx if dofs[d]["coverage_90"][i] == dofs[d]["coverage_90"][i]]
            c = finite(inside)
            cov[d] = (min(c), max(c)) if c else None
            c = finite(past_zero)
            cov_all[d] = (min(c), max(c)) if c else None
            nrmse_end[d] = at_end(dofs[d]["nrmse"], leads, span[1]) if span[1] > 0 else None
        rows.append(dict(
            vessel=vessel, spans=spans,
            corr={d: (at_lead(dofs[d]["correlation"], leads, 30), at_lead(dofs[d]["correlation"], leads, 60)) for d in DOFS},
            nrmse_end=nrmse_end, cov=cov, cov_all=cov_all))
    return rows


def fmt_pair(p):
    return f"{p[0]:.2f} / {p[1]:.2f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("outdir")
    ap.add_argument("--shipcast", default="target/release/shipcast")
    ap.add_argument("--config", default="config/shipcast.toml")
    ap.add_argument("--duration", type=float, default=1800.0)
    ap.add_argument("--only", help="case names, comma-separated")
    ap.add_argument("--tables-only", action="store_true",
                    help="no runs: the table of the reports already in OUTDIR/<case>")
    a = ap.parse_args()
    os.makedirs(a.outdir, exist_ok=True)
    lines = [
        f"Config `{a.config}`, {a.duration:.0f} s per case, `{' '.join(sys.argv)}`.",
        "",
        "| case | vessel | heave span (median, s) | roll span (median, s) | heave corr 30 / 60 s | roll corr 30 / 60 s | NRMSE at each span's end: heave; roll | coverage_90 inside each one's span: heave; roll; pitch | coverage_90 at every lead past 0: heave; roll; pitch |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, what, keys in CASES:
        if a.only and name not in a.only.split(","):
            continue
        env = dict(os.environ, **{f"SHIPCAST_{k}": v for k, v in keys.items()})
        log = os.path.join(a.outdir, f"{name}.mcap")
        rep = os.path.join(a.outdir, name)
        t = time.time()
        if not a.tables_only:
            run([a.shipcast, "simulate", "--config", a.config, "--record", log, "--duration", str(a.duration)], env)
            run([a.shipcast, "replay", log, "--config", a.config, "--report", rep], env)
            os.remove(log)
        j = json.load(open(os.path.join(rep, "skill.json")))
        for r in summarize(j):
            nr = r["nrmse_end"]
            nrmse = "; ".join("-" if nr[d] is None else f"{nr[d]:.2f}" for d in ("heave", "roll"))
            span_of = lambda c: "; ".join("-" if c[d] is None else f"{c[d][0]:.2f}-{c[d][1]:.2f}" for d in DOFS)
            cov = span_of(r["cov"]) + " | " + span_of(r["cov_all"])
            sp = lambda d: f"{r['spans'][d][0]:.0f}-{r['spans'][d][1]:.0f}"
            lines.append(f"| {name}: {what} | {r['vessel']} | {sp('heave')} | {sp('roll')} | "
                         f"{fmt_pair(r['corr']['heave'])} | {fmt_pair(r['corr']['roll'])} | {nrmse} | {cov} |")
        print(f"{name}: {time.time() - t:.0f} s", file=sys.stderr)
    text = "\n".join(lines) + "\n"
    open(os.path.join(a.outdir, "matrix.md"), "w").write(text)
    print(text)


if __name__ == "__main__":
    main()
