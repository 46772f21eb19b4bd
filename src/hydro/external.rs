//! External models of the system file (pure): connections (spring-dampers, bushings, mooring lines,
//! fenders), passive anti-roll U-tube tanks, points of interest and relative motions.
//!
//! Conventions (DESIGN.md section 1): SI units; body frame x forward, y to port, z up, origin at the
//! body's reference point (`position` in the system file, BEM global frame); DOF order surge..yaw per
//! body. Points on a body are given in body coordinates: metres from the body's reference point, body
//! axes; points on the earth in the BEM global frame. Small rotations: a point r on a body whose motion
//! is (xi, theta) is displaced by xi + theta x r (linear kinematics; the second-order terms are left out,
//! as everywhere in linear seakeeping).
//!
//! Equilibrium: the positions in the system file are the static equilibrium. A connection enters the
//! equations of motion as F(x, v) - F(0, 0): its force at equilibrium (pretension, initial fender
//! compression) is taken as balanced by the mean loads, so the linear model stays about its
//! equilibrium. What a connection reports as an output is its whole force (a line's tension includes the
//! pretension, a slack line reports 0, a fender never reports a pull).
//!
//! Tank states: each tank adds one state after the 6N body modes, in file order (state 6N + k is the
//! k-th tank's fluid angle tau, rad, the angle of the fluid line relative to the ship, positive when the
//! port reservoir is higher).

use nalgebra::{DMatrix, Matrix3, Vector3};
use serde::Deserialize;

/// Where a connection end sits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    /// Body index, or None for the earth.
    pub body: Option<usize>,
    /// Body coordinates (m from the body's reference point) or, for the earth, the global frame.
    pub point_m: Vector3<f64>,
}

/// A force-deflection (fender) or tension-elongation (line) curve, force >= 0 and non-decreasing.
#[derive(Debug, Clone, PartialEq)]
pub enum Curve {
    /// (deflection or elongation m, force N), deflections increasing; linear between points, linear
    /// from (0, 0) to the first point, the last segment's slope beyond the last.
    Table(Vec<(f64, f64)>),
    /// F(e) = c1 e + c2 e^2 + ... (coefficients from the first power).
    Polynomial(Vec<f64>),
}

impl Curve {
    /// Force at deflection `e` (0 for e <= 0).
    pub fn force(&self, e: f64) -> f64 {
        if e <= 0.0 {
            return 0.0;
        }
        match self {
            Curve::Polynomial(c) => c.iter().rev().fold(0.0, |acc, ck| (acc + ck) * e),
            Curve::Table(t) => {
                let mut prev = (0.0, 0.0);
                for &(x, f) in t {
                    if e <= x {
                        return if x > prev.0 {
                            prev.1 + (f - prev.1) * (e - prev.0) / (x - prev.0)
                        } else {
                            f
                        };
                    }
                    prev = (x, f);
                }
                // beyond the table: the last segment's slope
                let n = t.len();
                let (x0, f0) = if n >= 2 { t[n - 2] } else { (0.0, 0.0) };
                let (x1, f1) = t[n - 1];
                let slope = if x1 > x0 { (f1 - f0) / (x1 - x0) } else { 0.0 };
                f1 + slope * (e - x1)
            }
        }
    }

    /// Strain energy: the integral of the force from 0 to `e` (0 for e <= 0).
    pub fn energy(&self, e: f64) -> f64 {
        if e <= 0.0 {
            return 0.0;
        }
        match self {
            Curve::Polynomial(c) => c
                .iter()
                .enumerate()
                .map(|(k, ck)| ck * e.powi(k as i32 + 2) / (k as f64 + 2.0))
                .sum(),
            Curve::Table(t) => {
                let mut prev = (0.0, 0.0);
                let mut w = 0.0;
                for &(x, _) in t {
                    let upto = e.min(x);
                    if upto > prev.0 {
                        w += 0.5 * (self.force(prev.0) + self.force(upto)) * (upto - prev.0);
                    }
                    if e <= x {
                        return w;
                    }
                    prev = (x, self.force(x));
                }
                w + 0.5 * (self.force(prev.0) + self.force(e)) * (e - prev.0)
            }
        }
    }

    fn validate(&self, range_m: f64) -> Result<(), String> {
        match self {
            Curve::Table(t) => {
                if t.is_empty() {
                    return Err("the curve needs at least one [deflection, force] point".into());
                }
                let mut prev = (0.0, 0.0);
                for (k, &(x, f)) in t.iter().enumerate() {
                    if !(x.is_finite() && f.is_finite()) {
                        return Err(format!("point {k} is not finite: [{x}, {f}]"));
                    }
                    if x <= prev.0 || (k == 0 && x <= 0.0) {
                        return Err(format!(
                            "point {k}: deflections must be positive and increasing, found {x} after {}",
                            prev.0
                        ));
                    }
                    if f < prev.1 {
                        return Err(format!(
                            "point {k}: the curve is not monotonic (force {f} N after {} N)",
                            prev.1
                        ));
                    }
                    prev = (x, f);
                }
                Ok(())
            }
            Curve::Polynomial(c) => {
                if c.is_empty() || c.iter().any(|v| !v.is_finite()) {
                    return Err("the polynomial needs finite coefficients, from the first power".into());
                }
                // non-decreasing and non-negative over [0, range]
                let dfdx = |e: f64| -> f64 {
                    c.iter()
                        .enumerate()
                        .map(|(k, ck)| (k as f64 + 1.0) * ck * e.powi(k as i32))
                        .sum()
                };
                for s in 0..=200 {
                    let e = range_m * s as f64 / 200.0;
                    if dfdx(e) < 0.0 {
                        return Err(format!(
                            "the tension decreases at elongation {e:.4} m (the curve is not monotonic over 0..{range_m:.3} m)"
                        ));
                    }
                }
                Ok(())
            }
        }
    }
}

/// What a connection does.
#[derive(Debug, Clone, PartialEq)]
pub enum ConnectionKind {
    /// Linear spring-damper along a fixed unit axis (global frame) or, without one, along the line
    /// between the two points; the pretension adds the lateral stiffness T / L of a taut line.
    SpringDamper {
        axis: Option<Vector3<f64>>,
        stiffness_n_m: f64,
        damping_n_s_m: f64,
        pretension_n: f64,
    },
    /// Six linear springs and dampers on the relative translation (x, y, z, global axes) and rotation
    /// (about x, y, z) of the two ends: a bushing; with large stiffnesses, a joint.
    Bushing { stiffness: [f64; 6], damping: [f64; 6] },
    /// Tension from the curve of the elongation beyond the unstretched length, zero when slack, plus
    /// axial damping while taut (the tension never goes negative).
    MooringLine {
        curve: Curve,
        unstretched_length_m: f64,
        damping_n_s_m: f64,
    },
    /// Compression-only force along `normal` (unit, global, the direction the fender pushes end a),
    /// from the curve of the compression; Coulomb friction along the contact plane, regularized as
    /// mu F v_t / sqrt(|v_t|^2 + v_ref^2).
    Fender {
        curve: Curve,
        normal: Vector3<f64>,
        initial_compression_m: f64,
        friction_coefficient: f64,
        friction_velocity_m_s: f64,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub struct Connection {
    pub name: String,
    pub a: Anchor,
    pub b: Anchor,
    pub kind: ConnectionKind,
}

/// A passive U-tube anti-roll tank (seed paper eqs. 3-4):
///   a_tt tau'' + b_tt tau' + c_tt tau + a_t4 x4'' + c_t4 x4 = 0,
/// and a_t4 tau'' + c_t4 tau added to the left-hand side of the body's roll equation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tank {
    pub body: usize,
    /// kg m^2.
    pub a_tt: f64,
    /// N m s.
    pub b_tt: f64,
    /// N m.
    pub c_tt: f64,
    /// kg m^2.
    pub a_t4: f64,
    /// N m.
    pub c_t4: f64,
}

impl Tank {
    /// Natural frequency of the fluid with the ship held, rad/s.
    pub fn natural_frequency_rad_s(&self) -> f64 {
        (self.c_tt / self.a_tt).sqrt()
    }
}

/// Tank dimensions (Lloyd, "Seakeeping: ship behaviour in rough weather", 1989, ch. 13; the
/// coefficients are re-derived in the module docs of the tests from the fluid's kinetic and potential
/// energy). Q = rho_t b_r x_t w^2 / 2 and
///   a_tt = Q (h_r + b_r w / (2 h_d)),  c_tt = c_t4 = Q g,  a_t4 = Q (r_d + h_r),
///   b_tt = 2 zeta sqrt(a_tt c_tt).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TankGeometry {
    /// w: distance between the reservoirs' centrelines, m.
    pub reservoir_spacing_m: f64,
    /// b_r: athwartships width of each reservoir, m.
    pub reservoir_width_m: f64,
    /// x_t: fore-aft length of the tank, m.
    pub length_m: f64,
    /// h_d: height of the duct, m.
    pub duct_height_m: f64,
    /// h_r: height of the fluid in each reservoir above the duct's centreline, m.
    pub fluid_height_m: f64,
    /// r_d: the duct's centreline below the roll axis (the reference point), m (negative above).
    pub duct_below_roll_axis_m: f64,
    pub fluid_density_kg_m3: f64,
    /// Fluid damping as a fraction of critical.
    pub damping_ratio: f64,
}

impl TankGeometry {
    pub fn coefficients(&self, body: usize, g_m_s2: f64) -> Tank {
        let w = self.reservoir_spacing_m;
        let br = self.reservoir_width_m;
        let q = self.fluid_density_kg_m3 * br * self.length_m * w * w / 2.0;
        let a_tt = q * (self.fluid_height_m + br * w / (2.0 * self.duct_height_m));
        let c_tt = q * g_m_s2;
        Tank {
            body,
            a_tt,
            b_tt: 2.0 * self.damping_ratio * (a_tt * c_tt).sqrt(),
            c_tt,
            a_t4: q * (self.duct_below_roll_axis_m + self.fluid_height_m),
            c_t4: q * g_m_s2,
        }
    }
}

/// A named point on a body whose motion is an output.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    pub name: String,
    pub body: usize,
    /// Body coordinates, m.
    pub point_m: Vector3<f64>,
}

/// Motion of point `a` minus that of point `b` (indices into the points).
#[derive(Debug, Clone, PartialEq)]
pub struct RelativeMotion {
    pub name: String,
    pub a: usize,
    pub b: usize,
}

/// Everything of the system file beyond the bodies and the database.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct External {
    pub connections: Vec<Connection>,
    pub tanks: Vec<Tank>,
    pub tank_names: Vec<String>,
    pub points: Vec<Point>,
    pub relative_motions: Vec<RelativeMotion>,
    /// Global-frame reference point of every body (for the lines' geometry).
    pub body_positions_m: Vec<Vector3<f64>>,
}

/// [r]x: the cross-product matrix, [r]x v = r x v.
fn skew(r: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0)
}

/// Displacement of a point r on a body with motion x (6 values): xi + theta x r.
fn point_of(x: &[f64], r: &Vector3<f64>) -> Vector3<f64> {
    let xi = Vector3::new(x[0], x[1], x[2]);
    let th = Vector3::new(x[3], x[4], x[5]);
    xi + th.cross(r)
}

impl External {
    pub fn has_nonlinear(&self) -> bool {
        self.connections.iter().any(|c| {
            matches!(
                c.kind,
                ConnectionKind::MooringLine { .. } | ConnectionKind::Fender { .. }
            )
        })
    }

    /// Global position at equilibrium of an anchor.
    fn rest_position(&self, a: &Anchor) -> Vector3<f64> {
        match a.body {
            Some(b) => self.body_positions_m[b] + a.point_m,
            None => a.point_m,
        }
    }

    /// Displacement (or velocity) of an anchor from the state vector (6N body modes first).
    fn anchor_motion(&self, a: &Anchor, x: &[f64]) -> Vector3<f64> {
        match a.body {
            Some(b) => point_of(&x[6 * b..6 * b + 6], &a.point_m),
            None => Vector3::zeros(),
        }
    }

    fn anchor_rotation(a: &Anchor, x: &[f64]) -> Vector3<f64> {
        match a.body {
            Some(b) => Vector3::new(x[6 * b + 3], x[6 * b + 4], x[6 * b + 5]),
            None => Vector3::zeros(),
        }
    }

    /// Adds the generalized force of force `f` (and moment `m`) applied at an anchor.
    fn apply(a: &Anchor, f: &Vector3<f64>, m: &Vector3<f64>, out: &mut [f64]) {
        if let Some(b) = a.body {
            let mo = a.point_m.cross(f) + m;
            for k in 0..3 {
                out[6 * b + k] += f[k];
                out[6 * b + 3 + k] += mo[k];
            }
        }
    }

    /// 3 x n_states map from the state to an anchor's displacement.
    fn anchor_jacobian(a: &Anchor, n: usize) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(3, n);
        if let Some(b) = a.body {
            let s = -skew(&a.point_m);
            for r in 0..3 {
                j[(r, 6 * b + r)] = 1.0;
                for c in 0..3 {
                    j[(r, 6 * b + 3 + c)] = s[(r, c)];
                }
            }
        }
        j
    }

    fn anchor_rotation_jacobian(a: &Anchor, n: usize) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(3, n);
        if let Some(b) = a.body {
            for r in 0..3 {
                j[(r, 6 * b + 3 + r)] = 1.0;
            }
        }
        j
    }

    /// Stiffness and damping (n_states x n_states) of the linear connections: spring-dampers and
    /// bushings. Added to C and B_lin by both solvers.
    pub fn linear_matrices(&self, n: usize) -> (DMatrix<f64>, DMatrix<f64>) {
        let mut k = DMatrix::zeros(n, n);
        let mut c = DMatrix::zeros(n, n);
        for conn in &self.connections {
            let g = Self::anchor_jacobian(&conn.a, n) - Self::anchor_jacobian(&conn.b, n);
            match &conn.kind {
                ConnectionKind::SpringDamper {
                    axis,
                    stiffness_n_m,
                    damping_n_s_m,
                    pretension_n,
                } => {
                    let (e, lateral) = match axis {
                        Some(e) => (*e, 0.0),
                        None => {
                            let d = self.rest_position(&conn.b) - self.rest_position(&conn.a);
                            let l = d.norm();
                            (d / l, pretension_n / l)
                        }
                    };
                    let ee = e * e.transpose();
                    let ks = ee * *stiffness_n_m + (Matrix3::identity() - ee) * lateral;
                    let cs = ee * *damping_n_s_m;
                    k += g.transpose() * to_d(&ks) * &g;
                    c += g.transpose() * to_d(&cs) * &g;
                }
                ConnectionKind::Bushing { stiffness, damping } => {
                    let gr = Self::anchor_rotation_jacobian(&conn.a, n) - Self::anchor_rotation_jacobian(&conn.b, n);
                    for (mat, coef) in [(&mut k, stiffness), (&mut c, damping)] {
                        let dt = to_d(&Matrix3::from_diagonal(&Vector3::new(coef[0], coef[1], coef[2])));
                        let dr = to_d(&Matrix3::from_diagonal(&Vector3::new(coef[3], coef[4], coef[5])));
                        *mat += g.transpose() * dt * &g + gr.transpose() * dr * &gr;
                    }
                }
                _ => {}
            }
        }
        (k, c)
    }

    /// Tank terms (n_states x n_states): mass, damping and stiffness couplings with roll.
    pub fn tank_matrices(&self, n_modes: usize) -> [DMatrix<f64>; 3] {
        let n = n_modes + self.tanks.len();
        let (mut m, mut b, mut c) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        for (k, t) in self.tanks.iter().enumerate() {
            let (s, r) = (n_modes + k, 6 * t.body + 3);
            m[(s, s)] = t.a_tt;
            m[(s, r)] = t.a_t4;
            m[(r, s)] = t.a_t4;
            b[(s, s)] = t.b_tt;
            c[(s, s)] = t.c_tt;
            c[(s, r)] = t.c_t4;
            c[(r, s)] = t.c_t4;
        }
        [m, b, c]
    }

    /// Whole generalized force (n_states, added into `out`) of the nonlinear connections (mooring lines,
    /// fenders) at state x, v: not relative to equilibrium.
    pub fn nonlinear_force(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        for conn in &self.connections {
            if let Some((fa, _)) = self.nonlinear_pair(conn, x, v) {
                let z = Vector3::zeros();
                Self::apply(&conn.a, &fa, &z, out);
                Self::apply(&conn.b, &(-fa), &z, out);
            }
        }
    }

    /// Force on end a of a nonlinear connection and its scalar output (tension or normal force).
    fn nonlinear_pair(&self, conn: &Connection, x: &[f64], v: &[f64]) -> Option<(Vector3<f64>, f64)> {
        match &conn.kind {
            ConnectionKind::MooringLine {
                curve,
                unstretched_length_m,
                damping_n_s_m,
            } => {
                let d = self.rest_position(&conn.b) + self.anchor_motion(&conn.b, x)
                    - self.rest_position(&conn.a)
                    - self.anchor_motion(&conn.a, x);
                let l = d.norm();
                if l <= 0.0 || l <= *unstretched_length_m {
                    return Some((Vector3::zeros(), 0.0));
                }
                let u = d / l;
                let ldot = u.dot(&(self.anchor_motion(&conn.b, v) - self.anchor_motion(&conn.a, v)));
                let t = (curve.force(l - unstretched_length_m) + damping_n_s_m * ldot).max(0.0);
                Some((u * t, t))
            }
            ConnectionKind::Fender {
                curve,
                normal,
                initial_compression_m,
                friction_coefficient,
                friction_velocity_m_s,
            } => {
                let rel = self.anchor_motion(&conn.a, x) - self.anchor_motion(&conn.b, x);
                let delta = initial_compression_m - normal.dot(&rel);
                let fnorm = curve.force(delta);
                if fnorm <= 0.0 {
                    return Some((Vector3::zeros(), 0.0));
                }
                let mut f = normal * fnorm;
                if *friction_coefficient > 0.0 {
                    let vr = self.anchor_motion(&conn.a, v) - self.anchor_motion(&conn.b, v);
                    let vt = vr - normal * normal.dot(&vr);
                    let s = (vt.norm_squared() + friction_velocity_m_s * friction_velocity_m_s).sqrt();
                    f -= vt * (friction_coefficient * fnorm / s);
                }
                Some((f, fnorm))
            }
            _ => None,
        }
    }

    /// The scalar output of every connection at a state: axial force of a spring-damper (tension
    /// positive, pretension included), translational force magnitude of a bushing, tension of a line,
    /// normal force of a fender. N.
    pub fn connection_forces(&self, x: &[f64], v: &[f64], out: &mut Vec<f64>) {
        out.clear();
        for conn in &self.connections {
            let f = match &conn.kind {
                ConnectionKind::SpringDamper {
                    axis,
                    stiffness_n_m,
                    damping_n_s_m,
                    pretension_n,
                } => {
                    let e = match axis {
                        Some(e) => *e,
                        None => (self.rest_position(&conn.b) - self.rest_position(&conn.a)).normalize(),
                    };
                    // elongation: b moving away from a along e
                    let dx = e.dot(&(self.anchor_motion(&conn.b, x) - self.anchor_motion(&conn.a, x)));
                    let dv = e.dot(&(self.anchor_motion(&conn.b, v) - self.anchor_motion(&conn.a, v)));
                    pretension_n + stiffness_n_m * dx + damping_n_s_m * dv
                }
                ConnectionKind::Bushing { stiffness, damping } => {
                    let dx = self.anchor_motion(&conn.a, x) - self.anchor_motion(&conn.b, x);
                    let dv = self.anchor_motion(&conn.a, v) - self.anchor_motion(&conn.b, v);
                    Vector3::from_fn(|r, _| stiffness[r] * dx[r] + damping[r] * dv[r]).norm()
                }
                _ => self.nonlinear_pair(conn, x, v).map(|p| p.1).unwrap_or(0.0),
            };
            out.push(f);
        }
    }

    /// Potential energy of the conservative connection forces (springs, bushings' springs, lines,
    /// fenders) at x, relative to the equilibrium's, with the equilibrium force's work removed as in the
    /// equations of motion: U(x) - U(0) - F(0) . x. J.
    pub fn potential_energy(&self, x: &[f64]) -> f64 {
        let n = x.len();
        let xv = nalgebra::DVector::from_column_slice(x);
        let (k, _) = self.linear_matrices(n);
        let mut e = 0.5 * xv.dot(&(&k * &xv));
        let zero = vec![0.0; n];
        for conn in &self.connections {
            let u = |st: &[f64]| -> f64 {
                match &conn.kind {
                    ConnectionKind::MooringLine {
                        curve,
                        unstretched_length_m,
                        ..
                    } => {
                        let d = self.rest_position(&conn.b) + self.anchor_motion(&conn.b, st)
                            - self.rest_position(&conn.a)
                            - self.anchor_motion(&conn.a, st);
                        curve.energy(d.norm() - unstretched_length_m)
                    }
                    ConnectionKind::Fender {
                        curve,
                        normal,
                        initial_compression_m,
                        ..
                    } => {
                        let rel = self.anchor_motion(&conn.a, st) - self.anchor_motion(&conn.b, st);
                        curve.energy(initial_compression_m - normal.dot(&rel))
                    }
                    _ => 0.0,
                }
            };
            e += u(x) - u(&zero);
        }
        let mut f0 = vec![0.0; n];
        self.nonlinear_force(&zero, &zero, &mut f0);
        e + f0.iter().zip(x).map(|(f, xi)| f * xi).sum::<f64>()
    }

    /// Tangent stiffness of the nonlinear connections at equilibrium (central differences), for the
    /// frequency-domain solver: K = -dF/dx.
    pub fn nonlinear_tangent(&self, n: usize) -> DMatrix<f64> {
        let mut k = DMatrix::zeros(n, n);
        if !self.has_nonlinear() {
            return k;
        }
        let zero = vec![0.0; n];
        let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..n {
            let h = 1e-6;
            let mut xp = zero.clone();
            xp[j] = h;
            let mut xm = zero.clone();
            xm[j] = -h;
            fp.iter_mut().for_each(|f| *f = 0.0);
            fm.iter_mut().for_each(|f| *f = 0.0);
            self.nonlinear_force(&xp, &zero, &mut fp);
            self.nonlinear_force(&xm, &zero, &mut fm);
            for i in 0..n {
                k[(i, j)] = -(fp[i] - fm[i]) / (2.0 * h);
            }
        }
        k
    }

    /// Displacement of a point (global axes, m) from the state vector.
    pub fn point_motion(&self, p: &Point, x: &[f64]) -> Vector3<f64> {
        point_of(&x[6 * p.body..6 * p.body + 6], &p.point_m)
    }

    /// The outputs of every point then every relative motion: 3 components each, into `out`.
    pub fn point_outputs(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        for p in &self.points {
            out.extend(self.point_motion(p, x).iter());
        }
        for r in &self.relative_motions {
            let d = self.point_motion(&self.points[r.a], x) - self.point_motion(&self.points[r.b], x);
            out.extend(d.iter());
        }
    }

    /// Names of the point outputs, `name.x|y|z`, in the order of [`Self::point_outputs`].
    pub fn point_output_names(&self) -> Vec<String> {
        self.points
            .iter()
            .map(|p| p.name.as_str())
            .chain(self.relative_motions.iter().map(|r| r.name.as_str()))
            .flat_map(|n| ["x", "y", "z"].map(|c| format!("{n}.{c}")))
            .collect()
    }

    /// Rotation of an anchor's body (for tests of the bushing).
    pub fn relative_rotation(&self, c: &Connection, x: &[f64]) -> Vector3<f64> {
        Self::anchor_rotation(&c.a, x) - Self::anchor_rotation(&c.b, x)
    }
}

fn to_d(m: &Matrix3<f64>) -> DMatrix<f64> {
    DMatrix::from_fn(3, 3, |r, c| m[(r, c)])
}

// ---------------------------------------------------------------------------------------------------
// The system file's sections

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ConnectionFile {
    name: String,
    kind: String,
    body_a: String,
    point_a_m: [f64; 3],
    body_b: String,
    point_b_m: [f64; 3],
    axis: Option<[f64; 3]>,
    stiffness_n_m: Option<f64>,
    damping_n_s_m: Option<f64>,
    pretension_n: Option<f64>,
    /// Bushing: [x, y, z] N/m then [rx, ry, rz] N m/rad.
    stiffness: Option<[f64; 6]>,
    damping: Option<[f64; 6]>,
    /// Lines: [elongation m, tension N]; fenders: [compression m, force N].
    curve: Option<Vec<[f64; 2]>>,
    /// Lines: tension = c1 e + c2 e^2 + ...
    tension_polynomial: Option<Vec<f64>>,
    unstretched_length_m: Option<f64>,
    normal: Option<[f64; 3]>,
    initial_compression_m: Option<f64>,
    friction_coefficient: Option<f64>,
    friction_velocity_m_s: Option<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TankFile {
    name: String,
    body: String,
    a_tt: Option<f64>,
    b_tt: Option<f64>,
    c_tt: Option<f64>,
    a_t4: Option<f64>,
    c_t4: Option<f64>,
    reservoir_spacing_m: Option<f64>,
    reservoir_width_m: Option<f64>,
    length_m: Option<f64>,
    duct_height_m: Option<f64>,
    fluid_height_m: Option<f64>,
    duct_below_roll_axis_m: Option<f64>,
    fluid_density_kg_m3: Option<f64>,
    damping_ratio: Option<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PointFile {
    name: String,
    body: String,
    position_m: [f64; 3],
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RelativeFile {
    name: String,
    point_a: String,
    point_b: String,
}

/// (key, message) of a validation failure.
pub(crate) type KeyErr = (String, String);

fn finite3(v: [f64; 3], key: &str) -> Result<Vector3<f64>, KeyErr> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(Vector3::new(v[0], v[1], v[2]))
    } else {
        Err((key.into(), format!("not finite: {v:?}")))
    }
}

fn nonneg(v: Option<f64>, key: &str) -> Result<f64, KeyErr> {
    let v = v.unwrap_or(0.0);
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err((key.into(), format!("must be a finite number >= 0, found {v}")))
    }
}

fn positive(v: Option<f64>, key: &str) -> Result<f64, KeyErr> {
    match v {
        Some(v) if v.is_finite() && v > 0.0 => Ok(v),
        Some(v) => Err((key.into(), format!("must be a positive number, found {v}"))),
        None => Err((key.into(), "is required".into())),
    }
}

fn unit(v: [f64; 3], key: &str) -> Result<Vector3<f64>, KeyErr> {
    let a = finite3(v, key)?;
    let n = a.norm();
    if n < 1e-9 {
        return Err((key.into(), "must be a non-zero vector".into()));
    }
    Ok(a / n)
}

/// Only the keys a kind uses may appear.
fn only(c: &ConnectionFile, at: &str, allowed: &[&str]) -> Result<(), KeyErr> {
    let present: [(&str, bool); 13] = [
        ("axis", c.axis.is_some()),
        ("stiffness_n_m", c.stiffness_n_m.is_some()),
        ("damping_n_s_m", c.damping_n_s_m.is_some()),
        ("pretension_n", c.pretension_n.is_some()),
        ("stiffness", c.stiffness.is_some()),
        ("damping", c.damping.is_some()),
        ("curve", c.curve.is_some()),
        ("tension_polynomial", c.tension_polynomial.is_some()),
        ("unstretched_length_m", c.unstretched_length_m.is_some()),
        ("normal", c.normal.is_some()),
        ("initial_compression_m", c.initial_compression_m.is_some()),
        ("friction_coefficient", c.friction_coefficient.is_some()),
        ("friction_velocity_m_s", c.friction_velocity_m_s.is_some()),
    ];
    for (k, there) in present {
        if there && !allowed.contains(&k) {
            return Err((
                format!("{at}.{k}"),
                format!(
                    "is not a key of a `{}` connection (its keys: {})",
                    c.kind,
                    allowed.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

pub(crate) fn parse_external(
    connections: &[ConnectionFile],
    tanks: &[TankFile],
    points: &[PointFile],
    relatives: &[RelativeFile],
    body_names: &[String],
    body_positions_m: Vec<Vector3<f64>>,
    g_m_s2: f64,
) -> Result<External, KeyErr> {
    let body_of = |name: &str, key: &str, earth: bool| body_of(body_names, name, key, earth);
    let mut out = External {
        body_positions_m,
        ..External::default()
    };
    for (k, c) in connections.iter().enumerate() {
        let at = format!("connection[{k}]");
        let names: Vec<&str> = out.connections.iter().map(|c| c.name.as_str()).collect();
        unique(&names, &c.name, &format!("{at}.name"))?;
        let a = Anchor {
            body: body_of(&c.body_a, &format!("{at}.body_a"), true)?,
            point_m: finite3(c.point_a_m, &format!("{at}.point_a_m"))?,
        };
        let b = Anchor {
            body: body_of(&c.body_b, &format!("{at}.body_b"), true)?,
            point_m: finite3(c.point_b_m, &format!("{at}.point_b_m"))?,
        };
        if a.body.is_none() && b.body.is_none() {
            return Err((format!("{at}.body_a"), "a connection needs at least one body".into()));
        }
        if a.body.is_some() && a.body == b.body {
            return Err((format!("{at}.body_b"), "connects a body to itself".into()));
        }
        let kind = connection_kind(&out, c, &at, &a, &b)?;
        out.connections.push(Connection {
            name: c.name.clone(),
            a,
            b,
            kind,
        });
    }
    for (k, t) in tanks.iter().enumerate() {
        let at = format!("tank[{k}]");
        let names: Vec<&str> = out.tank_names.iter().map(|s| s.as_str()).collect();
        unique(&names, &t.name, &format!("{at}.name"))?;
        let Some(body) = body_of(&t.body, &format!("{at}.body"), false)? else {
            return Err((format!("{at}.body"), "a tank sits on a body".into()));
        };
        out.tanks.push(tank(t, &at, body, g_m_s2)?);
        out.tank_names.push(t.name.clone());
    }
    for (k, p) in points.iter().enumerate() {
        let at = format!("point[{k}]");
        let names: Vec<&str> = out.points.iter().map(|p| p.name.as_str()).collect();
        unique(&names, &p.name, &format!("{at}.name"))?;
        let Some(body) = body_of(&p.body, &format!("{at}.body"), false)? else {
            return Err((format!("{at}.body"), "a point sits on a body".into()));
        };
        out.points.push(Point {
            name: p.name.clone(),
            body,
            point_m: finite3(p.position_m, &format!("{at}.position_m"))?,
        });
    }
    for (k, r) in relatives.iter().enumerate() {
        let at = format!("relative_motion[{k}]");
        let mut names: Vec<&str> = out.points.iter().map(|p| p.name.as_str()).collect();
        names.extend(out.relative_motions.iter().map(|r| r.name.as_str()));
        unique(&names, &r.name, &format!("{at}.name"))?;
        let find = |name: &str, key: &str| -> Result<usize, KeyErr> {
            out.points
                .iter()
                .position(|p| p.name == name)
                .ok_or_else(|| (format!("{at}.{key}"), format!("names no [[point]]: `{name}`")))
        };
        let (a, b) = (find(&r.point_a, "point_a")?, find(&r.point_b, "point_b")?);
        out.relative_motions.push(RelativeMotion {
            name: r.name.clone(),
            a,
            b,
        });
    }
    Ok(out)
}

/// The body `name` (a key's value) names: its index, or None for `earth` where `earth` is allowed.
fn body_of(body_names: &[String], name: &str, key: &str, earth: bool) -> Result<Option<usize>, KeyErr> {
    if earth && name == "earth" {
        return Ok(None);
    }
    body_names.iter().position(|b| b == name).map(Some).ok_or_else(|| {
        (
            key.into(),
            format!(
                "names no body: `{name}` (bodies: {}{})",
                body_names.join(", "),
                if earth { ", or \"earth\"" } else { "" }
            ),
        )
    })
}

/// A new name: not empty, not among `names`.
fn unique(names: &[&str], name: &str, key: &str) -> Result<(), KeyErr> {
    if name.trim().is_empty() {
        return Err((key.into(), "must not be empty".into()));
    }
    if names.contains(&name) {
        return Err((key.into(), format!("`{name}` is used twice")));
    }
    Ok(())
}

/// Connection `at`'s model from its `kind` and the keys that kind takes (anchors `a`, `b`).
fn connection_kind(
    out: &External,
    c: &ConnectionFile,
    at: &str,
    a: &Anchor,
    b: &Anchor,
) -> Result<ConnectionKind, KeyErr> {
    let kind = match c.kind.as_str() {
        "spring_damper" => {
            only(c, at, &["axis", "stiffness_n_m", "damping_n_s_m", "pretension_n"])?;
            let axis = c.axis.map(|v| unit(v, &format!("{at}.axis"))).transpose()?;
            if axis.is_none() {
                let d = out.rest_position(b) - out.rest_position(a);
                if d.norm() < 1e-6 {
                    return Err((
                        format!("{at}.axis"),
                        "the two points coincide: give the spring's axis".into(),
                    ));
                }
            }
            ConnectionKind::SpringDamper {
                axis,
                stiffness_n_m: nonneg(c.stiffness_n_m, &format!("{at}.stiffness_n_m"))?,
                damping_n_s_m: nonneg(c.damping_n_s_m, &format!("{at}.damping_n_s_m"))?,
                pretension_n: nonneg(c.pretension_n, &format!("{at}.pretension_n"))?,
            }
        }
        "bushing" => bushing(c, at)?,
        "mooring_line" => {
            only(
                c,
                at,
                &["curve", "tension_polynomial", "unstretched_length_m", "damping_n_s_m"],
            )?;
            let l0 = positive(c.unstretched_length_m, &format!("{at}.unstretched_length_m"))?;
            ConnectionKind::MooringLine {
                curve: curve(c, at, l0)?,
                unstretched_length_m: l0,
                damping_n_s_m: nonneg(c.damping_n_s_m, &format!("{at}.damping_n_s_m"))?,
            }
        }
        "fender" => fender(c, at)?,
        other => {
            return Err((
                format!("{at}.kind"),
                format!("unknown kind `{other}` (spring_damper, bushing, mooring_line, fender)"),
            ));
        }
    };
    Ok(kind)
}

/// A line's or fender's force curve (`curve` table or `tension_polynomial`), valid over `range`.
fn curve(c: &ConnectionFile, at: &str, range: f64) -> Result<Curve, KeyErr> {
    let cv = match (&c.curve, &c.tension_polynomial) {
        (Some(t), None) => Curve::Table(t.iter().map(|p| (p[0], p[1])).collect()),
        (None, Some(p)) => Curve::Polynomial(p.clone()),
        (Some(_), Some(_)) => {
            return Err((
                format!("{at}.curve"),
                "give `curve` or `tension_polynomial`, not both".into(),
            ));
        }
        (None, None) => return Err((format!("{at}.curve"), "is required".into())),
    };
    cv.validate(range).map_err(|m| (format!("{at}.curve"), m))?;
    Ok(cv)
}

/// A bushing's six stiffnesses and dampings (each finite and >= 0; default 0).
fn bushing(c: &ConnectionFile, at: &str) -> Result<ConnectionKind, KeyErr> {
    only(c, at, &["stiffness", "damping"])?;
    let six = |v: Option<[f64; 6]>, key: &str| -> Result<[f64; 6], KeyErr> {
        let v = v.unwrap_or([0.0; 6]);
        for (i, x) in v.iter().enumerate() {
            if !(x.is_finite() && *x >= 0.0) {
                return Err((
                    format!("{at}.{key}[{i}]"),
                    format!("must be finite and >= 0, found {x}"),
                ));
            }
        }
        Ok(v)
    };
    Ok(ConnectionKind::Bushing {
        stiffness: six(c.stiffness, "stiffness")?,
        damping: six(c.damping, "damping")?,
    })
}

/// A fender: its curve, normal, initial compression and friction.
fn fender(c: &ConnectionFile, at: &str) -> Result<ConnectionKind, KeyErr> {
    only(
        c,
        at,
        &[
            "curve",
            "normal",
            "initial_compression_m",
            "friction_coefficient",
            "friction_velocity_m_s",
        ],
    )?;
    if c.tension_polynomial.is_some() {
        return Err((
            format!("{at}.tension_polynomial"),
            "fenders take a `curve` table".into(),
        ));
    }
    let normal = match c.normal {
        Some(v) => unit(v, &format!("{at}.normal"))?,
        None => return Err((format!("{at}.normal"), "is required".into())),
    };
    let mu = nonneg(c.friction_coefficient, &format!("{at}.friction_coefficient"))?;
    let vref = match c.friction_velocity_m_s {
        None => 0.01,
        v => positive(v, &format!("{at}.friction_velocity_m_s"))?,
    };
    Ok(ConnectionKind::Fender {
        curve: curve(c, at, 1.0)?,
        normal,
        initial_compression_m: nonneg(c.initial_compression_m, &format!("{at}.initial_compression_m"))?,
        friction_coefficient: mu,
        friction_velocity_m_s: vref,
    })
}

/// Tank `at` on `body`: from its coefficients or from its geometry (Lloyd's U-tube), not both.
fn tank(t: &TankFile, at: &str, body: usize, g_m_s2: f64) -> Result<Tank, KeyErr> {
    let direct = [t.a_tt, t.b_tt, t.c_tt, t.a_t4, t.c_t4].iter().any(Option::is_some);
    let geometric = [
        t.reservoir_spacing_m,
        t.reservoir_width_m,
        t.length_m,
        t.duct_height_m,
        t.fluid_height_m,
        t.duct_below_roll_axis_m,
        t.fluid_density_kg_m3,
        t.damping_ratio,
    ]
    .iter()
    .any(Option::is_some);
    let tank = match (direct, geometric) {
        (true, false) => {
            let a_t4 = t.a_t4.unwrap_or(f64::NAN);
            if !a_t4.is_finite() {
                return Err((format!("{at}.a_t4"), "is required (kg m^2, finite)".into()));
            }
            Tank {
                body,
                a_tt: positive(t.a_tt, &format!("{at}.a_tt"))?,
                b_tt: nonneg(t.b_tt, &format!("{at}.b_tt"))?,
                c_tt: positive(t.c_tt, &format!("{at}.c_tt"))?,
                a_t4,
                c_t4: positive(t.c_t4, &format!("{at}.c_t4"))?,
            }
        }
        (false, true) => {
            let r_d = t.duct_below_roll_axis_m.unwrap_or(f64::NAN);
            if !r_d.is_finite() {
                return Err((
                    format!("{at}.duct_below_roll_axis_m"),
                    "is required (m, negative when the duct is above the roll axis)".into(),
                ));
            }
            let zeta = nonneg(t.damping_ratio, &format!("{at}.damping_ratio"))?;
            TankGeometry {
                reservoir_spacing_m: positive(t.reservoir_spacing_m, &format!("{at}.reservoir_spacing_m"))?,
                reservoir_width_m: positive(t.reservoir_width_m, &format!("{at}.reservoir_width_m"))?,
                length_m: positive(t.length_m, &format!("{at}.length_m"))?,
                duct_height_m: positive(t.duct_height_m, &format!("{at}.duct_height_m"))?,
                fluid_height_m: positive(t.fluid_height_m, &format!("{at}.fluid_height_m"))?,
                duct_below_roll_axis_m: r_d,
                fluid_density_kg_m3: positive(
                    t.fluid_density_kg_m3.or(Some(1025.0)),
                    &format!("{at}.fluid_density_kg_m3"),
                )?,
                damping_ratio: zeta,
            }
            .coefficients(body, g_m_s2)
        }
        (true, true) => {
            return Err((
                at.to_string(),
                "give the coefficients (a_tt, b_tt, c_tt, a_t4, c_t4) or the geometry, not both".into(),
            ));
        }
        (false, false) => {
            return Err((
                at.to_string(),
                "needs its coefficients (a_tt, b_tt, c_tt, a_t4, c_t4) or its geometry (reservoir_spacing_m, ...)"
                    .into(),
            ));
        }
    };
    Ok(tank)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> Curve {
        Curve::Table(vec![(0.5, 1.0e5), (1.0, 3.0e5), (1.5, 8.0e5)])
    }

    #[test]
    fn curve_force_and_energy() {
        let c = table();
        assert_eq!(c.force(-0.1), 0.0);
        assert!((c.force(0.25) - 0.5e5).abs() < 1e-6);
        assert!((c.force(0.75) - 2.0e5).abs() < 1e-6);
        assert!((c.force(2.0) - 13.0e5).abs() < 1e-6, "last slope beyond the table");
        // energy is the integral of the force
        let e = 1.7;
        let steps = 20000;
        let num: f64 = (0..steps)
            .map(|k| c.force((k as f64 + 0.5) * e / steps as f64) * e / steps as f64)
            .sum();
        assert!((c.energy(e) - num).abs() < 1e-6 * num, "{} vs {num}", c.energy(e));
        let p = Curve::Polynomial(vec![1.0e5, 2.0e4]);
        assert!((p.force(2.0) - (2.0e5 + 8.0e4)).abs() < 1e-6);
        assert!((p.energy(2.0) - (1.0e5 * 2.0 + 2.0e4 * 8.0 / 3.0)).abs() < 1e-6);
    }

    #[test]
    fn curves_that_are_not_monotonic_are_refused() {
        let bad = Curve::Table(vec![(0.5, 2.0e5), (1.0, 1.0e5)]);
        assert!(bad.validate(1.0).unwrap_err().contains("not monotonic"));
        let bad = Curve::Polynomial(vec![1.0e5, -1.0e6]);
        assert!(bad.validate(1.0).unwrap_err().contains("not monotonic"));
        assert!(table().validate(1.0).is_ok());
    }

    #[test]
    fn tank_from_geometry_has_the_u_tube_frequency() {
        // uniform section (duct as high as a reservoir is wide): w^2 = 2 g / (w + 2 h_r)
        let g = TankGeometry {
            reservoir_spacing_m: 10.0,
            reservoir_width_m: 2.0,
            length_m: 4.0,
            duct_height_m: 2.0,
            fluid_height_m: 3.0,
            duct_below_roll_axis_m: 1.0,
            fluid_density_kg_m3: 1000.0,
            damping_ratio: 0.1,
        };
        let t = g.coefficients(0, 9.81);
        let expected = (2.0f64 * 9.81 / (10.0 + 2.0 * 3.0)).sqrt();
        assert!((t.natural_frequency_rad_s() - expected).abs() < 1e-12);
        // free-surface effect: Q g = rho g b_r x_t w^2 / 2
        assert!((t.c_t4 - 1000.0 * 9.81 * 2.0 * 4.0 * 100.0 / 2.0).abs() < 1e-6);
        assert!((t.b_tt - 0.2 * (t.a_tt * t.c_tt).sqrt()).abs() < 1e-6);
    }

    fn two_bodies() -> External {
        let conns = vec![
            Connection {
                name: "line".into(),
                a: Anchor {
                    body: Some(0),
                    point_m: Vector3::new(40.0, 10.0, 3.0),
                },
                b: Anchor {
                    body: Some(1),
                    point_m: Vector3::new(30.0, -8.0, 3.0),
                },
                kind: ConnectionKind::MooringLine {
                    curve: Curve::Polynomial(vec![1.0e6, 5.0e5]),
                    unstretched_length_m: 19.5,
                    damping_n_s_m: 1.0e4,
                },
            },
            Connection {
                name: "fender".into(),
                a: Anchor {
                    body: Some(0),
                    point_m: Vector3::new(0.0, 12.0, 0.0),
                },
                b: Anchor {
                    body: Some(1),
                    point_m: Vector3::new(0.0, -8.0, 0.0),
                },
                kind: ConnectionKind::Fender {
                    curve: Curve::Table(vec![(0.3, 2.0e5), (1.0, 1.5e6)]),
                    normal: Vector3::new(0.0, -1.0, 0.0),
                    initial_compression_m: 0.2,
                    friction_coefficient: 0.0,
                    friction_velocity_m_s: 0.01,
                },
            },
        ];
        External {
            connections: conns,
            body_positions_m: vec![Vector3::zeros(), Vector3::new(0.0, 30.0, 0.0)],
            ..External::default()
        }
    }

    fn small_state() -> impl proptest::strategy::Strategy<Value = Vec<f64>> {
        use proptest::prelude::*;
        proptest::collection::vec(-1.0f64..1.0, 12).prop_map(|v| {
            v.iter()
                .enumerate()
                .map(|(i, x)| if i % 6 >= 3 { 0.02 * x } else { 2.0 * x })
                .collect()
        })
    }

    proptest::proptest! {
        #[test]
        fn a_slack_line_carries_nothing_and_a_fender_never_pulls(x in small_state(), v in small_state()) {
            let e = two_bodies();
            let mut f = vec![];
            e.connection_forces(&x, &v, &mut f);
            proptest::prop_assert!(f[0] >= 0.0 && f[1] >= 0.0);
            // line: zero when its length is below the unstretched length
            let ConnectionKind::MooringLine { unstretched_length_m, .. } = &e.connections[0].kind else { unreachable!() };
            let pa = e.rest_position(&e.connections[0].a) + e.anchor_motion(&e.connections[0].a, &x);
            let pb = e.rest_position(&e.connections[0].b) + e.anchor_motion(&e.connections[0].b, &x);
            if (pb - pa).norm() <= *unstretched_length_m {
                proptest::prop_assert_eq!(f[0], 0.0);
            }
            // fender: the force on the carrier along the normal is a push (never toward the lighter)
            let mut q = vec![0.0; 12];
            e.nonlinear_force(&x, &v, &mut q);
            let only_fender = External { connections: vec![e.connections[1].clone()], ..e.clone() };
            let mut qf = vec![0.0; 12];
            only_fender.nonlinear_force(&x, &v, &mut qf);
            proptest::prop_assert!(qf[1] <= 0.0, "fender pulls the carrier toward the lighter: {}", qf[1]);
            proptest::prop_assert!(qf[7] >= 0.0);
        }

        #[test]
        fn connection_forces_are_minus_the_gradient_of_their_energy(x in small_state()) {
            let e = two_bodies();
            let zero = vec![0.0; 12];
            let mut f = vec![0.0; 12];
            e.nonlinear_force(&x, &zero, &mut f);
            let mut f0 = vec![0.0; 12];
            e.nonlinear_force(&zero, &zero, &mut f0);
            for j in 0..12 {
                let h = if j % 6 >= 3 { 1e-7 } else { 1e-5 };
                let mut xp = x.clone();
                xp[j] += h;
                let mut xm = x.clone();
                xm[j] -= h;
                let grad = (e.potential_energy(&xp) - e.potential_energy(&xm)) / (2.0 * h);
                // potential_energy removes the equilibrium force: F - F0 = -grad
                let force = f[j] - f0[j];
                let scale = f.iter().chain(&f0).fold(1.0f64, |m, v| m.max(v.abs())) * if j % 6 >= 3 { 50.0 } else { 1.0 };
                proptest::prop_assert!((force + grad).abs() <= 1e-5 * scale, "mode {j}: force {force}, -grad {}", -grad);
            }
        }
    }
}
