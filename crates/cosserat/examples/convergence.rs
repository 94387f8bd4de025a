//! Convergence of the Cosserat DEM on the shear boundary layer (Marazzato (2021),
//! arXiv:2101.08712, §3.9.2, case A of the closed form in `reference::ShearLayer`): the
//! relative L2 errors of `u1` and `φ` against the mesh size, with the observed orders, for
//! each stencil rule and strain variant.
//!
//! `cargo run --release -p porofrac-cosserat --example convergence [out.csv]`
//!
//! The strip `[−h/2, h/2] × [0, h]`, h = 1 mm, ν = 0, G = 10 GPa, Gc = 20 GPa, couple
//! modulus 4Gℓ² = 100 N; u1 = 1e-5 m on top, u = φ = 0 at the bottom, φ = 0 on top,
//! u2 = 0 on the sides. Meshes: crossed `n × 5n` squares (20·n² triangles, the cell size
//! `h/(5n)` along the layer) with the interior nodes jittered by 0.2 of the smallest
//! altitude (`mesh::crossed_perturbed`, seed 7), so that the stencil rules meet generic
//! cell arrangements. The errors are `‖w_h − w‖ / ‖w‖` in L2 over the strip, `w_h` the
//! cellwise P1 reconstruction (eq. 14), integrated with the edge-midpoint rule (exact
//! for quadratics) on each triangle.

use std::io::Write;
use std::sync::Arc;

use porofrac_cosserat::reference::ShearLayer;
use porofrac_cosserat::{
    BodyLoads, Condition, Cosserat, Material, Options, StencilRule, StrainVariant, constant, mesh,
    strain_index,
};
use porofrac_grid::Point;

/// Relative L2 errors `(u1, φ, σ12)` on the `n × 5n` mesh (σ12 the cell stress against
/// the constant τ).
fn errors(n: usize, options: Options) -> (usize, f64, f64, f64) {
    let h = 1e-3;
    let grid = mesh::crossed_perturbed(
        Point::<2>::new(-h / 2.0, 0.0),
        Point::<2>::new(h / 2.0, h),
        [n, 5 * n],
        0.2,
        7,
    )
    .expect("strip mesh");
    let m = Material::with_length(1e10, 0.0, 2e10, 0.05e-3).expect("material");
    let ends = [0.0, 0.0, 1e-5, 0.0];
    let bottom = Condition::new(grid.boundary("ymin").expect("ymin"))
        .fix(0, constant(ends[0]))
        .fix(1, constant(0.0))
        .fix(2, constant(ends[1]));
    let top = Condition::new(grid.boundary("ymax").expect("ymax"))
        .fix(0, constant(ends[2]))
        .fix(1, constant(0.0))
        .fix(2, constant(ends[3]));
    let mut sides = grid.boundary("xmin").expect("xmin");
    sides.extend(grid.boundary("xmax").expect("xmax"));
    let mirror = Condition::new(sides).fix(1, Arc::new(|_: &Point<2>, _: f64| 0.0));
    let model = Cosserat::new(grid, m, options, &[bottom, top, mirror], BodyLoads::none())
        .expect("assembly");
    let w = model.solve_static(0.0).expect("solve");
    let exact = ShearLayer::new(h, 1e10, 2e10, 100.0, ends);
    let (g, r) = (model.grid(), model.reconstruction());
    let (mut eu, mut nu, mut ep, mut np, mut es) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for c in 0..g.num_cells() {
        let s12 = model.cell_stress(c, &w)[strain_index(2, 0, 1)];
        es += g.cell_volume(c) * (s12 - exact.tau) * (s12 - exact.tau);
        let wq = g.cell_volume(c) / 3.0;
        for &f in g.cell_faces(c) {
            let nodes = g.face_nodes(f);
            let x = (g.node(nodes[0]) + g.node(nodes[1])) * 0.5;
            let (u, p) = (exact.u1(x[1]), exact.phi(x[1]));
            let uh = r.p1_value(g, c, &x, &w, 3, 0);
            let ph = r.p1_value(g, c, &x, &w, 3, 2);
            eu += wq * (uh - u) * (uh - u);
            nu += wq * u * u;
            ep += wq * (ph - p) * (ph - p);
            np += wq * p * p;
        }
    }
    let area = h * h;
    (
        g.num_cells(),
        (eu / nu).sqrt(),
        (ep / np).sqrt(),
        (es / area).sqrt() / exact.tau.abs(),
    )
}

fn main() {
    let out = std::env::args().nth(1);
    let mut csv = String::from("rule,strain,n,cells,h_mm,err_u,err_phi,err_s12\n");
    let rules = [
        ("smallest-weight", StencilRule::SmallestWeight),
        ("first-interpolating", StencilRule::FirstInterpolating),
        (
            "smallest-boundary-weight",
            StencilRule::SmallestBoundaryWeight,
        ),
    ];
    let strains = [
        ("facet", StrainVariant::Facet),
        ("cell", StrainVariant::Cell),
    ];
    println!(
        "rule                     strain  cells    h (mm)   L2(u1)     order  L2(φ)      order  \
         L2(σ12)    order"
    );
    for (rname, rule) in rules {
        for (sname, strain) in strains {
            let mut prev: Option<(f64, f64, f64, f64)> = None;
            for n in [4usize, 8, 16, 32] {
                let options = Options {
                    strain,
                    stencil: rule,
                    ..Options::default()
                };
                let (cells, eu, ep, es) = errors(n, options);
                let hh = 1.0 / (5 * n) as f64;
                let order = |e: f64, e0: f64, h0: f64| (e0 / e).ln() / (h0 / hh).ln();
                let (ou, op, os) = prev
                    .map_or((f64::NAN, f64::NAN, f64::NAN), |(h0, u0, p0, s0)| {
                        (order(eu, u0, h0), order(ep, p0, h0), order(es, s0, h0))
                    });
                println!(
                    "{rname:24} {sname:7} {cells:6} {hh:9.5} {eu:10.3e} {ou:6.2} {ep:10.3e} \
                     {op:6.2} {es:10.3e} {os:6.2}"
                );
                csv.push_str(&format!(
                    "{rname},{sname},{n},{cells},{hh},{eu:.6e},{ep:.6e},{es:.6e}\n"
                ));
                prev = Some((hh, eu, ep, es));
            }
        }
    }
    if let Some(path) = out {
        let mut f = std::fs::File::create(&path).expect("csv file");
        f.write_all(csv.as_bytes()).expect("write csv");
        println!("→ {path}");
    }
}
