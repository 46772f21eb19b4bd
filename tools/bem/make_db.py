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
"""

import argparse
import math
import sys
import time

import numpy as np
import xarray as xr
import capytaine as cpt

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
PRESETS["pair-direct"] = dict(PRESETS["pair"], bem_method="direct")
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


def fmt(v):
    return f"{v:.7e}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--preset", choices=sorted(PRESETS), required=True)
    ap.add_argument("outdir")
    args = ap.parse_args()
    p = PRESETS[args.preset]
    import os
    os.makedirs(args.outdir, exist_ok=True)
    t0 = time.time()
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
    dof_names = list(system.dofs.keys())
    nmodes = len(dof_names)
    # unless a preset chooses otherwise (every preset before session 12), Capytaine's defaults: the indirect
    # (source) formulation, the Green function's singularities integrated for low frequencies
    bem_method = p.get("bem_method", "indirect")
    gf_singularities = p.get("gf_singularities", "low_freq")
    solver = cpt.BEMSolver(green_function=cpt.Delhommeau(gf_singularities=gf_singularities), method=bem_method)

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
    # Reciprocity: radiation added mass and damping are symmetric matrices (Green's second identity); a
    # panel method's are not, by its discretization error (measured on the pair preset: up to 3 % of
    # sqrt(A_ii A_jj) in A, 4 % in B, and a heave-yaw coupling between the two hulls off by a factor 15
    # at low frequency, which alone moved the lighter's beam-sea yaw RAO by 6 %). No time-domain model
    # can be both passive and unsymmetric, and the two BEM estimates of each coupling are equally good:
    # write their mean, and record how far apart they were.
    asym = {}
    for dset, names in ((ds, ("added_mass", "radiation_damping")), (ds_lim, ("added_mass",))):
        for name in names:
            da = dset[name]
            swapped = da.rename({"radiating_dof": "influenced_dof", "influenced_dof": "radiating_dof"})
            sym = 0.5 * (da + swapped).transpose(*da.dims)
            diag = np.sqrt(np.abs(np.asarray([da.sel(radiating_dof=d, influenced_dof=d).values
                                              for d in dof_names])).reshape(len(dof_names), -1).max(axis=1))
            scale = xr.DataArray(np.outer(diag, diag), dims=("radiating_dof", "influenced_dof"),
                                 coords={"radiating_dof": dof_names, "influenced_dof": dof_names})
            worst = float((np.abs(da - swapped) / scale.where(scale > 0)).max())
            key = name if dset is ds else name + "_limits"
            asym[key] = worst
            print(f"{key}: largest asymmetry {100 * worst:.3f} % of sqrt(X_ii X_jj), symmetrized", flush=True)
            dset[name] = sym

    mmat = np.asarray(system.inertia_matrix)
    cmat = np.asarray(system.hydrostatic_stiffness)
    ds["inertia_matrix"] = system.inertia_matrix
    ds["hydrostatic_stiffness"] = system.hydrostatic_stiffness
    # Viscous roll damping (potential flow alone leaves ship roll almost undamped, 0.1 % of critical here):
    # a linear B44 giving `roll_damping_ratio` of critical at each body's roll natural frequency. Written
    # to system.toml as linear_damping and passed to Capytaine's RAO as dissipation, so both agree.
    dissipation = np.zeros((nmodes, nmodes))
    roll_b44 = []
    for k, spec in enumerate(p["bodies"]):
        i = 6 * k + 3
        am = ds["added_mass"].sel(radiating_dof=dof_names[i], influenced_dof=dof_names[i]).values
        w = math.sqrt(cmat[i, i] / mmat[i, i])
        for _ in range(50):
            a44 = float(np.interp(w, omegas, am))
            w = 0.5 * w + 0.5 * math.sqrt(cmat[i, i] / (mmat[i, i] + a44))
        a44 = float(np.interp(w, omegas, am))
        b44 = 2.0 * spec.get("roll_damping_ratio", 0.0) * math.sqrt(cmat[i, i] * (mmat[i, i] + a44))
        dissipation[i, i] = b44
        roll_b44.append(b44)
        print(f"{spec['name']}: roll natural frequency {w:.4f} rad/s, linear roll damping {b44:.4e} N m s/rad", flush=True)
    rao = cpt.post_pro.rao(ds, dissipation=system.add_dofs_labels_to_matrix(dissipation))

    def sel(da, **kw):
        return np.asarray(da.sel(**kw).squeeze().values)

    stem = os.path.join(args.outdir, p["stem"])
    # .1: PER I J Abar Bbar; A = rho Abar, B = rho w Bbar (ULEN = 1)
    with open(stem + ".1", "w") as f:
        lim_a = ds_lim["added_mass"]
        for omega, per in ((0.0, -1.0), (np.inf, 0.0)):
            a = np.asarray(lim_a.sel(omega=omega).transpose("radiating_dof", "influenced_dof", ...)
                           .values).reshape(nmodes, nmodes)
            for i in range(nmodes):
                for j in range(nmodes):
                    # WAMIT A_ij: force in mode i due to motion in mode j
                    f.write(f"{fmt(per)} {i + 1:3d} {j + 1:3d} {fmt(a[j, i] / RHO)}\n")
        for omega in omegas:
            a = np.asarray(ds["added_mass"].sel(omega=omega).transpose("radiating_dof", "influenced_dof").values)
            b = np.asarray(ds["radiation_damping"].sel(omega=omega)
                           .transpose("radiating_dof", "influenced_dof").values)
            per = 2 * np.pi / omega
            for i in range(nmodes):
                for j in range(nmodes):
                    f.write(f"{fmt(per)} {i + 1:3d} {j + 1:3d} {fmt(a[j, i] / RHO)} {fmt(b[j, i] / (RHO * omega))}\n")
    # .3: PER BETA I |X| phase Re Im; X = rho g (Re + i Im), exp(+i w t): conjugate Capytaine's value
    with open(stem + ".3", "w") as f:
        exc = ds["excitation_force"].transpose("omega", "wave_direction", "influenced_dof")
        for io_, omega in enumerate(omegas):
            per = 2 * np.pi / omega
            for ib, beta in zip(db_index, db_headings):
                for i in range(nmodes):
                    x = np.conj(complex(exc.values[io_, ib, i])) / (RHO * G)
                    f.write(f"{fmt(per)} {fmt(beta)} {i + 1:3d} {fmt(abs(x))} {fmt(np.degrees(np.angle(x)))} "
                            f"{fmt(x.real)} {fmt(x.imag)}\n")
    # .hst: I J Cbar, C = rho g Cbar
    with open(stem + ".hst", "w") as f:
        for i in range(nmodes):
            for j in range(nmodes):
                f.write(f"{i + 1:3d} {j + 1:3d} {fmt(cmat[i, j] / (RHO * G))}\n")
    # Capytaine's own RAO, exp(+i w t)
    with open(os.path.join(args.outdir, "capytaine_rao.csv"), "w") as f:
        f.write("omega,heading_deg,mode,amplitude,phase_deg\n")
        r = rao.transpose("omega", "wave_direction", "radiating_dof").values
        for io_, omega in enumerate(omegas):
            for ib, beta in zip(rao_index, rao_headings):
                for i in range(nmodes):
                    x = np.conj(complex(r[io_, ib, i]))
                    f.write(f"{omega:.6g},{beta:.6g},{i + 1},{abs(x):.9e},{np.degrees(np.angle(x)):.6f}\n")
    # system.toml
    with open(os.path.join(args.outdir, "system.toml"), "w") as f:
        f.write(f"# shipcast system file, written by tools/bem/make_db.py --preset {args.preset}\n")
        f.write(f"# Capytaine {cpt.__version__}; conventions: shipcast DESIGN.md section 1\n")
        f.write(f'wamit = "{p["stem"]}"\nulen = 1.0\nrho = {RHO}\ng = {G}\nwater_depth = "infinite"\n')
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
    # Passivity of the (symmetrized) damping: the smallest eigenvalue of B(w), raw (relative to the largest
    # |eigenvalue| at that frequency) and in coordinates scaled by sqrt(max_w B_ii) as shipcast's
    # hydro::radiation::passive_damping does (translations and rotations weigh alike).
    bmat = np.asarray(ds["radiation_damping"].transpose("omega", "influenced_dof", "radiating_dof").values)
    peaks = np.array([np.abs(bmat[:, i, i]).max() for i in range(nmodes)])
    sc = np.sqrt(np.where(peaks > 1e-9 * peaks.max(), peaks, np.inf))
    indefinite, lowest_scaled, lowest_at = [], 0.0, None
    for io_, omega in enumerate(omegas):
        bs = 0.5 * (bmat[io_] + bmat[io_].T)
        raw = np.linalg.eigvalsh(bs)
        scaled = np.linalg.eigvalsh(bs / np.outer(sc, sc))
        if scaled.min() < -1e-3:
            indefinite.append(float(omega))
            print(f"B indefinite at omega = {omega:.4g}: min eigenvalue {raw.min() / np.abs(raw).max():+.4f} of the "
                  f"largest |eigenvalue|, scaled {scaled.min():+.4f}", flush=True)
        if scaled.min() < lowest_scaled:
            lowest_scaled, lowest_at = float(scaled.min()), float(omega)
    # natural periods of heave, roll and pitch: the lowest frequency in the data with C_ii = w^2 (M_ii + A_ii(w))
    natural = []
    for k in range(len(bodies)):
        periods = {}
        for j, name in ((2, "heave"), (3, "roll"), (4, "pitch")):
            i = 6 * k + j
            am = np.asarray(ds["added_mass"].sel(radiating_dof=dof_names[i], influenced_dof=dof_names[i]).values)
            res = cmat[i, i] - omegas**2 * (mmat[i, i] + am)
            cross = np.nonzero((res[:-1] > 0) & (res[1:] <= 0))[0]
            if len(cross) == 0:
                periods[name] = None
                continue
            n = cross[0]
            w = omegas[n] + (omegas[n + 1] - omegas[n]) * res[n] / (res[n] - res[n + 1])
            periods[name] = float(2 * np.pi / w)
            print(f"{bodies[k].name}: {name} natural period {2 * np.pi / w:.3f} s ({w:.4f} rad/s)", flush=True)
        natural.append(periods)
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


if __name__ == "__main__":
    main()
