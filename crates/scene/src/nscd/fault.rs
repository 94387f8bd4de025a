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
//!   relative L2 mismatch `l2`; `layer` the same over the particles of the layer only
//!   (current centre at or below the initial free surface y_top: without the uplifted
//!   hanging wall and the surface flow above the footwall);
//! * `area`: the fault area as two rays from the current tip (Fig. 12's dashed lines,
//!   drawn from the tip as in trishear), each the ray that best separates the particles
//!   moved by at least a fraction of the slip (on its left) from the others, over the
//!   particles of the window between the tip height and y_top ([`ray_angle`]):
//!   `left_deg` for |u| = (1 − f)s, `right_deg` for |u| = f s, `axis_deg` for |u| = s/2,
//!   and `opening_deg` = left − right, the angle of the fault area between its limits
//!   (the paper's θ_l read as the one angle its two limits reduce to).

use porofrac_nscd::Nscd;
use porofrac_particles::fault::{fault_limits, fit_trishear, limit_angle, moved_by, run_out};
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
                let fit = |x: &[[f64; 2]], v: &[[f64; 2]]| match self.section.half_apex {
                    Some(_) => (base.half_apex, base.l2_mismatch(x, v)),
                    None => fit_trishear(base, x, v),
                };
                let (apex, l2) = fit(&x, &v);
                let (xl, vl): (Vec<[f64; 2]>, Vec<[f64; 2]>) = x
                    .iter()
                    .zip(&v)
                    .filter(|(p, _)| p[1] <= self.y_top)
                    .map(|(p, vi)| (*p, *vi))
                    .unzip();
                let layer = (!xl.is_empty()).then(|| {
                    let (apex, l2) = fit(&xl, &vl);
                    serde_json::json!({
                        "half_apex_deg": apex.to_degrees(),
                        "l2": l2,
                        "particles": xl.len(),
                    })
                });
                serde_json::json!({
                    "half_apex_deg": apex.to_degrees(),
                    "fitted": self.section.half_apex.is_none(),
                    "l2": l2,
                    "from_time": t0,
                    "to_time": t,
                    "layer": layer,
                })
            })
        });
        // The fault area as rays from the tip, over the layer between the tip height and
        // the initial free surface.
        let (xa, ua): (Vec<[f64; 2]>, Vec<[f64; 2]>) = x
            .iter()
            .zip(&u)
            .filter(|(p, _)| p[1] > tip[1] && p[1] <= self.y_top)
            .map(|(p, d)| (*p, *d))
            .unzip();
        let ray = |fraction: f64| {
            let moved: Vec<bool> = ua.iter().map(|d| moved_by(*d, slip, fraction)).collect();
            ray_angle(&xa, &moved, tip)
        };
        let (area_left, area_right) = (ray(1.0 - f), ray(f));
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
            "area": {
                "particles": xa.len(),
                "axis_deg": ray(0.5),
                "left_deg": area_left,
                "right_deg": area_right,
                "opening_deg": area_left.zip(area_right).map(|(l, r)| l - r),
            },
        })
    }
}

/// The angle (degrees from +x, in [1°, 179°], 0.5° steps) of the ray from `tip` that
/// best separates the points `x` flagged `moved` (expected on its left, at larger polar
/// angles about the tip) from the others: the number of moved points below the ray plus
/// other points on or above it is smallest; where several neighbouring angles share the
/// smallest count, the middle of the first such run. `None` when no point is moved or
/// every point is.
pub fn ray_angle(x: &[[f64; 2]], moved: &[bool], tip: [f64; 2]) -> Option<f64> {
    let m = moved.iter().filter(|&&b| b).count();
    if m == 0 || m == moved.len() {
        return None;
    }
    let polar: Vec<f64> = x
        .iter()
        .map(|p| (p[1] - tip[1]).atan2(p[0] - tip[0]).to_degrees())
        .collect();
    let cost = |alpha: f64| {
        polar
            .iter()
            .zip(moved)
            .filter(|(a, mv)| if **mv { **a < alpha } else { **a >= alpha })
            .count()
    };
    let grid: Vec<f64> = (2..=358).map(|k| 0.5 * k as f64).collect();
    let costs: Vec<usize> = grid.iter().map(|&a| cost(a)).collect();
    let best = *costs.iter().min()?;
    let first = costs.iter().position(|&c| c == best)?;
    let last = first + costs[first..].iter().take_while(|&&c| c == best).count() - 1;
    Some(0.5 * (grid[first] + grid[last]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points of a lattice above a tip, moved where their polar angle about the tip is at
    /// least β: the ray comes back as β to the grid's 0.5° (the lattice is dense enough
    /// that no grid angle between the two points nearest to β is empty of both).
    #[test]
    fn ray_recovers_a_straight_boundary_through_the_tip() {
        let tip = [3.0, 1.0];
        for beta in [12.5f64, 30.0, 64.5, 90.0, 121.0] {
            let (mut x, mut moved) = (Vec::new(), Vec::new());
            for j in 1..=80 {
                for i in -400..400 {
                    let p = [
                        tip[0] + 0.013 * i as f64 + 0.0061,
                        tip[1] + 0.011 * j as f64,
                    ];
                    let a = (p[1] - tip[1]).atan2(p[0] - tip[0]).to_degrees();
                    x.push(p);
                    moved.push(a >= beta);
                }
            }
            let r = ray_angle(&x, &moved, tip).unwrap();
            assert!((r - beta).abs() <= 0.5, "β = {beta}: {r}");
        }
    }

    /// A fan of displacement between rays from the tip at 40° (right) and 70° (left),
    /// |u| rising linearly in polar angle from 0 to s across it, with a quarter of the
    /// points flipped to the wrong class at random near the boundary (noise): the rays
    /// of the contours f s, s/2 and (1 − f) s come back at 40 + 30 f, 55 and 70 − 30 f
    /// within 1°, so the opening is (1 − 2f)·30° within 2°.
    #[test]
    fn rays_of_a_fan_give_its_limits_and_opening() {
        let tip = [0.0, 0.0];
        let mut x = Vec::new();
        let mut frac = Vec::new();
        let mut state = 12345u64;
        for j in 1..=60 {
            for i in -300..300 {
                let p = [0.02 * i as f64 + 0.01, 0.1 * j as f64];
                let a = p[1].atan2(p[0]).to_degrees();
                let mut m = ((a - 40.0) / 30.0).clamp(0.0, 1.0);
                // Deterministic jitter of ±0.05 in the fraction.
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                m += 0.1 * ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
                x.push(p);
                frac.push(m);
            }
        }
        let f = 0.2;
        let ray = |k: f64| {
            let moved: Vec<bool> = frac.iter().map(|&m| m >= k).collect();
            ray_angle(&x, &moved, tip).unwrap()
        };
        let (l, a, r) = (ray(1.0 - f), ray(0.5), ray(f));
        assert!((l - 64.0).abs() <= 1.0, "left {l}");
        assert!((a - 55.0).abs() <= 1.0, "axis {a}");
        assert!((r - 46.0).abs() <= 1.0, "right {r}");
        assert!(((l - r) - 18.0).abs() <= 2.0, "opening {}", l - r);
    }

    /// No boundary to find: nothing moved, or everything did.
    #[test]
    fn ray_is_undefined_without_both_classes() {
        let x = [[1.0, 1.0], [-1.0, 1.0]];
        assert_eq!(ray_angle(&x, &[false, false], [0.0, 0.0]), None);
        assert_eq!(ray_angle(&x, &[true, true], [0.0, 0.0]), None);
        assert_eq!(ray_angle(&[], &[], [0.0, 0.0]), None);
        // One each, the moved one on the left: the grid rays above 45° up to 135°
        // separate them; the middle of that run is 90.25°.
        assert_eq!(ray_angle(&x, &[false, true], [0.0, 0.0]), Some(90.25));
    }
}
