//! The Timoshenko–Goodier cantilever with the VEM (plane stress).
//!
//! Beam `L = 8`, `D = 1`, `E = 1000`, `ν = 0.3`, end load `P = 1` with the parabolic
//! shear traction, exact displacement prescribed at the clamped end `x = 0` (the classical
//! benchmark set-up; see `common::Beam` for the closed form). Exact tip deflection
//! `u_y(L, 0) = P L³/(3EI) + (4 + 5ν) P D² L/(24EI) = 2.0480 + 0.0220 = 2.0700`.
//!
//! Checks:
//!
//! * `tip_deflection_quads`: meshes 32×4, 64×8, 128×16, 256×32 squares: the tip deflection
//!   is too small (the discretization is stiff) by 10.0%, 2.71%, 0.69%, 0.17%: within 1%
//!   at 128×16, and the error falls by more than 3 per halving of h (measured 3.7–4.0).
//! * `tip_deflection_triangles`: the same meshes with each square split into 2 triangles
//!   (P1): 17.5%, 5.06%, 1.32%, 0.33% too small: within 1% at 256×32 (not at 128×16), and
//!   the error falls by more than 3 per halving (measured 3.5–4.0).
//! * `nodal_error_converges`: the largest nodal error relative to the tip deflection falls
//!   at least by a factor 3 from 64×8 to 128×16 squares (second order: ~4).

mod common;

use common::*;
use porofrac::grid::Grid;
use porofrac::grid::generate::{cartesian, simplices};
use porofrac::law::Stiffness;
use porofrac::sim::LawMap;
use porofrac::vem::VemLaw;

const BEAM: Beam = Beam {
    l: 8.0,
    d: 1.0,
    p: 1.0,
    e: 1000.0,
    nu: 0.3,
};

fn tip_error(grid: &Grid<2>) -> (f64, f64) {
    let law = VemLaw::new(Stiffness::<2>::isotropic_plane_stress(BEAM.e, BEAM.nu).unwrap());
    let laws = LawMap::uniform(grid, &law).unwrap();
    let (tip, u) = BEAM.solve(grid, &laws);
    let exact = BEAM.displacement();
    let all: Vec<usize> = (0..grid.num_nodes()).collect();
    let nodal = max_node_error(grid, &u, &exact, &all, BEAM.tip());
    ((tip - BEAM.tip()) / BEAM.tip(), nodal)
}

fn study(name: &str, make: impl Fn(usize, usize) -> Grid<2>) -> Vec<(f64, f64)> {
    println!("\n{name}: exact tip deflection {:.6}", BEAM.tip());
    println!(
        "{:>10} {:>8} {:>14} {:>14}",
        "mesh", "dofs", "tip rel. err", "max nodal err"
    );
    [(32, 4), (64, 8), (128, 16), (256, 32)]
        .iter()
        .map(|&(nx, ny)| {
            let g = make(nx, ny);
            let (e, nodal) = tip_error(&g);
            println!(
                "{:>10} {:>8} {:>14.3e} {:>14.3e}",
                format!("{nx}x{ny}"),
                2 * g.num_nodes(),
                e,
                nodal
            );
            (e, nodal)
        })
        .collect()
}

fn quads(nx: usize, ny: usize) -> Grid<2> {
    let (lo, hi) = BEAM.box_corners();
    cartesian(lo, hi, [nx, ny]).unwrap()
}

fn triangles(nx: usize, ny: usize) -> Grid<2> {
    let (lo, hi) = BEAM.box_corners();
    simplices(lo, hi, [nx, ny]).unwrap()
}

/// Too stiff (negative error) and the error falls by more than 3 per halving of h.
fn assert_second_order(r: &[(f64, f64)]) {
    for w in r.windows(2) {
        assert!(w[0].0 < 0.0 && w[1].0 < 0.0, "{r:?}");
        assert!(w[0].0 / w[1].0 > 3.0, "{r:?}");
    }
}

#[test]
fn exact_tip_deflection() {
    let i = BEAM.inertia();
    let t = BEAM.p * BEAM.l.powi(3) / (3.0 * BEAM.e * i)
        + (4.0 + 5.0 * BEAM.nu) * BEAM.p * BEAM.d * BEAM.d * BEAM.l / (24.0 * BEAM.e * i);
    assert!((BEAM.tip() - t).abs() < 1e-12 * t);
    assert!((t - 2.07).abs() < 1e-12);
}

#[test]
fn tip_deflection_quads() {
    let r = study("VEM on squares", quads);
    assert!(r[2].0.abs() < 0.01, "128x16: tip error {:e}", r[2].0);
    assert_second_order(&r);
}

#[test]
fn tip_deflection_triangles() {
    let r = study("VEM on triangles (= P1)", triangles);
    assert!(r[2].0.abs() > 0.01, "128x16: tip error {:e}", r[2].0);
    assert!(r[3].0.abs() < 0.01, "256x32: tip error {:e}", r[3].0);
    assert_second_order(&r);
}

#[test]
fn nodal_error_converges() {
    let (_, a) = tip_error(&quads(64, 8));
    let (_, b) = tip_error(&quads(128, 16));
    println!(
        "max nodal error / tip: 64x8 {a:.3e}, 128x16 {b:.3e}, ratio {:.2}",
        a / b
    );
    assert!(a / b > 3.0, "ratio {}", a / b);
}
