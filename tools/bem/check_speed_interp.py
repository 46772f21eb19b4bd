#!/usr/bin/env python3
"""How well does interpolation in forward speed reproduce a database solved directly at that speed?

Reads back the WAMIT files written by `make_db.py --preset barge-speeds OUTDIR` (conventions: make_db.py's
docstring, or OUTDIR/bem_info.toml `convention`): the speed set listed in OUTDIR/system.toml ([[database]]) and the
database solved directly at the target speed (`--direct direct_u3 --speed 3`), and measures
- linear interpolation in U between the two set speeds around the target (u2, u4 for 3 m/s),
- quadratic (Lagrange) interpolation through the three set speeds nearest the target (u0, u2, u4),
for A(w_e) and B(w_e) (each entry ij a curve over the encounter frequency) and X(w, beta) (complex, each
mode and heading a curve over the wave frequency), over the band --band (0.3-2.5 rad/s):
  per curve, the worst |interpolated - direct| relative to that curve's peak |direct| (`of peak`, curves
  whose peak is at least --small of the mode's scale) and relative to the mode's scale (`of mode`, all
  curves): for A_ij and B_ij sqrt(P_ii P_jj), P the diagonal curves' peaks; for X_i the largest peak of
  mode i over the headings. Prints the worst per quantity and method, with where.

Also (consistency of the files): the RAO solved from the direct database's .1/.3/.hst and system.toml at
heading 90 deg (where w_e = w, on the .1's grid) against Capytaine's own RAO (capytaine_rao_u3.csv), and,
with --against DIR, the zero-speed set against another database of the same hull (e.g. config/vessels/barge)
at their common frequencies and headings.

Usage: python3 tools/bem/check_speed_interp.py tests/data/capytaine-barge-speeds [--against config/vessels/barge]
"""

import argparse
import os
import tomllib

import numpy as np

MODES = ["surge", "sway", "heave", "roll", "pitch", "yaw"]


def read_1(path, rho):
    """A(w), B(w) (SI, [iw, i, j]: force in mode i due to motion j), their frequencies, and A at PER = 0."""
    rows = np.loadtxt(path, ndmin=2, usecols=(0, 1, 2, 3))
    full = [ln.split() for ln in open(path) if ln.strip()]
    per = rows[:, 0]
    n = int(rows[:, 1].max())
    pos = per > 0
    periods = np.unique(per[pos])
    omegas = np.sort(2 * np.pi / periods)
    a = np.zeros((len(omegas), n, n))
    b = np.zeros((len(omegas), n, n))
    a_inf = None
    for f in full:
        p, i, j = float(f[0]), int(f[1]) - 1, int(f[2]) - 1
        if p == 0.0:
            a_inf = np.zeros((n, n)) if a_inf is None else a_inf
            a_inf[i, j] = rho * float(f[3])
        elif p > 0:
            w = 2 * np.pi / p
            k = int(np.argmin(np.abs(omegas - w)))
            a[k, i, j] = rho * float(f[3])
            b[k, i, j] = rho * w * float(f[4])
    return omegas, a, b, a_inf


def read_3(path, rho, g):
    """X(w, beta) (SI, complex, exp(+i w t), [iw, ib, i]), frequencies and headings (deg)."""
    rows = np.loadtxt(path, ndmin=2)
    omegas = np.unique(np.round(2 * np.pi / rows[:, 0], 10))
    heads = np.unique(rows[:, 1])
    n = int(rows[:, 2].max())
    x = np.zeros((len(omegas), len(heads), n), dtype=complex)
    for r in rows:
        k = int(np.argmin(np.abs(omegas - 2 * np.pi / r[0])))
        ib = int(np.argmin(np.abs(heads - r[1])))
        x[k, ib, int(r[2]) - 1] = rho * g * (r[5] + 1j * r[6])
    return omegas, heads, x


def read_hst(path, rho, g):
    rows = np.loadtxt(path, ndmin=2)
    n = int(rows[:, 0].max())
    c = np.zeros((n, n))
    for r in rows:
        c[int(r[0]) - 1, int(r[1]) - 1] = rho * g * r[2]
    return c


def mass_matrix(body):
    """6x6 rigid-body mass matrix about the reference point from a system.toml [[body]]."""
    m = body["mass"]
    x, y, z = body["centre_of_gravity"]
    skew = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    cg = np.array([x, y, z])
    io = np.diag([m * r**2 for r in body["radii_of_gyration"]]) + m * (cg @ cg * np.eye(3) - np.outer(cg, cg))
    mm = np.zeros((6, 6))
    mm[:3, :3] = m * np.eye(3)
    mm[:3, 3:] = -m * skew
    mm[3:, :3] = m * skew
    mm[3:, 3:] = io
    return mm


def load(outdir, stem, rho, g):
    wr, a, b, a_inf = read_1(os.path.join(outdir, stem + ".1"), rho)
    wx, heads, x = read_3(os.path.join(outdir, stem + ".3"), rho, g)
    return dict(w_rad=wr, a=a, b=b, a_inf=a_inf, w_exc=wx, heads=heads, x=x,
                c=read_hst(os.path.join(outdir, stem + ".hst"), rho, g))


def lagrange(speeds, target):
    w = []
    for k, uk in enumerate(speeds):
        lk = 1.0
        for m, um in enumerate(speeds):
            if m != k:
                lk *= (target - um) / (uk - um)
        w.append(lk)
    return w


def curve_errors(direct, approx, band, kind, small):
    """direct, approx: [iw, ...curves...] over the band; returns per-curve (of_peak or None, of_mode, where)."""
    d = direct[band]
    e = np.abs(approx[band] - d)
    peak = np.abs(d).max(axis=0)
    worst = e.max(axis=0)
    at = e.argmax(axis=0)
    if kind == "rad":  # [iw, i, j]
        diag = np.diagonal(peak)
        scale = np.sqrt(np.outer(diag, diag))
    else:  # [iw, ib, i]
        scale = np.broadcast_to(peak.max(axis=0)[None, :], peak.shape)
    of_mode = worst / np.where(scale > 0, scale, np.inf)
    of_peak = np.where(peak >= small * scale, worst / np.where(peak > 0, peak, np.inf), np.nan)
    return of_peak, of_mode, at


def report(name, direct, approx, omegas, band, kind, small, heads=None):
    of_peak, of_mode, at = curve_errors(direct, approx, band, kind, small)
    wb = omegas[band]

    def where(idx):
        if kind == "rad":
            i, j = idx
            return f"{MODES[i]}-{MODES[j]} ({i + 1},{j + 1}) at w_e = {wb[at[idx]]:.2f}"
        ib, i = idx
        return f"{MODES[i]} ({i + 1}), beta {heads[ib]:g} deg, at w = {wb[at[idx]]:.2f}"

    ip = np.unravel_index(np.nanargmax(of_peak), of_peak.shape)
    im = np.unravel_index(np.argmax(of_mode), of_mode.shape)
    # the diagonal / largest curves alone (kind rad: A_ii, B_ii)
    text = (f"  {name:<3s} {100 * of_peak[ip]:7.3f} % of peak ({where(ip)}); "
            f"{100 * of_mode[im]:7.3f} % of mode ({where(im)})")
    if kind == "rad":
        dg = np.array([of_peak[i, i] for i in range(of_peak.shape[0])])
        k = int(np.nanargmax(dg))
        text += f"; diagonal worst {100 * dg[k]:.3f} % of peak ({where((k, k))})"
    print(text)
    if kind == "exc":  # per mode: the worst over its headings
        for i in range(of_peak.shape[1]):
            if np.all(np.isnan(of_peak[:, i])):
                continue
            ib = int(np.nanargmax(of_peak[:, i]))
            jb = int(np.argmax(of_mode[:, i]))
            print(f"      {MODES[i]:<5s} {100 * of_peak[ib, i]:7.3f} % of peak ({where((ib, i))}); "
                  f"{100 * of_mode[jb, i]:7.3f} % of mode ({where((jb, i))})")
    return of_peak, of_mode


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("outdir")
    ap.add_argument("--direct", default="direct_u3", help="stem of the database solved at the target speed")
    ap.add_argument("--speed", type=float, default=3.0, help="the target speed, m/s")
    ap.add_argument("--band", type=float, nargs=2, default=(0.3, 2.5), help="rad/s")
    ap.add_argument("--small", type=float, default=0.05,
                    help="curves with a peak below this fraction of the mode's scale count `of mode` only")
    ap.add_argument("--against", help="a zero-speed database directory of the same hull (its system.toml's wamit)")
    args = ap.parse_args()
    system = tomllib.load(open(os.path.join(args.outdir, "system.toml"), "rb"))
    rho, g = system["rho"], system["g"]
    sset = sorted(tomllib.load(open(os.path.join(args.outdir, "system.toml"), "rb"))["database"],
                  key=lambda d: d["speed_m_s"])
    dbs = {d["speed_m_s"]: load(args.outdir, d["wamit"], rho, g) for d in sset}
    direct = load(args.outdir, args.direct, rho, g)
    u = np.array(sorted(dbs))
    target = args.speed
    for d in dbs.values():
        assert np.allclose(d["w_rad"], direct["w_rad"]) and np.allclose(d["w_exc"], direct["w_exc"])
        assert np.allclose(d["heads"], direct["heads"])
    lo, hi = u[u < target].max(), u[u > target].min()
    near3 = u[np.argsort(np.abs(u - target), kind="stable")[:3]]
    near3.sort()
    methods = [(f"linear in U through {lo:g}, {hi:g} m/s", [lo, hi]),
               (f"quadratic in U through {', '.join(f'{s:g}' for s in near3)} m/s", list(near3))]
    band_r = (direct["w_rad"] >= args.band[0] - 1e-9) & (direct["w_rad"] <= args.band[1] + 1e-9)
    band_x = (direct["w_exc"] >= args.band[0] - 1e-9) & (direct["w_exc"] <= args.band[1] + 1e-9)
    print(f"{args.outdir}: {args.direct} (U = {target:g} m/s) against interpolation in speed; band "
          f"{args.band[0]}-{args.band[1]} rad/s; `of peak`: curves with a peak >= {args.small:g} of the mode's scale")
    for label, us in methods:
        wts = lagrange(us, target)
        print(f"{label} (weights {', '.join(f'{w:+.4f}' for w in wts)}):")
        for name, key, kind, w in (("A", "a", "rad", "w_rad"), ("B", "b", "rad", "w_rad"), ("X", "x", "exc", "w_exc")):
            approx = sum(wk * dbs[uk][key] for wk, uk in zip(wts, us))
            report(name, direct[key], approx, direct[w], band_r if kind == "rad" else band_x, kind, args.small,
                   heads=direct["heads"])

    # consistency: the RAO solved from the direct database's files against Capytaine's, at beta = 90 deg
    rao_path = os.path.join(args.outdir, f"capytaine_rao_u{target:g}.csv")
    if os.path.exists(rao_path):
        body = system["body"][0]
        mm = mass_matrix(body)
        blin = np.array(body.get("linear_damping", np.zeros((6, 6))))
        cap = np.loadtxt(rao_path, delimiter=",", skiprows=1)
        ib = int(np.argmin(np.abs(direct["heads"] - 90.0)))
        worst = np.zeros(6)
        peak = np.zeros(6)
        for k, w in enumerate(direct["w_exc"]):
            kr = int(np.argmin(np.abs(direct["w_rad"] - w)))  # w_e = w at 90 deg
            h = (-w**2 * (mm + direct["a"][kr]) + 1j * w * (direct["b"][kr] + blin) + direct["c"])
            xi = np.linalg.solve(h, direct["x"][k, ib])
            rows = cap[(np.abs(cap[:, 0] - w) < 1e-6) & (np.abs(cap[:, 1] - 90.0) < 1e-6)]
            for r in rows:
                i = int(r[2]) - 1
                c = r[3] * np.exp(1j * np.radians(r[4]))
                worst[i] = max(worst[i], abs(xi[i] - c))
                peak[i] = max(peak[i], abs(c))
        print(f"RAO from the {args.direct} files against {os.path.basename(rao_path)} at beta = 90 deg: worst "
              + ", ".join(f"{MODES[i]} {100 * worst[i] / peak[i]:.2e} %" for i in range(6) if peak[i] > 0)
              + " of the curve's peak")

    if args.against:
        other_sys = tomllib.load(open(os.path.join(args.against, "system.toml"), "rb"))
        other = load(args.against, other_sys["wamit"], other_sys["rho"], other_sys["g"])
        zero = dbs[0.0]
        ia = [int(np.argmin(np.abs(other["w_rad"] - w))) for w in zero["w_rad"]]
        common = np.array([abs(other["w_rad"][k] - w) < 1e-6 for k, w in zip(ia, zero["w_rad"])])
        ka = np.array(ia)[common]
        out = []
        for name, key in (("A", "a"), ("B", "b")):
            d = zero[key][common]
            o = other[key][ka]
            diag = np.abs(np.diagonal(d, axis1=1, axis2=2)).max(axis=0)
            scale = np.sqrt(np.outer(diag, diag))
            rel = np.abs(d - o).max(axis=0) / np.where(scale > 0, scale, np.inf)
            i, j = np.unravel_index(np.argmax(rel), rel.shape)
            out.append(f"{name} {100 * rel[i, j]:.2e} % ({MODES[i]}-{MODES[j]})")
        ix = [int(np.argmin(np.abs(other["w_exc"] - w))) for w in zero["w_exc"]]
        cx = np.array([abs(other["w_exc"][k] - w) < 1e-6 for k, w in zip(ix, zero["w_exc"])])
        hb = [int(np.argmin(np.abs(other["heads"] - h))) for h in zero["heads"]]
        assert np.allclose(other["heads"][hb], zero["heads"])
        d = zero["x"][cx]
        o = other["x"][np.array(ix)[cx]][:, hb]
        rel = np.abs(d - o).max(axis=(0, 1)) / np.abs(d).max(axis=(0, 1))
        out.append(f"X {100 * rel.max():.2e} % ({MODES[int(rel.argmax())]})")
        lim = np.abs(zero["a_inf"] - other["a_inf"]).max() / np.abs(np.diagonal(other["a_inf"])).max()
        out.append(f"A_inf {100 * lim:.2e} %")
        out.append(f"C {np.abs(zero['c'] - other['c']).max() / np.abs(other['c']).max():.2e}")
        print(f"{sset[0]['wamit']} against {args.against} at {int(common.sum())} common frequencies "
              f"({int(cx.sum())} for X), headings {', '.join(f'{h:g}' for h in zero['heads'])}: worst "
              + "; ".join(out) + " (of the mode's scale)")


if __name__ == "__main__":
    main()
