//! The engine's inputs: each sample judged by its source's clock, then by its estimator or track;
//! what is refused is counted and logged, never taken.

use super::estimator::{Refusal, Taken};
use super::message::{Input, LinkStatus, MotionSample, NavigationSample, SCHEMA_VERSION, Scan, flags};
use super::*;
use crate::waves::window::{MIN_WINDOW_SCANS, regrid, window_scans};

impl Engine {
    /// One input that arrived at `clock_s` (engine clock). Every stamp is judged against its source's
    /// clock first ([`clock`]): refused samples never reach the history.
    pub fn input(&mut self, msg: Input, clock_s: f64) {
        match msg {
            Input::Motion(m) => self.motion(m, clock_s),
            Input::Navigation(n) => self.navigation(n, clock_s),
            Input::Elevation(scan) => self.elevation(*scan, clock_s),
            Input::Waves(f) => self.waves(f, clock_s),
            Input::Link(l) => self.link_status(l, clock_s),
            Input::Rejected(why) => {
                self.counters.rejected += 1;
                tracing::warn!("input rejected: {why}");
            }
        }
    }

    /// A motion sample: judged by its vessel's clock, then by its estimator.
    fn motion(&mut self, m: MotionSample, clock_s: f64) {
        let rules = self.clock_rules;
        let c = &mut self.counters;
        c.samples += 1;
        let sample = (m.schema_version, m.vessel, m.time_s);
        let Some((b, stepped)) = vessel_sample(c, &mut self.motion_clock, "motion sample", sample, clock_s, &rules)
        else {
            return;
        };
        if stepped {
            self.state_flags |= flags::CLOCK_STEP;
            self.hist[b].restart();
        }
        match self.hist[b].push(m.time_s, m.x, m.v) {
            Ok(taken) => {
                self.arrival[b] = Some(clock_s);
                match taken {
                    Taken::Restarted => {
                        c.motion_restarts += 1;
                        self.state_flags |= flags::MOTION_RESTARTED;
                        tracing::warn!(
                            vessel = b,
                            "motion samples that agree with each other but not with the estimate: a real jump, the estimate restarts from them (trusted nowhere until its new offset is averaged)"
                        );
                    }
                    Taken::Reverted => {
                        c.implausible += 1;
                        self.state_flags |= flags::MOTION_IMPLAUSIBLE;
                        tracing::warn!(
                            vessel = b,
                            "the motion is back where it was before the last restart: the run it restarted from was a burst of spikes, dropped"
                        );
                    }
                    Taken::Accepted => {}
                }
            }
            Err(Refusal::NonFinite) => {
                c.nonfinite += 1;
                log_count(
                    c.nonfinite,
                    &format!("vessel {b}: motion sample with a non-finite value refused"),
                );
            }
            Err(Refusal::Late) => {
                c.late += 1;
                log_count(
                    c.late,
                    &format!("vessel {b}: motion sample older than the newest refused"),
                );
            }
            Err(Refusal::Duplicate) => c.duplicate += 1,
            Err(why) => {
                c.implausible += 1;
                self.state_flags |= flags::MOTION_IMPLAUSIBLE;
                log_count(
                    c.implausible,
                    &format!(
                        "vessel {b}: motion sample refused as physically impossible: {}",
                        refusal_text(&why)
                    ),
                );
            }
        }
    }

    /// A navigation fix: judged by its vessel's navigation clock, then by its track.
    fn navigation(&mut self, n: NavigationSample, clock_s: f64) {
        let rules = self.clock_rules;
        let c = &mut self.counters;
        c.navigation += 1;
        let sample = (n.schema_version, n.vessel, n.time_s);
        let Some((b, stepped)) = vessel_sample(c, &mut self.nav_clock, "navigation fix", sample, clock_s, &rules)
        else {
            return;
        };
        if stepped {
            self.state_flags |= flags::CLOCK_STEP;
            self.nav[b].restart();
        }
        match self.nav[b].push(&n, self.cfg.navigation_window_s) {
            Ok(()) => {}
            Err(navigation::NavRefusal::NonFinite) => {
                c.nonfinite += 1;
                log_count(
                    c.nonfinite,
                    &format!("vessel {b}: navigation fix with a non-finite value refused"),
                );
            }
            Err(navigation::NavRefusal::Late) => {
                c.late += 1;
                log_count(
                    c.late,
                    &format!("vessel {b}: navigation fix not newer than the newest refused"),
                );
            }
            Err(navigation::NavRefusal::Implausible(what)) => {
                c.rejected += 1;
                log_count(
                    c.rejected,
                    &format!("vessel {b}: navigation fix refused: its {what} is beyond what a ship does"),
                );
            }
        }
    }

    /// A radar scan: judged by the radar's clock; a full sequence of scans of one grid is inverted into
    /// the field.
    fn elevation(&mut self, scan: Scan, clock_s: f64) {
        let rules = self.clock_rules;
        let c = &mut self.counters;
        c.wave_fields += 1;
        let Some(stepped) = judge(&mut self.wave_clock, c, "radar scan", scan.grid.time_s, clock_s, &rules) else {
            return;
        };
        if stepped {
            self.state_flags |= flags::CLOCK_STEP;
            self.scans.clear();
            self.radar_fit = None;
        }
        // a sequence shares one grid at increasing times: another grid of the same lattice (a map
        // re-centred on the ship by whole cells) takes the earlier scans moved onto it; any other
        // starts it again
        let continues = self.scans.back().map(|last| {
            last.frame == scan.frame
                && last.grid.x_m == scan.grid.x_m
                && last.grid.y_m == scan.grid.y_m
                && last.grid.time_s < scan.grid.time_s
        });
        // the same values bit for bit (a scan's invalid cells are NaN)
        let repeat = continues == Some(true)
            && self.scans.back().is_some_and(|last| {
                last.grid.values.len() == scan.grid.values.len()
                    && last
                        .grid
                        .values
                        .iter()
                        .zip(&scan.grid.values)
                        .all(|(a, b)| a.to_bits() == b.to_bits())
            });
        if !stepped && self.refuse_frozen(repeat, "radar scan") {
            return;
        }
        if continues == Some(false) {
            self.move_scans_onto(&scan);
        }
        self.scans.push_back(scan);
        self.waves_frozen = false;
        let most = self.cfg.radar_snapshots as usize;
        while self.scans.len() > most {
            self.scans.pop_front();
        }
        if self.scans.len() < MIN_WINDOW_SCANS.min(most) {
            return;
        }
        // the newest scans of the window the last field asked for (all there are while it fills)
        let used = self.radar_window.clamp(1, most).min(self.scans.len());
        let grids: Vec<crate::waves::observe::Grid> = self
            .scans
            .iter()
            .skip(self.scans.len() - used)
            .map(|s| s.grid.clone())
            .collect();
        let frame = self
            .scans
            .back()
            .map(|s| s.frame)
            .unwrap_or(crate::waves::observe::GridFrame {
                origin_m: [0.0, 0.0],
                orientation_rad: 0.0,
            });
        match crate::waves::observe::from_scans_after(&grids, frame, &self.radar_options, self.radar_fit.as_ref()) {
            Ok((f, fit)) => {
                self.radar_fit = Some(fit);
                if !stepped && self.refuse_implausible(&f, "radar scans' field") {
                    return;
                }
                let f = f.pruned(self.cfg.wave_variance_kept);
                let period_s = (f.time_s - grids[0].time_s) / (used - 1).max(1) as f64;
                self.radar_window = window_scans(&f, period_s, most);
                if stepped || self.field.as_ref().is_none_or(|old| f.time_s > old.time_s) {
                    self.take_field(f);
                }
            }
            Err(e) => {
                self.counters.rejected += 1;
                log_count(self.counters.rejected, &format!("radar scans not inverted: {e}"));
            }
        }
    }

    /// The kept scans moved onto `scan`'s grid (`waves::window::regrid`) when it is a later one of
    /// their lattice; otherwise none are kept.
    fn move_scans_onto(&mut self, scan: &Scan) {
        let later = self
            .scans
            .back()
            .is_some_and(|last| last.grid.time_s < scan.grid.time_s);
        let moved: Option<Vec<Scan>> = later
            .then(|| {
                self.scans
                    .iter()
                    .map(|s| {
                        regrid(&s.grid, s.frame, &scan.grid.x_m, &scan.grid.y_m, scan.frame).map(|grid| Scan {
                            grid,
                            frame: scan.frame,
                        })
                    })
                    .collect()
            })
            .flatten();
        self.scans = moved.unwrap_or_default().into();
    }

    /// A wave field: its size checked, then judged by the radar's clock.
    fn waves(&mut self, f: WaveField, clock_s: f64) {
        let rules = self.clock_rules;
        let c = &mut self.counters;
        c.wave_fields += 1;
        if let Err(why) = message::check_wave_components(f.components.len()) {
            c.rejected += 1;
            log_count(c.rejected, &format!("{why}: refused"));
            return;
        }
        let Some(stepped) = judge(&mut self.wave_clock, c, "wave field", f.time_s, clock_s, &rules) else {
            return;
        };
        if stepped {
            self.state_flags |= flags::CLOCK_STEP;
        }
        if !stepped && self.refuse_implausible(&f, "wave field") {
            return;
        }
        let f = f.pruned(self.cfg.wave_variance_kept);
        let repeat = self
            .field
            .as_ref()
            .is_some_and(|old| f.time_s > old.time_s && !f.components.is_empty() && f.components == old.components);
        if !stepped && self.refuse_frozen(repeat, "wave field") {
            return;
        }
        if stepped || self.field.as_ref().is_none_or(|old| f.time_s > old.time_s) {
            self.take_field(f);
        }
    }

    /// The newest field, taken: its variance joins the recent ones the next is judged against.
    fn take_field(&mut self, f: WaveField) {
        self.recent_variance_m2.push_back(f.variance_m2());
        while self.recent_variance_m2.len() > RECENT_FIELDS {
            self.recent_variance_m2.pop_front();
        }
        self.field = Some(f);
        self.waves_frozen = false;
    }

    /// A field that is not a sea ([`implausible`]: more than the highest seas, a component steeper
    /// than a wave can be, a jump the sea does not make between fields seconds apart) is refused
    /// (counted, logged) and `waves_implausible` raised until the next status; the forecasts keep the
    /// last field taken. True when refused.
    fn refuse_implausible(&mut self, f: &WaveField, what: &str) -> bool {
        let Some(why) = implausible(f, &self.recent_variance_m2) else {
            return false;
        };
        self.state_flags |= flags::WAVES_IMPLAUSIBLE;
        let c = &mut self.counters;
        c.rejected += 1;
        log_count(c.rejected, &format!("{what} refused as not a sea: {why}"));
        true
    }

    /// A wave field (not an empty one) or radar scan that repeats the one before it, value for value,
    /// at a later stamp (`repeat`) is a processor that froze: the sea it describes would have moved on. It is refused
    /// (counted, logged) and `waves_frozen` raised, so that the field the forecasts take ages as it
    /// should; the next one that differs clears it. True when refused.
    fn refuse_frozen(&mut self, repeat: bool, what: &str) -> bool {
        if repeat {
            self.waves_frozen = true;
            let c = &mut self.counters;
            c.rejected += 1;
            log_count(
                c.rejected,
                &format!("{what} refused: the same values as the one before, stamped later (a frozen processor)"),
            );
        }
        repeat
    }

    /// The ship-to-ship link's health.
    fn link_status(&mut self, l: LinkStatus, clock_s: f64) {
        let c = &mut self.counters;
        if l.schema_version == message::LINK_SCHEMA_VERSION {
            self.link = Some((l, clock_s));
        } else {
            c.rejected += 1;
            log_count(
                c.rejected,
                &format!("link status of schema version {}: refused", l.schema_version),
            );
        }
    }
}

/// The largest significant wave height a field may claim, m: above the highest seas measured (about
/// 20 m), so a field that claims more is its processor's error.
pub const MAX_FIELD_HS_M: f64 = 25.0;
/// The steepest a component may be, k |a|: Stokes' limiting wave (H / L = 1/7, k a = pi / 7).
pub const MAX_STEEPNESS: f64 = std::f64::consts::PI / 7.0;
/// A field's variance may be at most this many times the median of the last [`RECENT_FIELDS`] taken
/// (its significant wave height four times theirs: no sea builds so fast between fields seconds
/// apart) ...
pub const MAX_VARIANCE_JUMP: f64 = 16.0;
/// ... once that many have been taken ...
pub const RECENT_FIELDS: usize = 8;
/// ... where it claims a significant wave height above this, m (a sea building from calm is no jump).
pub const JUMP_FLOOR_HS_M: f64 = 1.0;

/// Why a field is not a sea, judged against the variances of the last fields taken (m^2); None when
/// it may be one.
pub fn implausible(f: &WaveField, recent_variance_m2: &std::collections::VecDeque<f64>) -> Option<String> {
    let var = f.variance_m2();
    let hs = 4.0 * var.sqrt();
    if hs.is_nan() || hs > MAX_FIELD_HS_M {
        return Some(format!(
            "it claims a significant wave height of {hs:.1} m (at most {MAX_FIELD_HS_M} m)"
        ));
    }
    if let Some(c) = f
        .components
        .iter()
        .find(|c| f.wave_number(c.omega_rad_s) * c.amplitude_m.norm() > MAX_STEEPNESS)
    {
        return Some(format!(
            "a component of {:.2} m at {:.3} rad/s is steeper than a wave can be",
            c.amplitude_m.norm(),
            c.omega_rad_s
        ));
    }
    if recent_variance_m2.len() >= RECENT_FIELDS && hs > JUMP_FLOOR_HS_M {
        let mut v: Vec<f64> = recent_variance_m2.iter().copied().collect();
        v.sort_by(f64::total_cmp);
        let median = v[v.len() / 2];
        if var > MAX_VARIANCE_JUMP * median {
            return Some(format!(
                "its variance, {var:.3} m^2, is {:.0} times the last fields' ({median:.3} m^2)",
                var / median
            ));
        }
    }
    None
}

/// A stamp judged by its source's clock, counted and logged: None if refused, else whether the source's
/// clock stepped (and re-synchronized) with it.
fn judge(
    source: &mut clock::SourceClock,
    c: &mut Counters,
    what: &str,
    stamp_s: f64,
    clock_s: f64,
    rules: &clock::ClockRules,
) -> Option<bool> {
    match source.judge(stamp_s, clock_s, rules) {
        clock::Stamp::Accepted => Some(false),
        clock::Stamp::Stepped { step_s } => {
            c.clock_steps += 1;
            tracing::warn!(
                step_s,
                "{what}: the source's clock stepped: re-synchronized, its history restarts"
            );
            Some(true)
        }
        clock::Stamp::NonFinite => {
            c.nonfinite += 1;
            log_count(c.nonfinite, &format!("{what} with a non-finite stamp refused"));
            None
        }
        clock::Stamp::Future { ahead_s } => {
            c.future += 1;
            log_count(
                c.future,
                &format!("{what} stamped {ahead_s:.3} s ahead of its clock refused"),
            );
            None
        }
        clock::Stamp::Past { behind_s } => {
            c.past += 1;
            log_count(
                c.past,
                &format!("{what} stamped {behind_s:.3} s behind its clock refused"),
            );
            None
        }
    }
}

/// A vessel's sample (`what`: a motion sample, a navigation fix) of (schema version, vessel index,
/// stamp): the schema and the index checked against `clocks` (one per vessel), the stamp judged by
/// the vessel's clock of that kind. None: refused (counted, logged); else the vessel and whether its
/// clock stepped.
fn vessel_sample(
    c: &mut Counters,
    clocks: &mut [clock::SourceClock],
    what: &str,
    (schema_version, vessel, stamp_s): (u32, u32, f64),
    clock_s: f64,
    rules: &clock::ClockRules,
) -> Option<(usize, bool)> {
    let b = vessel as usize;
    if schema_version != SCHEMA_VERSION || b >= clocks.len() {
        c.rejected += 1;
        log_count(
            c.rejected,
            &format!(
                "{what} refused: schema version {schema_version} (this daemon reads {SCHEMA_VERSION}), vessel {vessel} of {}",
                clocks.len()
            ),
        );
        return None;
    }
    judge(
        &mut clocks[b],
        c,
        &format!("vessel {b}: {what}"),
        stamp_s,
        clock_s,
        rules,
    )
    .map(|stepped| (b, stepped))
}

/// A refusal in words, with the DOF's name and units.
fn refusal_text(why: &Refusal) -> String {
    let name = |d: usize| crate::hydro::Dof::of_index(d).output_name();
    let show = |d: usize, v: f64| crate::hydro::Dof::of_index(d).to_output(v);
    match *why {
        Refusal::InRun => "nearer a run of refused samples than the estimate (a jump, if they go on)".into(),
        Refusal::Bound {
            dof,
            what,
            value,
            bound,
        } => {
            format!(
                "{} {what} {:.4e} beyond +-{:.4e}",
                name(dof),
                show(dof, value),
                show(dof, bound)
            )
        }
        Refusal::Jump {
            dof,
            what,
            change,
            allowed,
        } => format!(
            "{} {what} changed by {:.4e} since the estimate, at most {:.4e} possible",
            name(dof),
            show(dof, change),
            show(dof, allowed)
        ),
        Refusal::Frozen => "the same values as the sample before while the vessel moves (a stalled sensor)".into(),
        Refusal::NonFinite | Refusal::Late | Refusal::Duplicate => format!("{why:?}"),
    }
}
