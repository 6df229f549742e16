//! The projectile's residual velocity, as experimenters measure it: its
//! speed along its flight direction once the contact force along that
//! direction has vanished (SPEC §10).
//!
//! The *flight direction* of a rigid body is the direction of its initial
//! velocity. Its *axial force* is the contact force on it along that
//! direction (`NAME_f_axial` in `history.csv`; negative while the plate
//! brakes it). A touch on the side wall of the hole pushes across the flight
//! direction and does not count: with a frictionless contact its axial
//! force is exactly zero.
//!
//! - **Released**: the axial force has stayed at or below
//!   [`FORCE_FRACTION`] of its largest magnitude so far for at least
//!   [`FREE_FLIGHT`]. The fraction is the contact solver's noise floor, far
//!   below anything that changes the result: in the coarse plane-strain
//!   Case I the peak is of order 2·10⁷ N/m on a 12.56 kg/m projectile, so a
//!   force at the threshold decelerates it by under 2·10³ m/s², which changes
//!   its speed by under 0.04 m/s (0.02 %) over the 20 µs a validation run
//!   goes on after release.
//! - **Perforated**: a plug has been cut out and the projectile is released
//!   at the end of the run, moving forward; the residual velocity `v_r` is
//!   its speed along its flight direction at the end of the run.
//! - **Held**: the projectile's speed along its flight direction has fallen
//!   to [`STOP_FRACTION`] of the impact speed or below (stopped, or bounced
//!   back); `v_r = 0`. Once stopped, the plate can only push it back.
//! - Otherwise the run ended too early to tell: the projectile is still
//!   pushed along its flight (or flies free without a plug cut out, ahead of
//!   a plate that will catch it again).
//!
//! `time.stop_after_release` stops a run by the same definitions
//! ([`ReleaseTracker`], fed every step), reading the verdict of the run is
//! done from its history rows ([`verdict`]), so resumed runs get it too.

use crate::math::{Real, Vec2};

/// How long the axial force must have vanished before the end of the run
/// for the projectile to count as released, s: several history rows (a row
/// every ten steps of about 0.04 µs), so a contact that only paused between
/// two rows is not taken for the end of contact.
pub const FREE_FLIGHT: Real = 1.0e-6;

/// An axial force at or below this fraction of the largest axial force so
/// far counts as vanished (module doc).
pub const FORCE_FRACTION: Real = 1.0e-3;

/// A projectile whose speed along its flight has fallen to this fraction of
/// the impact speed (or below) is held by the plate.
pub const STOP_FRACTION: Real = 0.01;

/// Unit vector along `velocity`, zero for a body at rest.
pub fn flight_direction(velocity: Vec2) -> Vec2 {
    let n = velocity.norm();
    if n > 0.0 {
        velocity / n
    } else {
        Vec2::zeros()
    }
}

/// Follows one projectile's axial force and speed from sample to sample.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReleaseTracker {
    /// Largest |axial force| so far, N.
    peak: Real,
    /// Time of the last sample whose axial force was above the threshold, s.
    last_loaded: Option<Real>,
    /// Since when the speed along the flight has been at or below
    /// [`STOP_FRACTION`] of the impact speed, s.
    stopped_since: Option<Real>,
}

impl ReleaseTracker {
    /// Take one sample: time `t` (s), axial force (N), speed along the
    /// flight `v_axial` and the impact speed (m/s).
    pub fn observe(&mut self, t: Real, f_axial: Real, v_axial: Real, impact_speed: Real) {
        self.peak = self.peak.max(f_axial.abs());
        if f_axial.abs() > FORCE_FRACTION * self.peak {
            self.last_loaded = Some(t);
        }
        if v_axial <= STOP_FRACTION * impact_speed {
            self.stopped_since.get_or_insert(t);
        } else {
            self.stopped_since = None;
        }
    }

    /// How long the axial force has vanished at time `t`, s; `None` before
    /// the first contact or while loaded.
    pub fn free_for(&self, t: Real) -> Option<Real> {
        let free = t - self.last_loaded?;
        (free > 0.0).then_some(free)
    }

    /// How long the projectile has been stopped (or moving back) at `t`, s.
    pub fn stopped_for(&self, t: Real) -> Option<Real> {
        self.stopped_since.map(|s| t - s)
    }

    /// Largest |axial force| so far, N.
    pub fn peak(&self) -> Real {
        self.peak
    }
}

/// How a projectile's flight ended.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Verdict {
    /// Released with a plug cut out: the residual velocity `residual` (m/s,
    /// along the flight), the axial force having vanished since `since` (s).
    Perforated { residual: Real, since: Real },
    /// Stopped or bounced back (since `since`, s): `v_r = 0`.
    Held { since: Real },
    /// Undecided at the end of the run: `speed` along the flight (m/s), and
    /// whether a plug was cut out and whether the axial force had vanished.
    Undecided { speed: Real, plug: bool, free: bool },
    /// The body never moved (no flight direction).
    NotMoving,
}

impl Verdict {
    /// The residual velocity, m/s: `v_r` when perforated, 0 when held.
    pub fn residual(&self) -> Option<Real> {
        match *self {
            Verdict::Perforated { residual, .. } => Some(residual),
            Verdict::Held { .. } => Some(0.0),
            _ => None,
        }
    }

    /// One phrase for tables and summaries.
    pub fn describe(&self) -> String {
        match *self {
            Verdict::Perforated { residual, since } => {
                format!(
                    "perforated: residual velocity {residual:.2} m/s (axial force gone since {:.2} us)",
                    since * 1e6
                )
            }
            Verdict::Held { since } => format!("held (stopped or moving back since {:.2} us): v_r = 0", since * 1e6),
            Verdict::Undecided { speed, plug, free } => format!(
                "undecided at the end: {speed:.2} m/s along its flight, {}, {}",
                if plug { "plug cut out" } else { "no plug cut out" },
                if free { "axial force gone" } else { "still pushed along its flight" }
            ),
            Verdict::NotMoving => "not a projectile (no initial velocity)".into(),
        }
    }
}

/// The verdict from a run's samples of one body, in time order: `(t,
/// axial force, speed along the flight)`, with its impact speed (m/s) and
/// whether a plug had been cut out by the end (module doc).
pub fn verdict(samples: impl IntoIterator<Item = (Real, Real, Real)>, impact_speed: Real, plug: bool) -> Verdict {
    if impact_speed <= 0.0 {
        return Verdict::NotMoving;
    }
    let mut tracker = ReleaseTracker::default();
    let mut last = None;
    for (t, f, v) in samples {
        tracker.observe(t, f, v, impact_speed);
        last = Some((t, v));
    }
    let Some((end, speed)) = last else {
        return Verdict::Undecided { speed: impact_speed, plug, free: false };
    };
    if let Some(since) = tracker.stopped_since {
        return Verdict::Held { since };
    }
    let free = tracker.free_for(end).is_some_and(|f| f >= FREE_FLIGHT);
    match (plug, free) {
        (true, true) => Verdict::Perforated { residual: speed, since: tracker.last_loaded.unwrap_or(end) },
        _ => Verdict::Undecided { speed, plug, free },
    }
}

/// The verdict of rigid body `name` from a run's history, given its flight
/// direction (unit, or zero), impact speed (m/s) and whether a plug was cut
/// out.
pub fn verdict_from_history(
    table: &crate::io::HistoryTable,
    name: &str,
    flight: Vec2,
    impact_speed: Real,
    plug: bool,
) -> Option<Verdict> {
    let t = table.column("time")?;
    let f = table.column(&format!("{name}_f_axial"))?;
    let (vx, vy) = (table.column(&format!("{name}_vx"))?, table.column(&format!("{name}_vy"))?);
    let samples = (0..t.len()).map(|k| (t[k], f[k], vx[k] * flight.x + vy[k] * flight.y));
    Some(verdict(samples, impact_speed, plug))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows every 0.4 µs: the plate brakes the projectile from 300 m/s for
    /// 10 µs, then `after` gives each later row's (axial force, speed).
    fn rows(after: impl Fn(Real) -> (Real, Real)) -> Vec<(Real, Real, Real)> {
        (0..100)
            .map(|k| {
                let t = k as Real * 0.4e-6;
                if t <= 10e-6 {
                    (t, -1.0e7, 300.0 - 5.0e6 * t)
                } else {
                    let (f, v) = after(t);
                    (t, f, v)
                }
            })
            .collect()
    }

    #[test]
    fn a_side_wall_touch_without_axial_force_is_a_release() {
        // After 10 µs only the hole's wall touches the side: the contact
        // counts exist, but the force along the flight is zero.
        let v = verdict(rows(|_| (0.0, 250.0)), 300.0, true);
        assert!(
            matches!(v, Verdict::Perforated { residual, since } if residual == 250.0 && (since - 10e-6).abs() < 0.5e-6),
            "{v:?}"
        );
        assert_eq!(v.residual(), Some(250.0));
        // Noise below 0.1 % of the peak is no force either.
        let v = verdict(rows(|_| (-5.0e3, 250.0)), 300.0, true);
        assert!(matches!(v, Verdict::Perforated { residual, .. } if residual == 250.0), "{v:?}");
    }

    #[test]
    fn an_axial_force_at_the_end_is_no_release() {
        // The plug is pushed ahead to the end.
        let v = verdict(rows(|_| (-1.0e5, 250.0)), 300.0, true);
        assert_eq!(v, Verdict::Undecided { speed: 250.0, plug: true, free: false });
        assert_eq!(v.residual(), None);
        // A force that came back less than FREE_FLIGHT before the end.
        let v = verdict(rows(|t| (if t > 39.0e-6 { -1.0e5 } else { 0.0 }, 250.0)), 300.0, true);
        assert!(matches!(v, Verdict::Undecided { free: false, .. }), "{v:?}");
        // Released, but no plug cut out: the plate will catch it again.
        let v = verdict(rows(|_| (0.0, 250.0)), 300.0, false);
        assert_eq!(v, Verdict::Undecided { speed: 250.0, plug: false, free: true });
    }

    #[test]
    fn a_stopped_or_rebounding_projectile_is_held() {
        // Bounces back and flies free backwards: v_r = 0, held.
        let v = verdict(rows(|_| (0.0, -20.0)), 300.0, false);
        assert!(matches!(v, Verdict::Held { since } if since > 10e-6), "{v:?}");
        assert_eq!(v.residual(), Some(0.0));
        // Stopped in the plate, still pressed (held even with a plug cut).
        let v = verdict(rows(|_| (-1.0e4, 1.0)), 300.0, true);
        assert!(matches!(v, Verdict::Held { .. }), "{v:?}");
        // A body that never moved.
        assert_eq!(verdict(rows(|_| (0.0, 0.0)), 0.0, false), Verdict::NotMoving);
    }

    #[test]
    fn the_tracker_times_the_release_and_the_stop() {
        let mut r = ReleaseTracker::default();
        r.observe(0.0, 0.0, 300.0, 300.0);
        assert_eq!(r.free_for(1.0), None, "never loaded: approaching, not released");
        r.observe(1.0, -2.0e6, 290.0, 300.0);
        r.observe(2.0, -1.0e3, 280.0, 300.0);
        assert_eq!(r.peak(), 2.0e6);
        assert_eq!(r.free_for(3.0), Some(2.0));
        r.observe(3.0, -1.0e4, 2.0, 300.0);
        assert_eq!(r.free_for(3.0), None);
        assert_eq!(r.stopped_for(4.0), Some(1.0));
        assert_eq!(flight_direction(Vec2::new(0.0, -298.0)), Vec2::new(0.0, -1.0));
        assert_eq!(flight_direction(Vec2::zeros()), Vec2::zeros());
    }
}
