//! Measures of a fault-propagation experiment (Renouf et al. (2006) §5.3) from the
//! particle positions x, displacements u and slip s of the basement fault:
//!
//! * **moved particles**: |u| ≥ s/2, i.e. on the hanging-wall side of the half-slip
//!   contour. In the linear trishear field ([`crate::trishear`]) the speed is V₀/2 on
//!   the extension of the fault, so this contour is the propagated fault (the fault
//!   zone's axis);
//! * **limit angle θ_l** ([`limit_angle`]): horizontal bands of height `band` from the
//!   current tip height up; in each band, the boundary x_b between moved particles (on
//!   the left, hanging wall) and the others is the step that misclassifies the fewest
//!   particles; a least-squares line x_b = a + b·y through the band boundaries gives
//!   θ_l = atan2(1, b) from the horizontal, measured on the footwall side (θ_l = θ for a
//!   fault zone that continues the basement fault of dip θ, 90° for a vertical one);
//! * **limits of the fault area** ([`fault_limits`]): the same construction on the
//!   contours |u| = (1 − f)s (left: the hanging wall in rigid motion on its left) and
//!   |u| = f s (right: the undeformed footwall on its right); their difference is the
//!   opening of the fault area;
//! * **run-out** ([`run_out`]): how far the moved material reaches beyond the point where
//!   the basement fault, extended at its dip from its initial tip, meets the initial
//!   free surface: max{x_i : |u_i| ≥ s/2} − (x_tip + (y_top − y_tip)/tan θ);
//! * **trishear fit** ([`fit_trishear`]): the half apical angle φ_a (1°…89° in steps of
//!   1°) that minimises the relative L2 mismatch of the particle velocities against the
//!   analytic field, and that mismatch.

use crate::trishear::Trishear;

/// θ_l and what it was measured from.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitAngle {
    /// θ_l from the horizontal (rad).
    pub angle: f64,
    /// The band boundaries (x_b, y) fitted (m).
    pub points: Vec<[f64; 2]>,
}

/// Whether a particle with displacement `u` moved with the hanging wall (|u| ≥ s/2).
pub fn moved(u: [f64; 2], slip: f64) -> bool {
    moved_by(u, slip, 0.5)
}

/// Whether a particle with displacement `u` moved by at least `fraction` of the slip.
pub fn moved_by(u: [f64; 2], slip: f64, fraction: f64) -> bool {
    (u[0] * u[0] + u[1] * u[1]).sqrt() >= fraction * slip
}

/// The limit angle θ_l (module docs) from bands of height `band` starting at `y0`
/// (the current tip height). A band is used when it holds at least two moved and two
/// other particles; `None` with fewer than two usable bands.
pub fn limit_angle(
    x: &[[f64; 2]],
    u: &[[f64; 2]],
    slip: f64,
    y0: f64,
    band: f64,
) -> Option<LimitAngle> {
    contour_angle(x, u, slip, 0.5, y0, band)
}

/// The limits of the fault area (Renouf et al. (2006) Fig. 12: "the left limit
/// separates the structure governed by a rigid motion from the other part; the right
/// limit separates the undeformed structure from the other part") as `(left, right)`:
/// the angles of the contours |u| = (1 − f) s and |u| = f s, each measured as
/// [`limit_angle`] measures the half-slip one. Their difference is the opening of the
/// fault area (2 φ_a for a trishear zone of half apical angle φ_a).
pub fn fault_limits(
    x: &[[f64; 2]],
    u: &[[f64; 2]],
    slip: f64,
    f: f64,
    y0: f64,
    band: f64,
) -> (Option<LimitAngle>, Option<LimitAngle>) {
    (
        contour_angle(x, u, slip, 1.0 - f, y0, band),
        contour_angle(x, u, slip, f, y0, band),
    )
}

/// The angle of the contour |u| = `fraction` × `slip`, measured as in [`limit_angle`].
pub fn contour_angle(
    x: &[[f64; 2]],
    u: &[[f64; 2]],
    slip: f64,
    fraction: f64,
    y0: f64,
    band: f64,
) -> Option<LimitAngle> {
    let top = x.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
    if !(band > 0.0 && top > y0) {
        return None;
    }
    let bands = ((top - y0) / band).ceil() as usize;
    let mut rows: Vec<Vec<(f64, bool)>> = vec![Vec::new(); bands];
    for (p, d) in x.iter().zip(u) {
        if p[1] >= y0 {
            let k = (((p[1] - y0) / band) as usize).min(bands - 1);
            rows[k].push((p[0], moved_by(*d, slip, fraction)));
        }
    }
    let mut points = Vec::new();
    for (k, row) in rows.iter_mut().enumerate() {
        let m = row.iter().filter(|r| r.1).count();
        if m < 2 || row.len() - m < 2 {
            continue;
        }
        row.sort_by(|a, b| a.0.total_cmp(&b.0));
        // cost(c): others left of c + moved from c on; boundary between c−1 and c.
        let mut cost = m;
        let (mut best, mut at) = (cost, 0);
        for (c, r) in row.iter().enumerate() {
            if r.1 {
                cost -= 1;
            } else {
                cost += 1;
            }
            if cost < best {
                best = cost;
                at = c + 1;
            }
        }
        let xb = match at {
            0 => row[0].0,
            a if a == row.len() => row[a - 1].0,
            a => 0.5 * (row[a - 1].0 + row[a].0),
        };
        points.push([xb, y0 + (k as f64 + 0.5) * band]);
    }
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let (my, mx) = (
        points.iter().map(|p| p[1]).sum::<f64>() / n,
        points.iter().map(|p| p[0]).sum::<f64>() / n,
    );
    let (mut sxy, mut syy) = (0.0, 0.0);
    for p in &points {
        sxy += (p[1] - my) * (p[0] - mx);
        syy += (p[1] - my) * (p[1] - my);
    }
    let b = sxy / syy;
    Some(LimitAngle {
        angle: 1.0f64.atan2(b),
        points,
    })
}

/// The run-out (module docs): the largest x of a moved particle minus the x where the
/// basement fault from `tip` at `dip` (rad) meets the height `y_top`. `None` when no
/// particle moved.
pub fn run_out(
    x: &[[f64; 2]],
    u: &[[f64; 2]],
    slip: f64,
    tip: [f64; 2],
    dip: f64,
    y_top: f64,
) -> Option<f64> {
    let front = x
        .iter()
        .zip(u)
        .filter(|(_, d)| moved(**d, slip))
        .map(|(p, _)| p[0])
        .fold(f64::NEG_INFINITY, f64::max);
    front
        .is_finite()
        .then(|| front - (tip[0] + (y_top - tip[1]) / dip.tan()))
}

/// The half apical angle (rad, 1°…89° in 1° steps) of `base` that minimises the L2
/// mismatch of the velocities `v` at `x`, and that mismatch.
pub fn fit_trishear(base: Trishear, x: &[[f64; 2]], v: &[[f64; 2]]) -> (f64, f64) {
    (1..90)
        .map(|d| {
            let t = Trishear {
                half_apex: (d as f64).to_radians(),
                ..base
            };
            (t.half_apex, t.l2_mismatch(x, v))
        })
        .fold(
            (f64::NAN, f64::INFINITY),
            |a, b| if b.1 < a.1 { b } else { a },
        )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lattice of points displaced exactly like a straight fault zone of angle β
    /// through the band centres (moved on the left): θ_l = β within 1° (the band
    /// boundaries are found on the 0.1 lattice, midway between columns).
    #[test]
    fn straight_boundary_gives_its_angle() {
        for beta_deg in [30.0f64, 60.0, 90.0, 120.0] {
            let cot = 1.0 / beta_deg.to_radians().tan();
            let (mut x, mut u) = (Vec::new(), Vec::new());
            for j in 0..40 {
                let y = 0.05 + 0.1 * j as f64;
                for i in -200..200 {
                    let xi = 0.1 * i as f64 + 0.05;
                    x.push([xi, y]);
                    // The boundary at x = y·cot β, through band centres.
                    let yc = 0.4 * (y / 0.4).floor() + 0.2;
                    let mv = xi < yc * cot;
                    u.push(if mv { [1.0, 0.0] } else { [0.1, 0.0] });
                }
            }
            let la = limit_angle(&x, &u, 1.0, 0.0, 0.4).unwrap();
            // Boundaries lie on the lattice mid-columns: within 0.05 of the line.
            let err = la.angle.to_degrees() - beta_deg;
            assert!(
                err.abs() < 1.0,
                "β = {beta_deg}: θ_l = {}",
                la.angle.to_degrees()
            );
            assert_eq!(la.points.len(), 10);
        }
    }

    /// A fan of displacement between two lines from the origin at 70° (left limit) and
    /// 40° (right limit), |u| falling linearly in angle from s to 0 across it: the
    /// limits come back within 1.5° each for f = 0.2 (their contours are the lines at
    /// 70 − 0.2·30 = 64° and 40 + 0.2·30 = 46°), and the half-slip angle is 55°.
    #[test]
    fn fan_gives_its_limits() {
        let (mut x, mut u) = (Vec::new(), Vec::new());
        for j in 0..60 {
            let y = 0.05 + 0.1 * j as f64;
            for i in -300..300 {
                let xi = 0.02 * i as f64 + 0.01;
                let a = y.atan2(xi).to_degrees();
                let m = ((a - 40.0) / 30.0).clamp(0.0, 1.0);
                x.push([xi, y]);
                u.push([m, 0.0]);
            }
        }
        let (l, r) = fault_limits(&x, &u, 1.0, 0.2, 0.0, 0.5);
        let (l, r) = (l.unwrap().angle.to_degrees(), r.unwrap().angle.to_degrees());
        assert!((l - 64.0).abs() < 1.5 && (r - 46.0).abs() < 1.5, "{l} {r}");
        let h = limit_angle(&x, &u, 1.0, 0.0, 0.5)
            .unwrap()
            .angle
            .to_degrees();
        assert!((h - 55.0).abs() < 1.5, "{h}");
    }

    /// The analytic trishear velocities are fitted back with their own apical angle
    /// and zero mismatch; the run-out of a rigid block is its heave beyond the fault.
    #[test]
    fn trishear_fit_recovers_its_angle_and_run_out() {
        let t = Trishear {
            tip: [1.0, 0.5],
            dip: 30f64.to_radians(),
            half_apex: 23f64.to_radians(),
            v0: 0.3,
        };
        let mut x = Vec::new();
        for i in 0..60 {
            for j in 0..30 {
                x.push([-2.0 + 0.1 * i as f64, 0.1 * j as f64]);
            }
        }
        let v: Vec<_> = x.iter().map(|p| t.velocity(*p)).collect();
        let (a, m) = fit_trishear(t, &x, &v);
        assert!((a.to_degrees() - 23.0).abs() < 1e-9 && m < 1e-14, "{a} {m}");
        let u = vec![[1.0, 0.0]; 2];
        let r = run_out(
            &[[5.0, 3.0], [4.0, 1.0]],
            &u,
            1.0,
            [0.0, 0.0],
            45f64.to_radians(),
            2.0,
        )
        .unwrap();
        assert!((r - 3.0).abs() < 1e-12);
        assert_eq!(
            run_out(&[[5.0, 3.0]], &[[0.1, 0.0]], 1.0, [0.0; 2], 1.0, 2.0),
            None
        );
    }
}
