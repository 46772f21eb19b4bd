#!/usr/bin/env python3
"""Build a shipcast vessel database with Capytaine (a BEM code on PyPI).

Writes, into OUTDIR:
  <stem>.1, <stem>.3, <stem>.hst   WAMIT-format files (ULEN = 1, no header line), modes 1..6N
  system.toml                      the shipcast system file (bodies, mass properties, positions)
  capytaine_rao.csv                Capytaine's own motion RAO, `omega,heading_deg,mode,amplitude,phase_deg`,
                                   converted to the exp(+i w t) convention (conjugated), for validation
  bem_info.toml                    what was run: mesh sizes, frequencies, run time, Capytaine version

Conventions (shipcast DESIGN.md section 1): body frame x forward, y port, z up; each body's rotations are
about its own reference point (at the waterline above midship); excitation phases refer to the global
origin (a multi-body database, so shipcast applies no extra shift); wave heading beta is the direction the
waves travel to, counterclockwise from +x. Capytaine works in exp(-i w t): every complex value written here
is conjugated into WAMIT's exp(+i w t).

Hulls are modified Wigley forms (Journee 1992 / Kashiwagi): half-breadth
  y = B/2 [ (1 - z'^2)(1 - x'^2)(1 + a2 x'^2 + a4 x'^4) + kappa z'^2 (1 - z'^8)(1 - x'^2)^4 ]
with x' = 2x/L, z' = -z/T (a2 = 0.6, a4 = 1, kappa = 1: block coefficient about 0.56), or a box.

Usage: python3 make_db.py --preset ship OUTDIR      (one 180 m ship)
       python3 make_db.py --preset pair OUTDIR      (180 m ship + 120 m ship side by side, 5 m gap)
       python3 make_db.py --preset barge OUTDIR     (one 24 m x 8 m x 3 m box barge)
       python3 make_db.py --preset box-test OUTDIR  (tiny, seconds: a smoke test of this script)
       python3 make_db.py --preset offset-box OUTDIR   (the barge placed at x = 40 m; RAO at off-grid headings)
       python3 make_db.py --preset messy-pair OUTDIR   (two 12 m boxes 6.5 m apart, no lid: B indefinite above 3 rad/s)
       python3 make_db.py --preset close-pair OUTDIR   (a 16 m barge and a 10 m boat 2 m apart, no lid)
       python3 make_db.py --preset barge-speeds OUTDIR (the barge at 0, 2, 4 m/s and, directly, 3 m/s)
       python3 make_db.py --preset pair-direct OUTDIR  (the pair, direct formulation: the two-ship demo's truth)
       python3 make_db.py --preset ship-direct OUTDIR  (the ship, direct formulation: the one-ship demo's truth)

Forward speed (a preset with `speeds`, e.g. barge-speeds) writes one file set per speed, <stem>.1/.3/.hst,
the zero-speed one named by system.toml's `wamit`, the speed set listed in system.toml's [[database]]
entries (speed_m_s, wamit), and <stem>.toml for each set solved directly outside the speed set. Capytaine 3.0.0's approximate forward-speed model (single rigid body;
theory manual "Problem with forward speed", Donatini et al. 2022): the problem is solved at the encounter
frequency w_e = |w - k U cos beta| with the ZERO-speed free-surface Green function at k_e = w_e^2 / g (no
U d/dx in the free-surface condition), the body condition gains the m-terms of a uniform stream -U only
(-U d(dr)/dx . n: pitch and yaw; the steady double-body flow is neglected), and the pressure is
rho (i w_e phi + U dphi/dx) (exp(-i w t)). Speed sets are written in this convention:

One WAMIT file set per forward speed U (m/s, the body moving to +x), solved by Capytaine's approximate
forward-speed model (single rigid body). Conventions as at zero speed (DESIGN.md section 1; exp(+i w t),
Capytaine's exp(-i w t) values conjugated), and:
- .1: A and B as functions of the ENCOUNTER frequency w_e: PER = 2 pi / w_e, B = rho w_e Bbar, on the same
  grid of w_e as the preset's frequencies (the range of the zero-speed set). Each row is one radiation
  problem solved at encounter frequency w_e (Capytaine's RadiationProblem takes a wave frequency and
  heading and solves at w_e = |w - k U cos beta|; it is solved with w = w_e, beta = 90 deg, so w_e = w;
  its result depends on w_e and U only). A_ij is the force in mode i due to motion in mode j; at U != 0 A
  and B are written as solved, NOT symmetrized (A_ij(U) = A_ji(-U): the asymmetry is physical).
  PER = 0 (w_e = infinity) rows: the zero-speed A_inf (Capytaine solves no infinite frequency at speed;
  in its model A(w_e, U) tends to A_inf(U = 0) as w_e grows, while B(w_e, U) tends to a nonzero constant
  in the pitch-heave / yaw-sway couplings). No PER = -1 row at U != 0 (A(w_e -> 0) grows like U^2 / w_e^2).
- .3: X per metre of wave amplitude as a function of the ABSOLUTE wave frequency w (PER = 2 pi / w) and
  heading beta (to, counterclockwise from +x; 180 deg = head seas): the force in the frame moving with the
  body is Re{ X exp(i w_e' t) }, w_e' = w - k U cos beta the SIGNED encounter frequency, for the wave
  eta = Re{ exp(i (w t - k (x_E cos beta + y sin beta))) }, x_E = x + U t (earth and moving frames
  coincide at t = 0): the phase is referred to the wave crest at the body origin at t = 0. Where w_e' < 0
  (following seas, U cos beta > g / w) the Capytaine value is written unconjugated (it is solved at |w_e'|
  with the conjugate incident wave), so X is continuous through w_e' = 0.
- .hst: as at zero speed (no speed-dependent restoring, no sinkage or trim)."""

import argparse
import math
import os
import sys
import time

import numpy as np
import xarray as xr
import capytaine as cpt
from capytaine.bem.airy_waves import airy_waves_velocity

RHO = 1025.0
G = 9.81
DOF_NAMES = ["Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw"]


def wigley_mesh(length, beam, draft, nx, nz, a2=0.6, a4=1.0, kappa=1.0):
    """Quad panels of a modified Wigley hull, centred at the origin, waterline at z = 0.

    Vertical stations are placed for equal girth at midship so the bilge is resolved."""

    def half_breadth(xp, zp):
        return 0.5 * beam * ((1 - zp**2) * (1 - xp**2) * (1 + a2 * xp**2 + a4 * xp**4)
                             + kappa * zp**2 * (1 - zp**8) * (1 - xp**2) ** 4)

    # equal-girth z' stations at midship
    fine = np.linspace(0.0, 1.0, 2001)
    ys = half_breadth(0.0, fine)
    zs = -draft * fine
    seg = np.hypot(np.diff(ys), np.diff(zs))
    girth = np.concatenate([[0.0], np.cumsum(seg)])
    zp_st = np.interp(np.linspace(0.0, girth[-1], nz + 1), girth, fine)
    xp_st = np.linspace(-1.0, 1.0, nx + 1)
    pts = np.zeros((nx + 1, nz + 1, 3))
    for i, xp in enumerate(xp_st):
        for j, zp in enumerate(zp_st):
            pts[i, j] = (0.5 * length * xp, half_breadth(xp, zp), -draft * zp)
    faces = []
    for i in range(nx):
        for j in range(nz):
            # port side (y >= 0): outward normal points to +y (checked by the positive volume below)
            port = [pts[i, j], pts[i + 1, j], pts[i + 1, j + 1], pts[i, j + 1]]
            faces.append(port)
            stbd = [p * np.array([1.0, -1.0, 1.0]) for p in port[::-1]]
            faces.append(stbd)
    return cpt.Mesh.from_list_of_faces(np.array(faces), name="wigley")


def make_body(name, hull, length, beam, draft, position, panel_m, omega_max, kg_m, radii, lid_placement="lowest",
              lid_omega=None):
    if hull == "wigley":
        nx = max(8, int(math.ceil(length / panel_m)))
        nz = max(3, int(math.ceil((draft + 0.5 * beam) / panel_m)))
        mesh = wigley_mesh(length, beam, draft, nx, nz)
    elif hull == "box":
        mesh = cpt.mesh_parallelepiped(size=(length, beam, draft), center=(0, 0, -draft / 2),
                                       resolution=(max(4, int(length / panel_m)),
                                                   max(2, int(beam / panel_m)),
                                                   max(2, int(draft / panel_m))),
                                       missing_sides={"top"})
        mesh = mesh.immersed_part()
    else:
        raise ValueError(f"unknown hull {hull}")
    mesh = mesh.translated(position)
    # Lid against irregular frequencies, where a preset asks for it (`lid`, passed as `lid_placement`):
    # - "lowest" (the default of the older presets): Capytaine's lowest_lid_position for 1.25 omega_max, or
    #   5 % of the draft down where that is higher or undefined. lowest_lid_position is the deepest a lid
    #   may go and assumes a rectangular waterplane; on the 180 m hull with the lid placed for omega_max
    #   itself a spike (negative heave damping) remained at 1.525 rad/s, for 1.25 omega_max it was gone.
    # - "waterline": 5 % of the draft down (session 10's experiments: a spike remained at 1.76 rad/s).
    # - "surface": on the free surface, z = 0 (Capytaine's own default for generate_lid). Measured on the
    #   carrier alone, 2 m panels (session 11): the 1.76 rad/s spike is gone, and a lid only 5 % of the
    #   draft down still moved the smooth data well below it (heave damping at 1.6 rad/s 3.41e6 against
    #   5.20e6 with the lid on the surface; 2.48e7 both at 0.5 rad/s).
    # - "none": no lid, so the irregular frequencies stay in the data (messy-pair: a deliberately bad database).
    # `lid_omega` (a preset's `lid_omega`) is the frequency "lowest" places the lid for instead of omega_max
    # (offset-box: the barge's lid, placed for the barge's 3 rad/s, on data that stop at 2.5 rad/s).
    if lid_placement == "none":
        z_lid = None
    elif lid_placement == "surface":
        z_lid = 0.0
    elif lid_placement == "waterline":
        z_lid = -0.05 * draft
    elif lid_placement == "lowest":
        z_lid = float(mesh.lowest_lid_position(1.25 * (omega_max if lid_omega is None else lid_omega), g=G))
        if not math.isfinite(z_lid) or z_lid > -0.05 * draft:
            z_lid = -0.05 * draft
    else:
        raise ValueError(f"unknown lid placement {lid_placement}")
    lid = None if z_lid is None else mesh.generate_lid(z=z_lid, faces_max_radius=0.75 * panel_m)
    dofs = cpt.rigid_body_dofs(rotation_center=np.array(position, dtype=float))
    body = cpt.FloatingBody(mesh=mesh, lid_mesh=lid, dofs=dofs, name=name)
    volume = body.disp_volume
    if volume <= 0:
        raise RuntimeError(f"{name}: non-positive volume {volume}: panel orientation is wrong")
    cob = np.array(body.center_of_buoyancy)
    mass = RHO * volume
    # equilibrium: centre of gravity above the centre of buoyancy, at KG = kg_m above the keel
    cog = np.array([cob[0], cob[1], -draft + kg_m])
    body.mass = mass
    body.center_of_mass = cog
    return body, mass, cog, z_lid


def mass_matrix(mass, cog_rel, radii):
    """6x6 rigid-body mass matrix about the reference point; cog_rel = CoG - reference point."""
    x, y, z = cog_rel
    skew = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    ig = np.diag([mass * r**2 for r in radii])
    io = ig + mass * (np.dot(cog_rel, cog_rel) * np.eye(3) - np.outer(cog_rel, cog_rel))
    m = np.zeros((6, 6))
    m[:3, :3] = mass * np.eye(3)
    m[:3, 3:] = -mass * skew
    m[3:, :3] = mass * skew
    m[3:, 3:] = io
    return m


PRESETS = {
    # one full-scale ship: 180 m x 30 m x 10 m, modified Wigley
    "ship": dict(
        stem="ship",
        bodies=[dict(name="carrier", hull="wigley", length=180.0, beam=30.0, draft=10.0,
                     position=(0.0, 0.0, 0.0), kg_m=11.0, radii=(0.35 * 30, 0.25 * 180, 0.26 * 180),
                     roll_damping_ratio=0.05)],
        panel_m=3.0,
        omegas=np.round(np.arange(0.05, 1.6001, 0.025), 4),
        headings_deg=np.arange(0.0, 360.0, 30.0),
    ),
    # two ships side by side: the carrier and a 120 m x 20 m x 7 m lighter to port, 5 m gap at the waterline
    "pair": dict(
        stem="pair",
        bodies=[dict(name="carrier", hull="wigley", length=180.0, beam=30.0, draft=10.0,
                     position=(0.0, 0.0, 0.0), kg_m=11.0, radii=(0.35 * 30, 0.25 * 180, 0.26 * 180),
                     roll_damping_ratio=0.05),
                dict(name="lighter", hull="wigley", length=120.0, beam=20.0, draft=7.0,
                     position=(0.0, 30.0, 0.0), kg_m=7.5, radii=(0.35 * 20, 0.25 * 120, 0.26 * 120),
                     roll_damping_ratio=0.05)],
        panel_m=3.0,
        # gap resonances live between about 0.8 and 1.6 rad/s: sample them at 0.005 rad/s
        omegas=np.round(np.concatenate([np.arange(0.05, 0.8, 0.025), np.arange(0.8, 1.6001, 0.005)]), 4),
        headings_deg=np.arange(0.0, 360.0, 30.0),
        # points of interest (outputs only: they change no motion)
        points=[("crane_tip", "carrier", (0.0, 14.0, 30.0)), ("lighter_hatch", "lighter", (0.0, 0.0, 3.0))],
        relative_motions=[("hook_over_hatch", "crane_tip", "lighter_hatch")],
    ),
    # a smoke test of this script (seconds)
    "box-test": dict(
        stem="box",
        bodies=[dict(name="box", hull="box", length=20.0, beam=8.0, draft=3.0,
                     position=(0.0, 0.0, 0.0), kg_m=2.0, radii=(3.0, 5.0, 5.5))],
        panel_m=2.0,
        omegas=np.array([0.5, 1.0, 1.5]),
        headings_deg=np.array([0.0, 90.0, 180.0]),
    ),
    # one box barge, 24 m x 8 m x 3 m, 1 m panels (issue 27: the accuracy of the time domain at the default
    # step on a vessel with 4.5 s periods; 87 s, 384 hull + 147 lid panels). Heave 4.89 s (1.284 rad/s),
    # pitch 4.49 s (1.401), roll 7.70 s (0.816): sampled at 0.01 rad/s from 1.1 to 1.6 rad/s. Capytaine's
    # hydrostatics take the waterplane's second moments at the panel centres (1 m strips): GM_T 0.750 m
    # (exact box 0.778), GM_L 14.97 m (15.00); the .hst and Capytaine's RAO both use these values.
    "barge": dict(
        stem="barge",
        bodies=[dict(name="barge", hull="box", length=24.0, beam=8.0, draft=3.0,
                     position=(0.0, 0.0, 0.0), kg_m=2.5, radii=(0.35 * 8, 0.25 * 24, 0.26 * 24),
                     roll_damping_ratio=0.05)],
        panel_m=1.0,
        omegas=np.unique(np.round(np.concatenate([np.arange(0.2, 1.1, 0.02), np.arange(1.1, 1.6, 0.01),
                                                  np.arange(1.6, 3.0001, 0.02)]), 4)),
        headings_deg=np.arange(0.0, 360.0, 15.0),
    ),
}


def _pair_to(step_above_1_6, **changes):
    """The pair preset with its frequencies continued from 1.6 to 2.2 rad/s (the experiments below)."""
    omegas = np.round(np.concatenate([np.arange(0.05, 0.8, 0.025), np.arange(0.8, 1.6, 0.005),
                                      np.arange(1.6, 2.2001, step_above_1_6)]), 4)
    return dict(PRESETS["pair"], omegas=omegas, **changes)


# the pair to 2.2 rad/s, an experiment on the pair's Kramers-Kronig residual (session 5, 450 s): the
# lighter's horizontal modes became consistent (yaw A 3.3 -> 0.74 %, Ogilvie spread 6.2 -> 1.3 %), so
# their residual is damping above 1.6 rad/s; but 3 m panels are too coarse there (carrier heave A
# 11 % off at 1.66 rad/s, negative lighter heave damping at 1.79): not a usable demo database.
PRESETS["pair-wide"] = _pair_to(0.01)
# the same on 2 m panels (an experiment, session 5, 1978 s): the lighter stays consistent (yaw A
# 0.77 %), but the carrier's heave and pitch go wrong above 1.76 rad/s (negative damping at 1.88 and
# 2.12 rad/s: irregular frequencies the lid does not remove; heave A 34 % off at 1.8): not usable.
PRESETS["pair-fine"] = _pair_to(0.02, panel_m=2.0)
# the pair preset on 2 m panels, same frequencies (an experiment, session 7, 2939 s): below 1.2 rad/s the
# time-domain floor moves closer to the frequency domain (worst 0.35-0.49 % of a curve's peak per band,
# 3 m panels 0.56-0.60 %), but the lighter's coupled resonance stays where it was (1.29 % at 1.22 rad/s,
# 3 m panels 1.14 % at 1.23), the asymmetry grows to 8.5 % and the carrier's heave damping goes
# negative at 1.58 rad/s (-25 % of its peak: an irregular frequency the lid does not remove): not usable.
PRESETS["pair-2m"] = dict(PRESETS["pair"], panel_m=2.0)
# the pair to 2.2 rad/s with the lids just under the waterline (5 % of the draft), where they should
# remove every irregular frequency, not only those below 1.25 omega_max (an experiment, session 10, 498 s): the
# lighter's coupled resonance stops setting the convolution's floor: over 0.05-1.6 rad/s 0.80 % (lighter
# roll at 0.5 rad/s, beam seas; the pair preset 1.14 % at 1.23 rad/s), 0.98 % over the whole range
# (lighter yaw at 1.62). But 3 m panels are too coarse above 1.76 rad/s (panel radius > wavelength / 8):
# B indefinite by 1.2 % at 1.72 rad/s, the lighter's roll damping negative at 2.02, heave A 8 % off its
# Kramers-Kronig value at 1.72; the same data cut at 1.76 / 1.9 / 2.0 rad/s give floors of 0.97 / 1.16 /
# 1.14 % at 1.23 rad/s (the tail beyond the data still decides it; at 1.64 / 1.68 / 1.70 / 1.72 rad/s:
# 1.10 / 1.32 / 1.31 / 1.04 %, the last three at the lighter's roll resonance), and the state-space model needs 454
# states (floor 18 %): not usable as it is.
PRESETS["pair-wide-lid"] = _pair_to(0.02, lid="waterline")
# the same on 2 m panels (an experiment, session 10, 1788 s): a spike at 1.76 rad/s the lids do not
# remove (carrier pitch B 50 times its neighbours', A negative: Kramers-Kronig 129 % off there); below
# 1.6 rad/s the convolution's floor is 1.18 % (carrier pitch at 0.81 rad/s): no better than 3 m panels.
# Not usable.
PRESETS["pair-fine-lid"] = _pair_to(0.02, panel_m=2.0, lid="waterline")
# the pair preset with the lids on the free surface (an experiment, session 11, 412 s): smooth data, but
# less Kramers-Kronig consistent than the pair preset's (worst A 1.33 % in band, lighter heave at 0.965
# rad/s) and the convolution's floor 1.51 % (the pair preset 1.14 %), both at the lighter's 1.23 rad/s
# resonance; state space 4.85 % (lighter yaw, beam seas, 0.05 rad/s). Not usable.
PRESETS["pair-surface-lid"] = dict(PRESETS["pair"], lid="surface")
# the same to 2.2 rad/s, sampled at 0.005 rad/s from 0.8 rad/s up (the gap's resonances go on above 1.6;
# an experiment, session 11, 838 s): no spike anywhere (no sample off the mean of its neighbours by 10 %
# above 1.55 rad/s), but 3 m panels are coarse there (Capytaine warns above 1.755 rad/s) and the
# convolution's floor is 8.3 % at the lighter's 1.23 rad/s resonance (7.7 % with the cubic tail). Not usable.
PRESETS["pair-wide-surface-lid"] = _pair_to(0.005, lid="surface")
# the same on 2 m panels, 0.01 rad/s above 1.6 (an experiment, session 12, 3071 s; 2340 + 1080 hull panels,
# 724 + 367 lid panels): clean data (no sample off the mean of its neighbours by 2 % of its peak above
# 1.55 rad/s, no negative diagonal damping beyond -0.1 % of its peak), but less Kramers-Kronig consistent
# than the pair preset's: worst A 1.79 % (carrier heave at 1.495 rad/s; pair preset 1.15 %), the fitted
# tail at its steepest (p = 16) on six DOFs, the convolution's floor 2.05 % (lighter sway, head seas,
# 1.23 rad/s; pair preset 1.14 %), the state space's 8.0 % (366 states). Not usable: the lid on the
# surface removes the spike, but its data are less consistent (so were the 3 m version's).
PRESETS["pair-fine-surface-lid"] = _pair_to(0.01, panel_m=2.0, lid="surface")
# the pair preset solved with the direct (potential) formulation instead of the source one (an experiment,
# session 12, 926 s): reciprocity holds better (largest asymmetry symmetrized away 1.8 % in A, 1.6 % in B;
# the pair preset 3.0 / 4.1 %), the convolution's floor 0.84 % (lighter heave, beam seas, 0.8 rad/s;
# 0.68 % at the lighter's 1.23 rad/s resonance), but the state space's 2.0 % (lighter sway, heading 0,
# 0.05 rad/s; the pair preset 1.37 %), and with the database's own A_inf the convolution's floor is 2.32 %
# at 1.23 rad/s (the pair preset 2.11 %): no more consistent there, only luckier. Not swapped in.
# Since session 21 it is the two-ship demo's truth (config/vessels/pair/truth: `shipcast simulate`'s true
# vessels are not the forecaster's database), and ship-direct the one-ship demo's (config/vessels/ship/truth).
PRESETS["pair-direct"] = dict(PRESETS["pair"], bem_method="direct")
PRESETS["ship-direct"] = dict(PRESETS["ship"], bem_method="direct")
# the pair preset with the Green function's singularities integrated for high frequencies (an experiment,
# session 12, 886 s): Kramers-Kronig worst A 1.26 % in band (the pair preset 1.15 %), the convolution's floor
# 1.21 %, the state space's 1.50 % (the pair preset 1.14 / 1.37 %). Not usable.
PRESETS["pair-high-freq-gf"] = dict(PRESETS["pair"], gf_singularities="high_freq")


# offset-box: the barge preset's hull, panels, mass properties and lid (placed for the barge's 3 rad/s via
# lid_omega), but with its reference point at x = 40 m in the BEM frame, so its excitation, referred to the
# global origin, turns by k 40 cos(beta) between headings; database headings 0-180 deg only (the hull is
# symmetric port-starboard and on the x axis), and Capytaine's RAO also at off-grid headings (7.5-172.5 deg
# every 15, and 187.5, 217.5, 262.5, 307.5, 352.5 deg in the other half, solved directly): the target of a
# test of heading interpolation, half-circle symmetry and the phase reference of a body away from the origin.
# Run (13 s, one thread; 384 hull + 147 lid panels, lid at z = -0.646 m as the barge's): 70 frequencies
# 0.2-2.5 rad/s, 13 database headings, 30 solved (those of capytaine_rao.csv). Against the barge preset at
# their common frequencies: A, B and C identical to the digits written, X the barge's times exp(-i k 40
# cos beta) to 3.6e-6 of its peak, Capytaine's RAO likewise to 1.5e-8 (so the excitation is referred to the
# global origin for a single body too); the RAO at 360 - beta mirrors beta's exactly (sway, roll, yaw with
# their sign turned). Heave 4.89 s, pitch 4.49 s, roll 7.70 s (0.816 rad/s; the beam-sea roll RAO peaks at
# 0.84 rad/s). B passive (lowest scaled eigenvalue -3e-4).
PRESETS["offset-box"] = dict(
    PRESETS["barge"],
    stem="offset_box",
    bodies=[dict(PRESETS["barge"]["bodies"][0], name="offset_box", position=(40.0, 0.0, 0.0))],
    lid_omega=3.0,
    # every 0.05 rad/s, 0.02 around roll (0.82 rad/s) and heave and pitch (1.28 and 1.40 rad/s)
    omegas=np.unique(np.round(np.concatenate([np.arange(0.2, 0.7, 0.05), np.arange(0.7, 0.9601, 0.02),
                                              np.arange(1.0, 1.1, 0.05), np.arange(1.1, 1.6001, 0.02),
                                              np.arange(1.65, 2.5001, 0.05)]), 4)),
    headings_deg=np.arange(0.0, 180.0001, 15.0),
    rao_headings_deg=np.unique(np.concatenate([np.arange(0.0, 180.0001, 15.0), np.arange(7.5, 180.0, 15.0),
                                               [187.5, 217.5, 262.5, 307.5, 352.5]])),
)
# messy-pair: two identical 12 m x 4 m x 2 m boxes side by side, 6.5 m between the hull sides, coupled, and
# NO lid, so the irregular frequencies (the first of a 12 x 4 x 2 box at 2.96 rad/s: k = pi sqrt(1/L^2 +
# 1/B^2), w^2 = g k coth(k T)) stay in the data above the 0.3-2.5 rad/s band that matters, with the
# frequencies continued to 5 rad/s on panels too coarse there: a deliberately messy database (B(w)
# indefinite above 3 rad/s) as close hulls often give, for the passivity repair and the fits downstream.
# Run (65 s on two threads, 117 s beside a cargo build; 448 + 448 hull panels of 0.5 m, no lid; Capytaine
# warns of the mesh above 4.675 rad/s): 175 frequencies 0.2-5 rad/s, 12 headings. B(w), symmetrized, in
# coordinates scaled by sqrt(max_w B_ii) (as shipcast's passive_damping): indefinite (eigenvalue below
# -1e-3) at 53 of the 85 frequencies from 2.925 to 5 rad/s, worst -1.32 at 3.1 rad/s (-6.4 % of the largest
# |eigenvalue| unscaled), -0.52 at 2.95; the diagonal heave and pitch damping negative at 2.95-2.975,
# 3.075-3.15, 3.325-3.35, 3.575-3.6, 3.85-3.9 and 4.325-4.425 rad/s (the box's irregular frequencies, 2.96,
# 3.12, 3.34, 3.60 rad/s, ...). Over 0.3-2.9 rad/s the lowest scaled eigenvalue is -1.9e-4 (noise).
# Asymmetry before symmetrizing: at most 1.35 % (A) and 5.9 % (B, at the gap's resonance) below 2.5 rad/s,
# 118 % (B) at the irregular frequencies. Free-floating roll RAO (beam seas) peaks at 1.2 rad/s (C44 /
# (M44 + A44) about the reference point: 1.003 rad/s, 6.26 s, where the 5 % roll damping is set); heave
# 3.72 s, pitch 3.46 s; a sway-roll resonance of the gap at 2.315 rad/s (B22 seven times its value 0.1 rad/s
# either side).
PRESETS["messy-pair"] = dict(
    stem="messy_pair",
    bodies=[dict(name="box_a", hull="box", length=12.0, beam=4.0, draft=2.0, position=(0.0, 0.0, 0.0),
                 kg_m=1.3, radii=(0.35 * 4, 0.25 * 12, 0.26 * 12), roll_damping_ratio=0.05),
            dict(name="box_b", hull="box", length=12.0, beam=4.0, draft=2.0, position=(0.0, 10.5, 0.0),
                 kg_m=1.3, radii=(0.35 * 4, 0.25 * 12, 0.26 * 12), roll_damping_ratio=0.05)],
    panel_m=0.5,
    lid="none",
    # every 0.05 rad/s to 2.5, 0.02 around the roll RAO's peak (1.2 rad/s; C44 / (M44 + A44) about the
    # reference point gives 1.0), 0.01 over the gap's sway-roll resonance (2.31 rad/s), 0.025 above 2.5 rad/s
    # (the irregular frequencies' spikes are about 0.1 rad/s wide)
    omegas=np.unique(np.round(np.concatenate([np.arange(0.2, 2.5, 0.05), np.arange(1.1, 1.3001, 0.02),
                                              np.arange(2.2, 2.4501, 0.01), np.arange(2.5, 5.0001, 0.025)]), 4)),
    headings_deg=np.arange(0.0, 360.0, 30.0),
)


# close-pair (issue 54): a 16 x 6 x 2.5 m barge and a 10 x 3.5 x 1.5 m boat alongside, 2 m apart and 2 m
# staggered, hydrodynamically coupled (12 x 12), solved without a lid so that irregular frequencies and the
# gap make the coupled damping indefinite above the band; the passivity choice is judged on it.
PRESETS["close-pair"] = dict(
    stem="close_pair",
    bodies=[dict(name="barge", hull="box", length=16.0, beam=6.0, draft=2.5, position=(0.0, 0.0, 0.0),
                 kg_m=1.8, radii=(0.35 * 6, 0.25 * 16, 0.26 * 16), roll_damping_ratio=0.05),
            dict(name="boat", hull="box", length=10.0, beam=3.5, draft=1.5, position=(2.0, 6.75, 0.0),
                 kg_m=1.0, radii=(0.35 * 3.5, 0.25 * 10, 0.26 * 10), roll_damping_ratio=0.05)],
    panel_m=0.5,
    lid="none",
    omegas=np.unique(np.round(np.concatenate([np.arange(0.2, 2.5, 0.05), np.arange(2.5, 5.0001, 0.025)]), 4)),
    headings_deg=np.arange(0.0, 360.0, 30.0),
)

# barge-speeds: the barge preset's hull, panels, mass properties and lid (placed for the barge's 3 rad/s via
# lid_omega) at forward speeds 0, 2 and 4 m/s (the speed set, system.toml's [[database]]) and, solved directly, 3 m/s (the
# target of a test of interpolation in speed), in the convention of the module docstring: A and B on the
# grid of ENCOUNTER frequencies 0.3-2.5 rad/s, X on the grid of wave frequencies 0.3-2.5 rad/s (every 0.05:
# those of the barge preset's grid coincide), headings 0-180 deg every 30 (the hull is symmetric
# port-starboard and on the x axis); Capytaine's RAO at 0 m/s (capytaine_rao.csv, the database's headings)
# and at 3 m/s (capytaine_rao_u3.csv, 90-180 deg, from A and B solved at each (w, beta)).
# Run (966 s beside a cargo build, load 3.5-4.6; 0 / 2 / 4 / 3 m/s: 21 / 255 / 241 / 448 s, a diffraction
# problem at speed about 0.7 s; 384 hull + 147 lid panels, lid at z = -0.646 m as the barge's): the zero-speed
# set equals config/vessels/barge at their 28 common frequencies to 1e-14 of each mode's scale
# (tools/bem/check_speed_interp.py --against). At speed: the .3 needs w_e from 0.0025 to 5.05 rad/s (4 m/s;
# head seas beyond the .1's 2.5 and the lid's 3.75 rad/s), one cell with w_e < 0 (4 m/s, beta 0, 2.5 rad/s);
# the symmetric part of B(w_e) is indefinite at nearly every frequency (scaled eigenvalue down to -1.23 at
# 4 m/s: the pitch-heave couplings B35, B53 are not antisymmetric in Capytaine's model). In Capytaine's model
# A and B at a fixed w_e are exactly quadratic in U (the Green function depends on w_e only; the body
# condition and the pressure are linear in U): interpolation through 0, 2, 4 m/s reproduces the direct 3 m/s
# diagonals to round-off (couplings to 0.16 % / 0.43 % of their peak: u0 is symmetrized), linear between 2 and
# 4 m/s misses A55 by 6.8 % of its peak (at 0.3 rad/s) and B55 by 0.96 %. X at a fixed w is not (w_e moves with
# U): linear 4.6 % (heave) to 31 % (surge, beta 60, 2.3 rad/s) of the curve's peak, quadratic no better;
# 1.6-7 % below 1.5 rad/s.
PRESETS["barge-speeds"] = dict(
    PRESETS["barge"],
    stem="barge_u0",
    lid_omega=3.0,
    omegas=np.round(np.arange(0.3, 2.5001, 0.05), 4),
    headings_deg=np.arange(0.0, 180.0001, 30.0),
    # (stem, forward speed in m/s, listed in system.toml's [[database]])
    speeds=[("barge_u0", 0.0, True), ("barge_u2", 2.0, True), ("barge_u4", 4.0, True), ("direct_u3", 3.0, False)],
    rao_headings_deg={"barge_u0": np.arange(0.0, 180.0001, 30.0), "direct_u3": np.arange(90.0, 180.0001, 30.0)},
)


def fmt(v):
    return f"{v:.7e}"


def build_system(p):
    """The preset's bodies with their mass properties and hydrostatics; (built, bodies, system, dof names)."""
    omegas = np.asarray(p["omegas"], dtype=float)
    omega_max = float(omegas.max())
    built = [make_body(b["name"], b["hull"], b["length"], b["beam"], b["draft"], b["position"], p["panel_m"],
                       omega_max, b["kg_m"], b["radii"], p.get("lid", "lowest"), p.get("lid_omega"))
             for b in p["bodies"]]
    bodies = [b[0] for b in built]
    for (body, mass, cog, z_lid), spec in zip(built, p["bodies"]):
        m = mass_matrix(mass, cog - np.array(spec["position"]), spec["radii"])
        body.inertia_matrix = body.add_dofs_labels_to_matrix(m)
        body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness(rho=RHO, g=G)
        lid_text = "no lid" if z_lid is None else f"{body.lid_mesh.nb_faces} lid panels at z = {z_lid:.2f} m"
        print(f"{body.name}: {body.mesh.nb_faces} hull panels, {lid_text}, mass {mass:.4e} kg, CoG {cog}",
              flush=True)
    system = bodies[0] if len(bodies) == 1 else cpt.Multibody(bodies)
    return built, bodies, system, list(system.dofs.keys())


def make_solver(p):
    # unless a preset chooses otherwise (every preset before session 12), Capytaine's defaults: the indirect
    # (source) formulation, the Green function's singularities integrated for low frequencies
    bem_method = p.get("bem_method", "indirect")
    gf_singularities = p.get("gf_singularities", "low_freq")
    solver = cpt.BEMSolver(green_function=cpt.Delhommeau(gf_singularities=gf_singularities), method=bem_method)
    return solver, bem_method, gf_singularities


def symmetrize(dset, names, dof_names, key_suffix=""):
    """Reciprocity: radiation added mass and damping are symmetric matrices (Green's second identity); a
    panel method's are not, by its discretization error (measured on the pair preset: up to 3 % of
    sqrt(A_ii A_jj) in A, 4 % in B, and a heave-yaw coupling between the two hulls off by a factor 15
    at low frequency, which alone moved the lighter's beam-sea yaw RAO by 6 %). No time-domain model
    can be both passive and unsymmetric, and the two BEM estimates of each coupling are equally good:
    write their mean, and record how far apart they were. (At zero forward speed only: at speed the
    asymmetry is physical.) Returns {name + key_suffix: worst}."""
    asym = {}
    for name in names:
        da = dset[name]
        swapped = da.rename({"radiating_dof": "influenced_dof", "influenced_dof": "radiating_dof"})
        sym = 0.5 * (da + swapped).transpose(*da.dims)
        diag = np.sqrt(np.abs(np.asarray([da.sel(radiating_dof=d, influenced_dof=d).values
                                          for d in dof_names])).reshape(len(dof_names), -1).max(axis=1))
        scale = xr.DataArray(np.outer(diag, diag), dims=("radiating_dof", "influenced_dof"),
                             coords={"radiating_dof": dof_names, "influenced_dof": dof_names})
        worst = float((np.abs(da - swapped) / scale.where(scale > 0)).max())
        key = name + key_suffix
        asym[key] = worst
        print(f"{key}: largest asymmetry {100 * worst:.3f} % of sqrt(X_ii X_jj), symmetrized", flush=True)
        dset[name] = sym
    return asym


def asymmetry(mats):
    """Largest |X_ij - X_ji| / sqrt(max|X_ii| max|X_jj|) of matrices mats[iw, i, j] (not symmetrized)."""
    diag = np.sqrt(np.abs(np.diagonal(mats, axis1=1, axis2=2)).max(axis=0))
    scale = np.outer(diag, diag)
    scale = np.where(scale > 0, scale, np.nan)
    return float(np.nanmax(np.abs(mats - np.transpose(mats, (0, 2, 1))) / scale))


def roll_damping(a_diag, omegas, mmat, cmat, specs):
    """Viscous roll damping (potential flow alone leaves ship roll almost undamped, 0.1 % of critical here):
    a linear B44 giving `roll_damping_ratio` of critical at each body's roll natural frequency. Written
    to system.toml as linear_damping and passed to Capytaine's RAO as dissipation, so both agree.
    a_diag[iw, i]: the diagonal of A(w). Returns (dissipation matrix, B44 per body)."""
    nmodes = mmat.shape[0]
    dissipation = np.zeros((nmodes, nmodes))
    roll_b44 = []
    for k, spec in enumerate(specs):
        i = 6 * k + 3
        am = a_diag[:, i]
        w = math.sqrt(cmat[i, i] / mmat[i, i])
        for _ in range(50):
            a44 = float(np.interp(w, omegas, am))
            w = 0.5 * w + 0.5 * math.sqrt(cmat[i, i] / (mmat[i, i] + a44))
        a44 = float(np.interp(w, omegas, am))
        b44 = 2.0 * spec.get("roll_damping_ratio", 0.0) * math.sqrt(cmat[i, i] * (mmat[i, i] + a44))
        dissipation[i, i] = b44
        roll_b44.append(b44)
        print(f"{spec['name']}: roll natural frequency {w:.4f} rad/s, linear roll damping {b44:.4e} N m s/rad",
              flush=True)
    return dissipation, roll_b44


def write_radiation(path, omegas, a, b, limits):
    """.1: PER I J Abar Bbar; A = rho Abar, B = rho w Bbar (ULEN = 1). a[iw, i, j], b[iw, i, j]: WAMIT's A_ij,
    the force in mode i due to motion in mode j (SI); limits: [(PER, A[i, j])] rows first (PER = -1: w = 0,
    PER = 0: w = infinity)."""
    nmodes = a.shape[1]
    with open(path, "w") as f:
        for per, lim in limits:
            for i in range(nmodes):
                for j in range(nmodes):
                    f.write(f"{fmt(per)} {i + 1:3d} {j + 1:3d} {fmt(lim[i, j] / RHO)}\n")
        for io_, omega in enumerate(omegas):
            per = 2 * np.pi / omega
            for i in range(nmodes):
                for j in range(nmodes):
                    f.write(f"{fmt(per)} {i + 1:3d} {j + 1:3d} {fmt(a[io_, i, j] / RHO)} "
                            f"{fmt(b[io_, i, j] / (RHO * omega))}\n")


def write_excitation(path, omegas, headings_deg, x):
    """.3: PER BETA I |X| phase Re Im; X = rho g (Re + i Im). x[iw, ib, i]: X in N (N m) per metre of wave
    amplitude, already in exp(+i w t)."""
    with open(path, "w") as f:
        for io_, omega in enumerate(omegas):
            per = 2 * np.pi / omega
            for ib, beta in enumerate(headings_deg):
                for i in range(x.shape[2]):
                    v = complex(x[io_, ib, i]) / (RHO * G)
                    f.write(f"{fmt(per)} {fmt(beta)} {i + 1:3d} {fmt(abs(v))} {fmt(np.degrees(np.angle(v)))} "
                            f"{fmt(v.real)} {fmt(v.imag)}\n")


def write_hst(path, cmat):
    """.hst: I J Cbar, C = rho g Cbar"""
    with open(path, "w") as f:
        for i in range(cmat.shape[0]):
            for j in range(cmat.shape[1]):
                f.write(f"{i + 1:3d} {j + 1:3d} {fmt(cmat[i, j] / (RHO * G))}\n")


def write_rao_csv(path, omegas, headings_deg, r):
    """Capytaine's own RAO, r[iw, ib, i] already in exp(+i w t)."""
    with open(path, "w") as f:
        f.write("omega,heading_deg,mode,amplitude,phase_deg\n")
        for io_, omega in enumerate(omegas):
            for ib, beta in enumerate(headings_deg):
                for i in range(r.shape[2]):
                    x = complex(r[io_, ib, i])
                    f.write(f"{omega:.6g},{beta:.6g},{i + 1},{abs(x):.9e},{np.degrees(np.angle(x)):.6f}\n")


def write_system_toml(path, preset, stem, built, p, roll_b44):
    with open(path, "w") as f:
        f.write(f"# shipcast system file, written by tools/bem/make_db.py --preset {preset}\n")
        f.write(f"# Capytaine {cpt.__version__}; conventions: shipcast DESIGN.md section 1\n")
        f.write(f'wamit = "{stem}"\nulen = 1.0\nrho = {RHO}\ng = {G}\nwater_depth = "infinite"\n')
        f.write("hydrodynamic_coupling = true\n")
        for (body, mass, cog, _), spec in zip(built, p["bodies"]):
            pos = np.array(spec["position"], dtype=float)
            f.write(f'\n[[body]]\nname = "{spec["name"]}"\n')
            f.write(f"# {spec['hull']} hull, L = {spec['length']} m, B = {spec['beam']} m, T = {spec['draft']} m\n")
            f.write(f"position = [{pos[0]:.6g}, {pos[1]:.6g}, {pos[2]:.6g}]\n")
            f.write(f"mass = {mass:.9e}\n")
            rel = cog - pos
            f.write(f"centre_of_gravity = [{rel[0]:.9g}, {rel[1]:.9g}, {rel[2]:.9g}]   # relative to position\n")
            f.write(f"radii_of_gyration = [{spec['radii'][0]:.9g}, {spec['radii'][1]:.9g}, {spec['radii'][2]:.9g}]\n")
            b44 = roll_b44[p["bodies"].index(spec)]
            if b44 > 0.0:
                f.write(f"# viscous roll damping: {spec['roll_damping_ratio']:.0%} of critical at the roll natural frequency\n")
                rows = [[0.0] * 6 for _ in range(6)]
                rows[3][3] = b44
                f.write("linear_damping = [\n" + "".join(f"    [{', '.join(f'{v:.9e}' for v in r)}],\n" for r in rows) + "]\n")
        for name, body, at in p.get("points", []):
            f.write(f'\n[[point]]\nname = "{name}"\nbody = "{body}"\nposition_m = [{at[0]}, {at[1]}, {at[2]}]\n')
        for name, a, b in p.get("relative_motions", []):
            f.write(f'\n[[relative_motion]]\nname = "{name}"\npoint_a = "{a}"\npoint_b = "{b}"\n')


def damping_passivity(bmat, omegas, label=""):
    """Passivity of the damping: the smallest eigenvalue of the symmetric part of B(w), raw (relative to the
    largest |eigenvalue| at that frequency) and in coordinates scaled by sqrt(max_w B_ii) as shipcast's
    hydro::radiation::passive_damping does (translations and rotations weigh alike). bmat[iw, i, j]."""
    nmodes = bmat.shape[1]
    peaks = np.array([np.abs(bmat[:, i, i]).max() for i in range(nmodes)])
    sc = np.sqrt(np.where(peaks > 1e-9 * peaks.max(), peaks, np.inf))
    indefinite, lowest_scaled, lowest_at = [], 0.0, None
    for io_, omega in enumerate(omegas):
        bs = 0.5 * (bmat[io_] + bmat[io_].T)
        raw = np.linalg.eigvalsh(bs)
        scaled = np.linalg.eigvalsh(bs / np.outer(sc, sc))
        if scaled.min() < -1e-3:
            indefinite.append(float(omega))
            print(f"{label}B indefinite at omega = {omega:.4g}: min eigenvalue {raw.min() / np.abs(raw).max():+.4f} of "
                  f"the largest |eigenvalue|, scaled {scaled.min():+.4f}", flush=True)
        if scaled.min() < lowest_scaled:
            lowest_scaled, lowest_at = float(scaled.min()), float(omega)
    return indefinite, lowest_scaled, lowest_at


def natural_periods(bodies, a_diag, omegas, mmat, cmat, label=""):
    """Natural periods of heave, roll and pitch: the lowest frequency in the data with C_ii = w^2 (M_ii + A_ii(w))."""
    natural = []
    for k in range(len(bodies)):
        periods = {}
        for j, name in ((2, "heave"), (3, "roll"), (4, "pitch")):
            i = 6 * k + j
            am = a_diag[:, i]
            res = cmat[i, i] - omegas**2 * (mmat[i, i] + am)
            cross = np.nonzero((res[:-1] > 0) & (res[1:] <= 0))[0]
            if len(cross) == 0:
                periods[name] = None
                continue
            n = cross[0]
            w = omegas[n] + (omegas[n + 1] - omegas[n]) * res[n] / (res[n] - res[n + 1])
            periods[name] = float(2 * np.pi / w)
            print(f"{label}{bodies[k].name}: {name} natural period {2 * np.pi / w:.3f} s ({w:.4f} rad/s)", flush=True)
        natural.append(periods)
    return natural


def speed_system_files(outdir, stem0, speed_set, direct):
    """Completes OUTDIR/system.toml with the speed set (shipcast's `[[database]]` entries: speed_m_s and
    wamit, ascending speeds; `wamit` stays the zero-speed set), and writes for each set solved directly
    at a speed outside the set a system file `<stem>.toml` of the same bodies naming it alone (what the
    interpolation in speed is checked against)."""
    path = os.path.join(outdir, "system.toml")
    with open(path) as f:
        text = f.read()
    for stem in direct:
        with open(os.path.join(outdir, f"{stem}.toml"), "w") as f:
            f.write(text.replace(f'wamit = "{stem0}"', f'wamit = "{stem}"', 1))
    with open(path, "a") as f:
        f.write("\n# databases at forward speeds: A and B against the encounter frequency, X against the wave\n"
                "# frequency (bem_info.toml `convention`); shipcast interpolates between them\n")
        for stem, speed in sorted(speed_set, key=lambda s: s[1]):
            f.write(f'\n[[database]]\nspeed_m_s = {speed:.1f}\nwamit = "{stem}"\n')


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--preset", choices=sorted(PRESETS), required=True)
    ap.add_argument("outdir")
    args = ap.parse_args()
    p = PRESETS[args.preset]
    os.makedirs(args.outdir, exist_ok=True)
    if "speeds" in p:
        return main_speeds(args, p)
    t0 = time.time()
    omegas = np.asarray(p["omegas"], dtype=float)
    omega_max = float(omegas.max())
    built, bodies, system, dof_names = build_system(p)
    nmodes = len(dof_names)
    solver, bem_method, gf_singularities = make_solver(p)

    # The database's headings (the .3 file) and the headings of Capytaine's RAO (capytaine_rao.csv; a preset's
    # `rao_headings_deg`, by default the database's): the diffraction problems are solved at both.
    db_headings = np.asarray(p["headings_deg"], dtype=float)
    rao_headings = np.asarray(p.get("rao_headings_deg", db_headings), dtype=float)
    solved_headings = np.unique(np.round(np.concatenate([db_headings, rao_headings]), 9))
    db_index = [int(np.argmin(np.abs(solved_headings - h))) for h in db_headings]
    rao_index = [int(np.argmin(np.abs(solved_headings - h))) for h in rao_headings]
    headings_rad = np.radians(solved_headings)
    test = xr.Dataset(coords={"omega": omegas, "wave_direction": headings_rad,
                              "radiating_dof": dof_names, "water_depth": [np.inf], "rho": [RHO], "g": [G]})
    ds = solver.fill_dataset(test, system, progress_bar=False)
    # infinite-frequency and zero-frequency added mass (radiation only)
    limits = xr.Dataset(coords={"omega": [0.0, np.inf], "radiating_dof": dof_names, "water_depth": [np.inf],
                                "rho": [RHO], "g": [G]})
    ds_lim = solver.fill_dataset(limits, system, progress_bar=False)
    t_solve = time.time() - t0
    asym = symmetrize(ds, ("added_mass", "radiation_damping"), dof_names)
    asym.update(symmetrize(ds_lim, ("added_mass",), dof_names, "_limits"))

    mmat = np.asarray(system.inertia_matrix)
    cmat = np.asarray(system.hydrostatic_stiffness)
    ds["inertia_matrix"] = system.inertia_matrix
    ds["hydrostatic_stiffness"] = system.hydrostatic_stiffness
    a_w = np.asarray(ds["added_mass"].transpose("omega", "influenced_dof", "radiating_dof").values)
    b_w = np.asarray(ds["radiation_damping"].transpose("omega", "influenced_dof", "radiating_dof").values)
    a_diag = np.diagonal(a_w, axis1=1, axis2=2)
    dissipation, roll_b44 = roll_damping(a_diag, omegas, mmat, cmat, p["bodies"])
    rao = cpt.post_pro.rao(ds, dissipation=system.add_dofs_labels_to_matrix(dissipation))

    stem = os.path.join(args.outdir, p["stem"])
    lim_a = ds_lim["added_mass"].transpose("omega", "influenced_dof", "radiating_dof", ...)
    lim_rows = [(per, np.asarray(lim_a.sel(omega=omega).values).reshape(nmodes, nmodes))
                for omega, per in ((0.0, -1.0), (np.inf, 0.0))]
    write_radiation(stem + ".1", omegas, a_w, b_w, lim_rows)
    # excitation in exp(+i w t): conjugate Capytaine's value
    exc = np.conj(np.asarray(ds["excitation_force"].transpose("omega", "wave_direction", "influenced_dof").values))
    write_excitation(stem + ".3", omegas, db_headings, exc[:, db_index, :])
    write_hst(stem + ".hst", cmat)
    # Capytaine's own RAO, exp(+i w t)
    r = np.conj(np.asarray(rao.transpose("omega", "wave_direction", "radiating_dof").values))
    write_rao_csv(os.path.join(args.outdir, "capytaine_rao.csv"), omegas, rao_headings, r[:, rao_index, :])
    write_system_toml(os.path.join(args.outdir, "system.toml"), args.preset, p["stem"], built, p, roll_b44)
    indefinite, lowest_scaled, lowest_at = damping_passivity(b_w, omegas)
    natural = natural_periods(bodies, a_diag, omegas, mmat, cmat)
    with open(os.path.join(args.outdir, "bem_info.toml"), "w") as f:
        f.write(f'capytaine_version = "{cpt.__version__}"\npreset = "{args.preset}"\n')
        f.write(f'command = "python3 tools/bem/make_db.py --preset {args.preset} {args.outdir}"\n')
        f.write(f"solve_seconds = {t_solve:.1f}\n")
        f.write(f'bem_method = "{bem_method}"\ngf_singularities = "{gf_singularities}"\n')
        for key, worst in asym.items():
            f.write(f"asymmetry_{key} = {worst:.6f}   # largest |X_ij - X_ji| / sqrt(X_ii X_jj) before symmetrizing\n")
        f.write(f"n_omega = {len(omegas)}\nomega_min = {omegas.min()}\nomega_max = {omega_max}\n")
        f.write(f"headings_deg = {list(map(float, db_headings))}\n")
        f.write(f"rao_headings_deg = {list(map(float, rao_headings))}   # the headings of capytaine_rao.csv\n")
        f.write(f'lid = "{p.get("lid", "lowest")}"\n')
        f.write(f"damping_indefinite_omegas = {[float(w) for w in indefinite]}   # symmetric B(w), scaled: "
                f"an eigenvalue below -1e-3\n")
        f.write(f"damping_lowest_scaled_eigenvalue = {lowest_scaled:.6f}"
                + ("\n" if lowest_at is None else f"   # at omega = {lowest_at}\n"))
        for body, _, _, z_lid in built:
            n_lid = 0 if z_lid is None else body.lid_mesh.nb_faces
            f.write(f'[panels.{body.name}]\nhull = {body.mesh.nb_faces}\nlid = {n_lid}\n')
            if z_lid is not None:
                f.write(f"lid_z = {z_lid:.6f}\n")
        for body, periods in zip(bodies, natural):
            f.write(f"[natural_periods_s.{body.name}]   # C_ii = w^2 (M_ii + A_ii(w)), lowest root in the data\n")
            for name, t in periods.items():
                f.write(f"{name} = {'nan' if t is None else f'{t:.4f}'}\n")
    print(f"done in {time.time() - t0:.1f} s: {len(omegas)} frequencies, {len(db_headings)} database headings "
          f"({len(solved_headings)} solved), {nmodes} modes", flush=True)
    # diagonal damping must be non-negative (irregular frequencies, coarse panels)
    bd = ds["radiation_damping"]
    for k, name in enumerate(dof_names):
        v = np.asarray(bd.sel(radiating_dof=name, influenced_dof=name).values)
        if (v < -1e-6 * max(1.0, np.abs(v).max())).any():
            print(f"WARNING: negative damping on {name} at omega = {omegas[v < 0]}", file=sys.stderr)


# ---------------------------------------------------------------------------------------------------------
# Forward speed (a preset with `speeds`): see SPEED_CONVENTION

SPEED_CONVENTION = __doc__[__doc__.index("One WAMIT file set per forward speed"):].rstrip()


def diffraction_problem(body, omega, beta_rad, speed):
    """Capytaine's DiffractionProblem, with the incident wave's normal velocity on the hull corrected where
    the Doppler-shifted frequency w - k U cos beta is negative. There Capytaine 3.0.0 solves at |w_e| with
    the wave turned by 180 deg (encounter_wave_direction = beta + pi): airy_waves_pressure (the Froude-Krylov
    pressure, rho g exp(-i k x.d) e^{kz}) is then the complex conjugate of the true incident wave's, as it
    should be, but airy_waves_velocity keeps the vertical component -i (g k / w) exp(-i k x.d) e^{kz}, where
    the conjugate wave has +i: the diffraction boundary condition is wrong (measured on the barge at 4 m/s in
    following seas, 2.40-2.50 rad/s: heave and pitch X jumped by 10 % and 40 % across w_e = 0; with this
    correction they are continuous). Set the boundary condition to -(conj(v_I) . n), v_I the incident velocity at zero
    speed (the same w, k and beta)."""
    pb = cpt.DiffractionProblem(body=body, omega=omega, wave_direction=beta_rad, forward_speed=speed,
                                water_depth=np.inf, rho=RHO, g=G)
    if speed != 0.0 and pb.encounter_wave_direction != pb.wave_direction:
        still = cpt.DiffractionProblem(body=body, omega=omega, wave_direction=beta_rad, water_depth=np.inf,
                                       rho=RHO, g=G)
        v = np.conj(airy_waves_velocity(body.mesh.faces_centers, still))
        pb.boundary_condition[body.hull_mask] = -(v * body.mesh.faces_normals).sum(axis=1)
    return pb


def solve_in_order(solver, problems):
    """solve_all, results in the order of `problems` (solve_all groups them), failures raised."""
    results = solver.solve_all(problems, progress_bar=False)
    by_id = {id(r.problem): r for r in results}
    out = [by_id[id(pb)] for pb in problems]
    for r in out:
        if hasattr(r, "exception"):
            raise RuntimeError(f"{r.problem}: {r.exception}")
    return out


def excitation_of(result):
    """Capytaine's excitation (diffraction + Froude-Krylov) of a diffraction result, per influenced dof."""
    return {rec["influenced_dof"]: rec["diffraction_force"] + rec["Froude_Krylov_force"] for rec in result.records}


def main_speeds(args, p):
    t0 = time.time()
    outdir = args.outdir
    omegas = np.asarray(p["omegas"], dtype=float)
    db_headings = np.asarray(p["headings_deg"], dtype=float)
    built, bodies, system, dof_names = build_system(p)
    if len(bodies) != 1:
        raise ValueError("forward speed: Capytaine 3.0.0 implements it for a single rigid body only")
    nmodes = len(dof_names)
    solver, bem_method, gf_singularities = make_solver(p)
    if bem_method != "indirect":
        raise ValueError("forward speed: Capytaine's direct method does not solve problems with forward speed")
    mmat = np.asarray(system.inertia_matrix)
    cmat = np.asarray(system.hydrostatic_stiffness)
    speeds = p["speeds"]
    rao_heads = {stem: np.asarray(h, dtype=float) for stem, h in p.get("rao_headings_deg", {}).items()}
    sets = {}

    # zero speed: as the other presets (fill_dataset; A and B symmetrized; Capytaine's RAO)
    stem0, u0, _ = next(s for s in speeds if s[1] == 0.0)
    rao0 = rao_heads.get(stem0, np.zeros(0))
    solved0 = np.unique(np.round(np.concatenate([db_headings, rao0]), 9))
    db_index = [int(np.argmin(np.abs(solved0 - h))) for h in db_headings]
    rao0_index = [int(np.argmin(np.abs(solved0 - h))) for h in rao0]
    test = xr.Dataset(coords={"omega": omegas, "wave_direction": np.radians(solved0), "radiating_dof": dof_names,
                              "water_depth": [np.inf], "rho": [RHO], "g": [G]})
    ds = solver.fill_dataset(test, system, progress_bar=False)
    ds_lim = solver.fill_dataset(xr.Dataset(coords={"omega": [0.0, np.inf], "radiating_dof": dof_names,
                                                    "water_depth": [np.inf], "rho": [RHO], "g": [G]}),
                                 system, progress_bar=False)
    asym0 = symmetrize(ds, ("added_mass", "radiation_damping"), dof_names)
    asym0.update(symmetrize(ds_lim, ("added_mass",), dof_names, "_limits"))
    ds["inertia_matrix"] = system.inertia_matrix
    ds["hydrostatic_stiffness"] = system.hydrostatic_stiffness
    a_w = np.asarray(ds["added_mass"].transpose("omega", "influenced_dof", "radiating_dof").values)
    b_w = np.asarray(ds["radiation_damping"].transpose("omega", "influenced_dof", "radiating_dof").values)
    dissipation, roll_b44 = roll_damping(np.diagonal(a_w, axis1=1, axis2=2), omegas, mmat, cmat, p["bodies"])
    lim_a = ds_lim["added_mass"].transpose("omega", "influenced_dof", "radiating_dof", ...)
    a_zero = np.asarray(lim_a.sel(omega=0.0).values).reshape(nmodes, nmodes)
    a_inf = np.asarray(lim_a.sel(omega=np.inf).values).reshape(nmodes, nmodes)
    exc = np.conj(np.asarray(ds["excitation_force"].transpose("omega", "wave_direction", "influenced_dof").values))
    rao = None
    if len(rao0):
        r = cpt.post_pro.rao(ds, dissipation=system.add_dofs_labels_to_matrix(dissipation))
        rao = np.conj(np.asarray(r.transpose("omega", "wave_direction", "radiating_dof").values))[:, rao0_index, :]
    sets[stem0] = dict(speed=0.0, a=a_w, b=b_w, x=exc[:, db_index, :], limits=[(-1.0, a_zero), (0.0, a_inf)],
                       asym={f"{k}": v for k, v in asym0.items()}, symmetrized=True, rao=rao, rao_headings=rao0,
                       negative_encounter=[], seconds=time.time() - t0)
    print(f"{stem0}: U = 0 m/s solved in {sets[stem0]['seconds']:.1f} s", flush=True)

    beta90 = np.radians(90.0)
    for stem, speed, _ in speeds:
        if speed == 0.0:
            continue
        t1 = time.time()
        # radiation on the grid of encounter frequencies: w = w_e at beta = 90 deg
        rad_pbs = [cpt.RadiationProblem(body=system, omega=we, wave_direction=beta90, forward_speed=speed,
                                        radiating_dof=d, water_depth=np.inf, rho=RHO, g=G)
                   for we in omegas for d in dof_names]
        rheads = rao_heads.get(stem, np.zeros(0))
        solved = np.unique(np.round(np.concatenate([db_headings, rheads]), 9))
        diff_pbs = [diffraction_problem(system, w, np.radians(h), speed) for w in omegas for h in solved]
        # Capytaine's RAO at speed takes A and B at (w, beta) (fill_dataset's radiation problems at speed):
        # the radiation problems at the RAO's headings other than 90 deg (90 deg: the encounter grid's)
        rao_rad_heads = [h for h in rheads if not np.isclose(h, 90.0)]
        rao_pbs = [cpt.RadiationProblem(body=system, omega=w, wave_direction=np.radians(h), forward_speed=speed,
                                        radiating_dof=d, water_depth=np.inf, rho=RHO, g=G)
                   for w in omegas for h in rao_rad_heads for d in dof_names]
        rad = solve_in_order(solver, rad_pbs)
        diff = solve_in_order(solver, diff_pbs)
        rao_rad = solve_in_order(solver, rao_pbs) if rao_pbs else []
        a = np.zeros((len(omegas), nmodes, nmodes))
        b = np.zeros((len(omegas), nmodes, nmodes))
        for io_, we in enumerate(omegas):
            for j, dj in enumerate(dof_names):
                res = rad[io_ * nmodes + j]
                assert res.radiating_dof == dj and np.isclose(res.encounter_omega, we, rtol=1e-12)
                for i, di in enumerate(dof_names):
                    a[io_, i, j] = res.added_mass[di]
                    b[io_, i, j] = res.radiation_damping[di]
        x = np.zeros((len(omegas), len(solved), nmodes), dtype=complex)
        negative = []
        for io_, w in enumerate(omegas):
            for ib, h in enumerate(solved):
                res = diff[io_ * len(solved) + ib]
                f = excitation_of(res)
                v = np.array([f[d] for d in dof_names])
                if res.encounter_wave_direction != res.wave_direction:
                    negative.append((float(w), float(h), float(-res.encounter_omega)))
                    x[io_, ib] = v          # solved at |w_e| with the conjugate wave: already exp(+i w_e' t)
                else:
                    x[io_, ib] = np.conj(v)
        if not (np.isfinite(a).all() and np.isfinite(b).all() and np.isfinite(x).all()):
            raise RuntimeError(f"{stem}: NaN in Capytaine's results (zero encounter frequency?)")
        db_idx = [int(np.argmin(np.abs(solved - h))) for h in db_headings]
        rao = None
        if len(rheads):
            # Capytaine's own RAO machinery (post_pro.rao uses the dataset's encounter_omega)
            keep = set(np.round(rheads, 9))
            rad90 = rad if any(np.isclose(rheads, 90.0)) else []
            diff_r = [r for r in diff if round(float(np.degrees(r.wave_direction)), 9) in keep]
            dsr = cpt.assemble_dataset(rad90 + rao_rad + diff_r, hydrostatics=False)
            dsr["inertia_matrix"] = system.inertia_matrix
            dsr["hydrostatic_stiffness"] = system.hydrostatic_stiffness
            r = cpt.post_pro.rao(dsr, dissipation=system.add_dofs_labels_to_matrix(dissipation))
            r = r.squeeze(drop=True).transpose("omega", "wave_direction", "radiating_dof")
            assert np.allclose(r["wave_direction"].values, np.radians(rheads))
            rao = np.conj(np.asarray(r.values))
        sets[stem] = dict(speed=speed, a=a, b=b, x=x[:, db_idx, :], limits=[(0.0, a_inf)],
                          asym={"added_mass": asymmetry(a), "radiation_damping": asymmetry(b)}, symmetrized=False,
                          rao=rao, rao_headings=rheads, negative_encounter=negative, seconds=time.time() - t1)
        print(f"{stem}: U = {speed:g} m/s solved in {sets[stem]['seconds']:.1f} s ({len(rad_pbs)} radiation, "
              f"{len(diff_pbs)} diffraction, {len(rao_pbs)} RAO radiation problems); "
              f"{len(negative)} (w, beta) with negative encounter frequency", flush=True)
    t_solve = time.time() - t0

    for stem, s in sets.items():
        path = os.path.join(outdir, stem)
        write_radiation(path + ".1", omegas, s["a"], s["b"], s["limits"])
        write_excitation(path + ".3", omegas, db_headings, s["x"])
        write_hst(path + ".hst", cmat)
        if s["rao"] is not None:
            name = "capytaine_rao.csv" if s["speed"] == 0.0 else f"capytaine_rao_{stem.split('_')[-1]}.csv"
            s["rao_file"] = name
            write_rao_csv(os.path.join(outdir, name), omegas, s["rao_headings"], s["rao"])
        s["passivity"] = damping_passivity(s["b"], omegas, label=f"{stem}: ")
        s["natural"] = natural_periods(bodies, np.diagonal(s["a"], axis1=1, axis2=2), omegas, mmat, cmat,
                                       label=f"{stem}: ")
    write_system_toml(os.path.join(outdir, "system.toml"), args.preset, stem0, built, p, roll_b44)
    speed_system_files(outdir, stem0, [(stem, speed) for stem, speed, in_set in speeds if in_set],
                       [stem for stem, _, in_set in speeds if not in_set])
    with open(os.path.join(outdir, "bem_info.toml"), "w") as f:
        f.write(f'capytaine_version = "{cpt.__version__}"\npreset = "{args.preset}"\n')
        f.write(f'command = "python3 tools/bem/make_db.py --preset {args.preset} {outdir}"\n')
        f.write(f"solve_seconds = {t_solve:.1f}\n")
        f.write(f'bem_method = "{bem_method}"\ngf_singularities = "{gf_singularities}"\n')
        f.write(f"n_omega = {len(omegas)}\nomega_min = {omegas.min()}\nomega_max = {omegas.max()}   "
                f"# the .3's wave frequencies; the .1's encounter frequencies (U != 0) on the same grid\n")
        f.write(f"headings_deg = {list(map(float, db_headings))}\n")
        f.write(f'lid = "{p.get("lid", "lowest")}"\n')
        f.write(f'convention = """\n{SPEED_CONVENTION}\n"""\n')
        body, _, _, z_lid = built[0]
        f.write(f'[panels.{body.name}]\nhull = {body.mesh.nb_faces}\nlid = {0 if z_lid is None else body.lid_mesh.nb_faces}\n')
        if z_lid is not None:
            f.write(f"lid_z = {z_lid:.6f}\n")
        for stem, s in sets.items():
            indefinite, lowest_scaled, lowest_at = s["passivity"]
            f.write(f'\n[[database]]\nwamit = "{stem}"\nspeed_m_s = {s["speed"]:.1f}\n')
            f.write(f"solve_seconds = {s['seconds']:.1f}\n")
            what = "before symmetrizing" if s["symmetrized"] else "as written (not symmetrized: physical at speed)"
            for key, worst in s["asym"].items():
                f.write(f"asymmetry_{key} = {worst:.6f}   # largest |X_ij - X_ji| / sqrt(X_ii X_jj), {what}\n")
            if s["speed"] != 0.0:
                # the encounter frequencies the .3's (w, beta) need, against the .1's grid
                k = omegas**2 / G
                we = np.abs(omegas[:, None] - k[:, None] * s["speed"] * np.cos(np.radians(db_headings))[None, :])
                f.write(f"encounter_omega_needed = [{we.min():.4f}, {we.max():.4f}]   # |w - k U cos beta| over "
                        f"the .3's grid; the .1 covers [{omegas.min()}, {omegas.max()}]\n")
                f.write(f"negative_encounter = {[[w, h, round(e, 5)] for w, h, e in s['negative_encounter']]}"
                        f"   # [w, beta_deg, w - k U cos beta] written unconjugated\n")
            if s["rao"] is not None:
                f.write(f'rao_file = "{s["rao_file"]}"\nrao_headings_deg = {list(map(float, s["rao_headings"]))}\n')
            f.write(f"damping_indefinite_omegas = {[float(w) for w in indefinite]}   # symmetric part of B(w), "
                    f"scaled: an eigenvalue below -1e-3\n")
            f.write(f"damping_lowest_scaled_eigenvalue = {lowest_scaled:.6f}"
                    + ("\n" if lowest_at is None else f"   # at omega = {lowest_at}\n"))
            for bname, periods in zip([b.name for b in bodies], s["natural"]):
                f.write(f"natural_periods_s = {{ {', '.join(f'{n} = ' + ('nan' if t is None else f'{t:.4f}') for n, t in periods.items())} }}"
                        f"   # {bname}: C_ii = w_e^2 (M_ii + A_ii(w_e)), lowest root in the data\n")
    print(f"done in {time.time() - t0:.1f} s: {len(sets)} speeds, {len(omegas)} frequencies, "
          f"{len(db_headings)} database headings, {nmodes} modes", flush=True)


if __name__ == "__main__":
    main()
