//! Fluid and heat through grains read from an image (Mora et al. (2015), Fig. 10) and the
//! heat books of every step.
//!
//! * An image's grains become rectangles of nodes whose every cut link is halfway
//!   (`δ = ½` exactly), and the rectangles cover the image's solid nodes once.
//! * Cold fluid enters a channel of hot grains (held at their temperature, then conjugate):
//!   `stored_after − stored_before = conduction_in + advection_in − advection_out +
//!   solids` to 1e-12 relative per step (the gate is 1e-8); the advected heat is `u T` of
//!   the inlet nodes at the inlet's temperature and of the outlet nodes (1e-6, the flow
//!   steady); held grains give heat (`solids > 0`) and, once the flow is steady, what their
//!   reservoir gives is what the fluid gets, within 1e-6; conjugate grains cool (they give
//!   less than half as much in the last 100 steps of 4 000 as in the first 100).

use porofrac_lbm::image::{GreyImage, Polarity, rectangles};
use porofrac_lbm::{Lattice, LatticeConfig, Obstacle, Shape, Side, SideKind, Thermal, ThermalSide};

/// A 48 × 16 lattice with grains from a small PGM drawn at 2 nodes per pixel: three
/// round-ish grains and one touching the bottom wall.
fn grain_channel(u_in: f64) -> (Lattice, Vec<bool>) {
    let (w, h) = (24, 8);
    let mut text = format!("P2\n{w} {h}\n255\n");
    for r in 0..h {
        for c in 0..w {
            let y = (h - 1 - r) as f64 + 0.5;
            let x = c as f64 + 0.5;
            let grain = [
                (7.0, 4.0, 1.8),
                (13.0, 2.0, 1.2),
                (17.0, 5.5, 1.5),
                (11.0, 0.0, 1.0),
            ]
            .iter()
            .any(|&(cx, cy, rad): &(f64, f64, f64)| (x - cx).hypot(y - cy) < rad);
            text.push_str(if grain { "230 " } else { "20 " });
        }
        text.push('\n');
    }
    let img = GreyImage::parse(text.as_bytes()).unwrap();
    let (nx, ny) = (48, 16);
    let solid = img.solid_map(nx, ny, [0.0, 0.0], 2.0, 0.5, Polarity::Above);
    let mut cfg = LatticeConfig::periodic(nx, ny, 0.8);
    cfg.periodic = [false, false];
    cfg.sides = [
        SideKind::Velocity,
        SideKind::Pressure { density: 1.0 },
        SideKind::Wall,
        SideKind::Wall,
    ];
    let mut lat = Lattice::new(cfg).unwrap();
    for r in rectangles(&solid, nx, ny) {
        lat.add_obstacle(Obstacle {
            shape: Shape::aligned_box(
                [r[0] as f64, r[1] as f64],
                [r[2] as f64 + 1.0, r[3] as f64 + 1.0],
            ),
            velocity: [0.0, 0.0],
            angular_velocity: 0.0,
        })
        .unwrap();
    }
    lat.set_side_velocity(Side::XMin, |_| [u_in, 0.0]);
    lat.init(|_| (1.0, [u_in, 0.0]));
    (lat, solid)
}

#[test]
fn image_grains_are_the_image_nodes_with_halfway_links() {
    let (lat, solid) = grain_channel(0.05);
    let (nx, ny) = lat.size();
    let n_solid = solid.iter().filter(|s| **s).count();
    assert!(n_solid > 60, "{n_solid} solid nodes");
    for j in 0..ny {
        for i in 0..nx {
            assert_eq!(lat.is_solid(i, j), solid[j * nx + i], "node ({i}, {j})");
        }
    }
    let mut links = 0;
    for k in 0..lat.obstacles().len() {
        for (_, _, _, delta) in lat.cut_links_of(k) {
            assert_eq!(delta, 0.5);
            links += 1;
        }
    }
    assert!(links > 50, "{links} cut links");
}

fn run_books(
    held: bool,
) -> (
    f64,
    Vec<porofrac_lbm::HeatBooks>,
    Vec<f64>,
    Lattice,
    Thermal,
) {
    let u_in = 0.02;
    let (t_cold, t_hot) = (0.2, 1.0);
    let (mut lat, solid) = grain_channel(u_in);
    let (nx, ny) = lat.size();
    let sides = [
        ThermalSide::Temperature(t_cold),
        ThermalSide::Outflow,
        ThermalSide::Adiabatic,
        ThermalSide::Adiabatic,
    ];
    let mut th = Thermal::new(&lat, 0.7, 0.9, sides, |_| t_cold).unwrap();
    let grains: Vec<(usize, usize)> = (0..nx * ny)
        .filter(|&n| solid[n])
        .map(|n| (n % nx, n / nx))
        .collect();
    if held {
        th.hold(grains.iter().copied(), t_hot);
    } else {
        for &(i, j) in &grains {
            th.set_temperature(i, j, t_hot);
        }
    }
    th.keep_books();
    let mut worst: f64 = 0.0;
    let mut books = Vec::new();
    let mut held_heat = Vec::new();
    for _ in 0..4000 {
        th.step(&lat);
        lat.step().unwrap();
        let b = th.books().unwrap();
        worst = worst.max(b.defect().abs() / b.stored_before.abs());
        books.push(b);
        held_heat.push(th.held_heat());
    }
    (worst, books, held_heat, lat, th)
}

#[test]
fn heat_books_balance_every_step_with_held_grains() {
    let (worst, books, held_heat, lat, th) = run_books(true);
    assert!(worst < 1e-12, "per-step relative defect {worst:e}");
    let last = books.last().unwrap();
    // the advected heat is `u T` of the inlet nodes at the inlet's temperature (the
    // inflow u_in T_w per link, less where the corner nodes lag in the walls' boundary
    // layers and where the pressure before the grains compresses the fluid), and `u T` of
    // the outlet nodes; the walls advect nothing (the books are those of the step before
    // the lattice's last one: the flow is steady to 1e-6)
    let (nx, ny) = (48, 16);
    let inflow: f64 = (0..ny).map(|j| lat.moments(0, j).1[0] * 0.2).sum();
    let outflow: f64 = (0..ny)
        .map(|j| lat.moments(nx - 1, j).1[0] * th.temperature(nx - 1, j))
        .sum();
    assert!(inflow > 0.7 * 0.02 * 0.2 * 16.0, "{inflow}");
    assert!(
        (last.advection_in / inflow - 1.0).abs() < 1e-6
            && (last.advection_out / outflow - 1.0).abs() < 1e-6,
        "advection in {} out {}, inlet u T {inflow}, outlet u T {outflow}",
        last.advection_in,
        last.advection_out
    );
    assert!(last.solids > 0.0 && last.advection_out > last.advection_in);
    // steady: the reservoir gives what the fluid gets
    let (h, s) = (*held_heat.last().unwrap(), last.solids);
    assert!((h - s).abs() < 1e-6 * s, "reservoir {h}, fluid {s}");
    // and the fluid's heat has settled: in = out to 1e-4 of what flows through
    let change = last.stored_after - last.stored_before;
    assert!(
        change.abs() < 1e-4 * last.advection_out,
        "change {change:e}"
    );
}

#[test]
fn heat_books_balance_every_step_with_conjugate_grains() {
    let (worst, books, held_heat, _, _) = run_books(false);
    assert!(worst < 1e-12, "per-step relative defect {worst:e}");
    assert!(held_heat.iter().all(|h| *h == 0.0));
    // the grains cool: they give heat early, and less later
    let early: f64 = books[..100].iter().map(|b| b.solids).sum();
    let late: f64 = books[3900..].iter().map(|b| b.solids).sum();
    assert!(
        early > 0.0 && late < 0.5 * early,
        "early {early}, late {late}"
    );
}
