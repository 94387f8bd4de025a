//! `[nscd.fault]`: the measures of a fault-propagation experiment (Renouf et al. (2006)
//! §5.3) written to `summary.json` under `fault` at the end of a run
//! ([`porofrac_particles::fault`]).
//!
//! With the tip x_T(t) = x_T⁰ + V₀ t e (the moving block's corner, e the fault direction)
//! and the slip s = V₀ t, over the particles whose current centre is in `window`:
//!
//! * `limit_angle_deg`: θ_l of the half-slip contour (the propagated fault), bands from
//!   the current tip height (`band` high, default 4 r_max); `limit_angle_points` the
//!   band boundaries;
//! * `limits`: the left and right limits of the fault area of Renouf et al. (2006)
//!   Fig. 12 (the hanging wall in rigid motion on the left of the contour
//!   |u| = (1 − f)s, the undeformed footwall on the right of |u| = f s, f =
//!   `limit_fraction`), each measured as θ_l: `left_deg`, `right_deg`, and their
//!   difference `opening_deg`, the opening of the fault area;
//! * `run_out`: the front of the moved material beyond the point where the basement
//!   fault, extended at its dip from x_T⁰, meets the initial free surface (the highest
//!   initial disk top);
//! * `trishear`: velocities averaged over the last `velocity_window` seconds
//!   (displacement over that time), compared with the analytic field of tip x_T at the
//!   middle of that time; `half_apex_deg` fitted (1° steps) unless given, and the
//!   relative L2 mismatch `l2`.

use porofrac_nscd::Nscd;
use porofrac_particles::fault::{fault_limits, fit_trishear, limit_angle, run_out};
use porofrac_particles::trishear::Trishear;

use super::file::FaultSection;

/// The state kept for the measures during a run.
#[derive(Clone, Debug)]
pub struct FaultProbe {
    section: FaultSection,
    dip: f64,
    start: f64,
    y_top: f64,
    snapshot: Option<(f64, Vec<[f64; 2]>)>,
}

impl FaultProbe {
    /// The probe of a run ending at `end_time`, on the system at t = 0.
    pub fn new(section: &FaultSection, sys: &Nscd, end_time: f64) -> Self {
        let d = &sys.disks;
        let y_top = (0..d.len())
            .map(|i| d.x0[i][1] + d.r[i])
            .fold(f64::NEG_INFINITY, f64::max);
        let start = (end_time - section.velocity_window.unwrap_or(1.0)).max(0.0);
        let mut p = Self {
            section: section.clone(),
            dip: section.dip.to_radians(),
            start,
            y_top,
            snapshot: None,
        };
        p.after_step(sys);
        p
    }

    /// Keep the positions at the start of the velocity window.
    pub fn after_step(&mut self, sys: &Nscd) {
        if self.snapshot.is_none() && sys.time >= self.start - 1e-9 {
            self.snapshot = Some((sys.time, sys.disks.x.clone()));
        }
    }

    /// Save the positions kept at the start of the velocity window (if already taken).
    pub fn save(&self, state: &mut crate::common::checkpoint::State) {
        if let Some((t, x)) = &self.snapshot {
            state.put_f64("fault/snapshot_time", vec![*t]);
            state.put_pairs("fault/snapshot", x);
        }
    }

    /// Put back what [`FaultProbe::save`] saved.
    pub fn restore(
        &mut self,
        state: &crate::common::checkpoint::State,
    ) -> Result<(), crate::common::model::RunError> {
        self.snapshot = match state.f64("fault/snapshot_time") {
            Ok(t) => {
                let n = state.f64s("fault/snapshot")?.len() / 2;
                Some((t, state.pairs("fault/snapshot", n)?))
            }
            Err(_) => None,
        };
        Ok(())
    }

    fn tip(&self, t: f64) -> [f64; 2] {
        let s = self.section.slip_rate * t;
        [
            self.section.tip[0] + s * self.dip.cos(),
            self.section.tip[1] + s * self.dip.sin(),
        ]
    }

    /// The measures at the current state, as JSON.
    pub fn measure(&self, sys: &Nscd) -> serde_json::Value {
        let d = &sys.disks;
        let [a, b] = self.section.window;
        let inside: Vec<usize> = (0..d.len())
            .filter(|&i| {
                let p = d.x[i];
                (a[0]..=b[0]).contains(&p[0]) && (a[1]..=b[1]).contains(&p[1])
            })
            .collect();
        let x: Vec<[f64; 2]> = inside.iter().map(|&i| d.x[i]).collect();
        let u: Vec<[f64; 2]> = inside.iter().map(|&i| d.displacement(i)).collect();
        let t = sys.time;
        let slip = self.section.slip_rate * t;
        let tip = self.tip(t);
        let band = self.section.band.unwrap_or(4.0 * d.radius_range()[1]);
        let la = limit_angle(&x, &u, slip, tip[1], band);
        let f = self.section.limit_fraction.unwrap_or(0.2);
        let (left, right) = fault_limits(&x, &u, slip, f, tip[1], band);
        let deg = |l: &Option<porofrac_particles::fault::LimitAngle>| {
            l.as_ref().map(|l| l.angle.to_degrees())
        };
        let opening = deg(&left).zip(deg(&right)).map(|(l, r)| l - r);
        let ro = run_out(&x, &u, slip, self.section.tip, self.dip, self.y_top);
        let trishear = self.snapshot.as_ref().and_then(|(t0, x0)| {
            let dt = t - t0;
            (dt > 0.0).then(|| {
                let v: Vec<[f64; 2]> = inside
                    .iter()
                    .map(|&i| [(d.x[i][0] - x0[i][0]) / dt, (d.x[i][1] - x0[i][1]) / dt])
                    .collect();
                let base = Trishear {
                    tip: self.tip(0.5 * (t + t0)),
                    dip: self.dip,
                    half_apex: self.section.half_apex.unwrap_or(45.0).to_radians(),
                    v0: self.section.slip_rate,
                };
                let (apex, l2) = match self.section.half_apex {
                    Some(_) => (base.half_apex, base.l2_mismatch(&x, &v)),
                    None => fit_trishear(base, &x, &v),
                };
                serde_json::json!({
                    "half_apex_deg": apex.to_degrees(),
                    "fitted": self.section.half_apex.is_none(),
                    "l2": l2,
                    "from_time": t0,
                    "to_time": t,
                })
            })
        });
        serde_json::json!({
            "slip": slip,
            "tip": tip,
            "particles": inside.len(),
            "limit_angle_deg": la.as_ref().map(|l| l.angle.to_degrees()),
            "limit_angle_points": la.map(|l| l.points),
            "limits": {
                "fraction": f,
                "left_deg": deg(&left),
                "right_deg": deg(&right),
                "opening_deg": opening,
            },
            "run_out": ro,
            "trishear": trishear,
        })
    }
}
