#!/usr/bin/env python3
"""An independent wave and ship-motion simulator: a test recording of the barge in head seas with a
wave probe 600 m up-wave, for `shipcast import` / `shipcast replay`.

What it is. A frequency-domain linear superposition, numpy only: it uses NO shipcast code and NOT
shipcast's time-domain (Cummins) model, only Capytaine's own motion RAO of the barge
(config/vessels/barge/capytaine_rao.csv, written by tools/bem/make_db.py --preset barge from
Capytaine's `post_pro.rao`, i.e. solved in the frequency domain by Capytaine itself). A forecaster
that reproduces these motions from the probe record does so through physics, not through sharing
code with the generator.

Command that made tests/data/indep-barge-probe/ (from the repository root; any Python 3 with numpy: here
a venv made by `python3 -m venv target/tmp/py-venv && target/tmp/py-venv/bin/pip install numpy`, numpy
2.4.6, Python 3.11.7; 1.5 s):
    target/tmp/py-venv/bin/python tools/indep/barge_probe.py --out tests/data/indep-barge-probe
(defaults: --seed 20260601 --components 2000 --duration 1500). It prints a few sanity figures.

The sea. Long-crested JONSWAP, Hs 1.5 m, Tp 8 s, gamma 3.3 (sigma 0.07 / 0.09), normalized so that its
integral over 0..inf is Hs^2 / 16; deep water, g = 9.81 m/s^2. N = 2000 components with frequencies
drawn uniformly at random in 0.25..2.0 rad/s (sorted; not on a grid, so the record never repeats and no
fitter can hit the components exactly), each of width dw_j = its Voronoi cell on the frequency axis (the
half-gaps to its neighbours, the band edges at the ends: the dw_j add up to the band exactly), amplitude
a_j = sqrt(2 S(w_j) dw_j), phase phi_j uniform in [0, 2 pi). The band keeps about 98 % of the variance
(printed: the band's own Hs).

Geometry (earth frame east-north-up, x east, y north; DESIGN.md section 1). The barge's reference point
is at the origin, its +x (bow) pointing east (compass heading 090). The waves travel to compass 270
(west), i.e. direction d = (-1, 0) in the earth frame, and to -x in the body frame: wave heading
beta = 180 deg (head seas). A regular component is
    eta_j(x, t) = a_j cos(w_j t - k_j d.x + phi_j),   k_j = w_j^2 / g,
so phi_j is its phase at the origin at t = 0. The probe is fixed at east 600 m, north 0 (600 m up-wave:
the waves pass it first): eta_probe(t) = sum_j a_j cos(w_j t + 600 k_j + phi_j).

Motions (body frame x forward, y port, z up; rotations about the reference point; DESIGN.md section 1):
    x_i(t) = sum_j |R_i(w_j)| a_j cos(w_j t + phi_j + arg R_i(w_j)),
R_i = Capytaine's RAO of mode i at heading 180 deg, interpolated linearly in omega in its real and
imaginary parts (zero outside the table's 0.2..3.0 rad/s; the band here lies inside it). All six DOFs;
in head seas sway, roll and yaw are zero to round-off (RAO ~1e-16).

RAO convention, confirmed (not assumed) before relying on it:
- tools/bem/make_db.py lines 673-675: `r = np.conj(rao...)` then write_rao_csv (lines 521-529): the file
  holds Capytaine's RAO conjugated into exp(+i w t), amplitude = |r|, phase_deg = degrees(angle(r)); the
  module docstring (lines 7-15) and DESIGN.md section 1 (lines 23-24, 29-31, 61-62) ("Motion RAO output: x_i(t) = Re{ Xi_i exp(i w t) }
  for a unit-amplitude wave whose crest is at the seakeeping-frame origin at t = 0"; "A wave heading beta
  is the direction the wave travels to, counterclockwise from the vessel's +x: beta = 180 deg is head
  seas") say the same.
- tests/capytaine_barge.rs lines 45-57 (with tests/util.rs rao_worst, lines 113-142: the complex
  difference) compares `shipcast rao` (DESIGN.md's RAO output convention) with this file row by row at
  equal (omega, heading_deg, mode), amplitude and phase, headings 90-180 deg: one convention.
- Physical check on the file's heading-180 rows at 0.2 rad/s (long waves, the barge follows the surface):
  heave 0.99982 at +0.00002 deg (follows eta); surge 0.9908 at +90 deg (the particle orbit's horizontal
  displacement, -a sin(w t) along +x for waves travelling to -x: Re{i a e^(i w t)}); pitch 4.066e-3 rad/m
  = k (0.00408) at -90 deg (pitch positive bow down, about +y: theta = -d(eta)/dx = a k sin(w t) at the
  origin = Re{-i a k e^(i w t)}). All as response = Re{ amplitude exp(i phase) a exp(i w t) } for the wave
  Re{ a exp(i w t) } at the origin, with heading 180 travelling to -x.

Outputs, in --out (layouts of src/shell/replay/import.rs, top comment):
  motion.csv  time_s,vessel,surge_m,sway_m,heave_m,roll_deg,pitch_deg,yaw_deg  at 5 Hz, 0..1500 s,
              vessel `barge`, with sensor noise: heave white 0.01 m std, roll and pitch white 0.05 deg std
              (surge, sway and yaw noise-free)
  truth.csv   the same layout and times, no noise
  probe.csv   time_s,elevation_m,east_m,north_m,towards_deg  at 2 Hz, 0..1500 s, white noise 0.02 m std,
              east_m 600, north_m 0, towards_deg 270 (compass degrees the waves travel to)
  README.md   what made them
Values are written with 4 decimals (trailing zeros dropped); times with 1. Random streams: one
numpy.random.default_rng(seed) draws, in order, the frequencies, the phases, then the noise of heave,
roll, pitch and the probe.
"""

import argparse
import math
import os

import numpy as np

G = 9.81
HS_M = 1.5
TP_S = 8.0
GAMMA = 3.3
W_MIN, W_MAX = 0.25, 2.0
PROBE_EAST_M, PROBE_NORTH_M = 600.0, 0.0
DIRECTION = np.array([-1.0, 0.0])  # waves travel to compass 270 = west = -x (east-north frame)
TOWARDS_DEG = 270.0
HEADING_DEG = 180.0  # in the body frame: the barge's +x points east
MOTION_HZ, PROBE_HZ = 5.0, 2.0
NOISE_HEAVE_M, NOISE_ROT_DEG, NOISE_PROBE_M = 0.01, 0.05, 0.02
RAO_CSV = "config/vessels/barge/capytaine_rao.csv"
COLUMNS = ["surge_m", "sway_m", "heave_m", "roll_deg", "pitch_deg", "yaw_deg"]


def jonswap_shape(w, tp=TP_S, gamma=GAMMA):
    """Unnormalized JONSWAP: w^-5 exp(-1.25 (wp/w)^4) gamma^r."""
    wp = 2.0 * math.pi / tp
    w = np.asarray(w, dtype=float)
    sigma = np.where(w <= wp, 0.07, 0.09)
    r = np.exp(-((w - wp) ** 2) / (2.0 * sigma**2 * wp**2))
    return w**-5.0 * np.exp(-1.25 * (wp / w) ** 4) * gamma**r


def jonswap(w):
    """JONSWAP with integral over 0..inf = Hs^2 / 16 (numerically, 0.05..40 rad/s)."""
    grid = np.linspace(0.05, 40.0, 400001)
    m0 = np.trapezoid(jonswap_shape(grid), grid)
    return HS_M**2 / 16.0 / m0 * jonswap_shape(w)


def load_rao(path, heading_deg):
    """Capytaine's RAO at one heading: (omegas, complex r[omega, mode 1..6]) in exp(+i w t)."""
    data = np.genfromtxt(path, delimiter=",", names=True)
    sel = data[np.isclose(data["heading_deg"], heading_deg)]
    omegas = np.unique(sel["omega"])
    r = np.zeros((len(omegas), 6), dtype=complex)
    for row in sel:
        i = int(np.searchsorted(omegas, row["omega"]))
        r[i, int(row["mode"]) - 1] = row["amplitude"] * np.exp(1j * np.radians(row["phase_deg"]))
    return omegas, r


def interp_rao(omegas, r, w):
    """Linear in omega on the real and imaginary parts; zero outside the table."""
    out = np.zeros((len(w), r.shape[1]), dtype=complex)
    for m in range(r.shape[1]):
        out[:, m] = (np.interp(w, omegas, r[:, m].real, left=0.0, right=0.0)
                     + 1j * np.interp(w, omegas, r[:, m].imag, left=0.0, right=0.0))
    return out


def synthesize(t, w, coef, chunk=500):
    """Re{ sum_j coef[j, :] exp(i w_j t) } for every t: (len(t), coef.shape[1])."""
    out = np.zeros((len(t), coef.shape[1]))
    for s in range(0, len(t), chunk):
        e = np.exp(1j * np.outer(t[s:s + chunk], w))
        out[s:s + chunk] = (e @ coef).real
    return out


def num(v, decimals=4):
    s = f"{v:.{decimals}f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def write_motion(path, t, x):
    with open(path, "w") as f:
        f.write("time_s,vessel," + ",".join(COLUMNS) + "\n")
        for ti, row in zip(t, x):
            f.write(f"{num(ti, 1)},barge," + ",".join(num(v) for v in row) + "\n")


def write_probe(path, t, eta):
    with open(path, "w") as f:
        f.write("time_s,elevation_m,east_m,north_m,towards_deg\n")
        for ti, e in zip(t, eta):
            f.write(f"{num(ti, 1)},{num(e)},{num(PROBE_EAST_M)},{num(PROBE_NORTH_M)},{num(TOWARDS_DEG)}\n")


def xcorr_peak_lag(a, b, dt, max_lag_s):
    """The lag tau in [0, max_lag_s] maximizing sum_t a(t) b(t + tau) (b lags a by tau)."""
    a = a - a.mean()
    b = b - b.mean()
    n = len(a)
    lags = np.arange(0, int(round(max_lag_s / dt)) + 1)
    c = np.array([np.dot(a[: n - L], b[L:]) / (n - L) for L in lags])
    c /= a.std() * b.std()
    i = int(np.argmax(c))
    return lags[i] * dt, c[i]


def write_readme(path, args, hs_band):
    with open(path, "w") as f:
        f.write(f"""# indep-barge-probe: an independent recording of the barge in head seas

Made by `tools/indep/barge_probe.py` (numpy only), from the repository root:

    python3 tools/indep/barge_probe.py --out tests/data/indep-barge-probe   # a Python 3 with numpy

(seed {args.seed}, {args.components} components, {args.duration:g} s). It shares no code with shipcast and does not use
shipcast's time-domain model: a frequency-domain linear superposition of Capytaine's own motion RAO
(`config/vessels/barge/capytaine_rao.csv`, heading 180 deg, linear in omega on real and imaginary parts).

- Sea: long-crested JONSWAP, Hs 1.5 m, Tp 8 s, gamma 3.3, deep water, g 9.81; {args.components} components at random
  frequencies in 0.25-2.0 rad/s (not a grid), random phases (band Hs {hs_band:.3f} m).
- Geometry (earth frame x east, y north): the barge's reference point at the origin, bow east (compass heading
  090, `site.heading_deg = 90`); waves travel to compass 270 (west): head seas, beta = 180 deg. Probe fixed at
  east 600 m, north 0, up-wave of the barge.
- `motion.csv` (5 Hz, 0-{args.duration:g} s, vessel `barge`): the six motions with white sensor noise (heave 0.01 m,
  roll and pitch 0.05 deg std; surge, sway and yaw noise-free). `truth.csv`: the same without noise.
- `probe.csv` (2 Hz): the elevation at the probe with 0.02 m white noise; `towards_deg` 270.
- Layouts: `src/shell/replay/import.rs` (top comment); system `config/vessels/barge/system.toml`.
""")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="tests/data/indep-barge-probe")
    ap.add_argument("--rao", default=RAO_CSV)
    ap.add_argument("--seed", type=int, default=20260601)
    ap.add_argument("--components", type=int, default=2000)
    ap.add_argument("--duration", type=float, default=1500.0)
    args = ap.parse_args()

    rng = np.random.default_rng(args.seed)
    w = np.sort(rng.uniform(W_MIN, W_MAX, args.components))
    phi = rng.uniform(0.0, 2.0 * math.pi, args.components)
    edges = np.concatenate([[W_MIN], 0.5 * (w[1:] + w[:-1]), [W_MAX]])
    dw = np.diff(edges)
    a = np.sqrt(2.0 * jonswap(w) * dw)
    k = w**2 / G
    hs_band = 4.0 * math.sqrt(0.5 * np.sum(a**2))

    omegas, r = load_rao(args.rao, HEADING_DEG)
    rao = interp_rao(omegas, r, w)  # (N, 6)

    # complex amplitudes at the origin: the elevation and the six motions
    c0 = a * np.exp(1j * phi)
    coef_motion = c0[:, None] * rao
    coef_motion[:, 3:] *= 180.0 / math.pi  # rotations in degrees
    probe_xy = np.array([PROBE_EAST_M, PROBE_NORTH_M])
    coef_probe = c0 * np.exp(-1j * k * float(DIRECTION @ probe_xy))  # cos(w t - k d.x + phi)

    t_m = np.arange(0, int(round(args.duration * MOTION_HZ)) + 1) / MOTION_HZ
    t_p = np.arange(0, int(round(args.duration * PROBE_HZ)) + 1) / PROBE_HZ
    truth = synthesize(t_m, w, coef_motion)
    at_probe_rate = synthesize(t_p, w, np.stack([coef_probe, c0, coef_motion[:, 2]], axis=1))
    eta_probe, eta_origin, heave_2hz = at_probe_rate.T

    motion = truth.copy()
    motion[:, 2] += rng.normal(0.0, NOISE_HEAVE_M, len(t_m))
    motion[:, 3] += rng.normal(0.0, NOISE_ROT_DEG, len(t_m))
    motion[:, 4] += rng.normal(0.0, NOISE_ROT_DEG, len(t_m))
    probe = eta_probe + rng.normal(0.0, NOISE_PROBE_M, len(t_p))

    os.makedirs(args.out, exist_ok=True)
    write_motion(os.path.join(args.out, "motion.csv"), t_m, motion)
    write_motion(os.path.join(args.out, "truth.csv"), t_m, truth)
    write_probe(os.path.join(args.out, "probe.csv"), t_p, probe)
    write_readme(os.path.join(args.out, "README.md"), args, hs_band)

    # sanity figures
    wp = 2.0 * math.pi / TP_S
    print(f"components {args.components}, seed {args.seed}, band {W_MIN}-{W_MAX} rad/s: band Hs {hs_band:.4f} m "
          f"(target Hs {HS_M} m over the whole spectrum; expected std {hs_band / 4:.4f} m)")
    print(f"probe elevation std {probe.std():.4f} m (noise-free {eta_probe.std():.4f}); "
          f"origin elevation std {eta_origin.std():.4f} m")
    for i, name in enumerate(COLUMNS):
        print(f"  {name:10s} truth std {truth[:, i].std():.5f}  recorded std {motion[:, i].std():.5f}")
    dist = float(-(DIRECTION @ probe_xy))
    lag, cc = xcorr_peak_lag(eta_probe, eta_origin, 1.0 / PROBE_HZ, 300.0)
    lag_h, cc_h = xcorr_peak_lag(probe, heave_2hz, 1.0 / PROBE_HZ, 300.0)
    print(f"lag of max cross-correlation, probe -> origin elevation: {lag:.1f} s (coefficient {cc:.3f}); "
          f"probe (noisy) -> barge heave (truth): {lag_h:.1f} s ({cc_h:.3f})")
    print(f"  {dist:.0f} m / group velocity g/(2 w) at wp {wp:.4f} rad/s: {dist * 2 * wp / G:.1f} s; "
          f"/ phase velocity: {dist * wp / G:.1f} s")


if __name__ == "__main__":
    main()
