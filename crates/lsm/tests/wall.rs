//! The pressure wall of a hole against closed forms, on a ring of N equal disks of radius
//! R whose centres lie on the circle of radius D = R / sin(π/N) (neighbours touch).
//!
//! * Faces seen from the centre ([`WallFaces::Rays`]): each disk subtends ±π/N, so it
//!   receives `p · 2a sin(π/N)` outwards (a the hole radius given), no tangential part
//!   and no moment (the midpoint sum of the rays: within 1e-6).
//! * Wetted faces ([`WallFaces::Wetted`], disks enlarged by s): neighbouring enlarged
//!   circles cross at radius `r_c = D cos(π/N) − √((sR)² − R²)` on the bisector, so
//!   the wetted arc of each disk runs between two points at radius `r_c` and angles
//!   ±π/N, and the pressure integral over it is `p · 2 r_c sin(π/N)` outwards (the
//!   chord), no tangential part. With s = 1.05 and N = 12 this is 1.19 times the rays'
//!   load for a = D − R: the fluid reaches into the notches up to the seals.
//! * A disk floating in the hole is wetted all round: no load.
//! * A ring with one disk missing leaks: refused.

use porofrac_lsm::{PressureWall, WallFaces};
use porofrac_particles::Disks;

const N: usize = 12;
const R: f64 = 0.5;

fn ring(skip: Option<usize>, floating: bool) -> Disks {
    let d = R / (std::f64::consts::PI / N as f64).sin();
    let mut x = Vec::new();
    let mut r = Vec::new();
    for k in (0..N).filter(|k| Some(*k) != skip) {
        let t = std::f64::consts::TAU * k as f64 / N as f64;
        x.push([d * t.cos(), d * t.sin()]);
        r.push(R);
    }
    if floating {
        x.push([0.3, -0.2]);
        r.push(0.25);
    }
    Disks::new(&x, &r, 2600.0).unwrap()
}

/// (radial, tangential) force and moment of member `i` of `w`.
fn parts(disks: &Disks, w: &PressureWall, i: usize) -> (f64, f64, f64) {
    let l = w
        .members
        .iter()
        .find(|m| m.0 as usize == i)
        .map_or([0.0; 3], |m| m.1);
    let c = disks.x[i];
    let n = c[0].hypot(c[1]);
    let e = [c[0] / n, c[1] / n];
    (l[0] * e[0] + l[1] * e[1], -l[0] * e[1] + l[1] * e[0], l[2])
}

#[test]
fn ring_loads_match_the_closed_forms() {
    let disks = ring(None, true);
    let half = std::f64::consts::PI / N as f64;
    let d = R / half.sin();
    let a = d - R;
    // the rays would stop at the floating disk: the ring alone
    let rays = PressureWall::new(&ring(None, false), [0.0; 2], a).unwrap();
    let s = 1.05;
    let rc = d * half.cos() - ((s * R).powi(2) - R * R).sqrt();
    let wet = PressureWall::with_faces(
        &disks,
        [0.0; 2],
        a,
        WallFaces::Wetted {
            spacing: R / 20.0,
            seal: s,
        },
    )
    .unwrap();
    let (want_rays, want_wet) = (2.0 * a * half.sin(), 2.0 * rc * half.sin());
    let mut worst: [f64; 2] = [0.0; 2];
    for i in 0..N {
        let (rr, rt, rm) = parts(&disks, &rays, i);
        let (wr, wt, _) = parts(&disks, &wet, i);
        worst[0] = worst[0].max(
            (rr / want_rays - 1.0)
                .abs()
                .max(rt.abs() / want_rays)
                .max(rm.abs() / (want_rays * R)),
        );
        worst[1] = worst[1].max((wr / want_wet - 1.0).abs().max(wt.abs() / want_wet));
    }
    eprintln!(
        "rays {want_rays:.4} m, wetted {want_wet:.4} m (ratio {:.3}); worst relative error \
         rays {:.2e}, wetted {:.2e}",
        want_wet / want_rays,
        worst[0],
        worst[1]
    );
    assert!(worst[0] < 1e-6, "{worst:?}");
    assert!(worst[1] < 0.02, "{worst:?}");
    // the floating disk: wet all round
    let (fr, ft, _) = parts(&disks, &wet, N);
    assert!(fr.abs() + ft.abs() < 1e-12, "{fr} {ft}");
}

#[test]
fn a_ring_with_a_gap_leaks_and_is_refused() {
    let disks = ring(Some(3), false);
    let e = PressureWall::with_faces(
        &disks,
        [0.0; 2],
        1.0,
        WallFaces::Wetted {
            spacing: R / 20.0,
            seal: 1.05,
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("reaches the outside"), "{e}");
    for (h, s) in [(0.0, 1.05), (f64::NAN, 1.05), (0.05, 0.9), (0.05, 2.5)] {
        let faces = WallFaces::Wetted {
            spacing: h,
            seal: s,
        };
        assert!(PressureWall::with_faces(&disks, [0.0; 2], 1.0, faces).is_err());
    }
}
