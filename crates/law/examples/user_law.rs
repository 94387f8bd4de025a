//! A cell law defined outside porofrac: linear (P1) elasticity on triangles.
//!
//! On a triangle the displacement is linear, its strain is constant,
//! `ε = (1/|K|) Σ_i sym(u_i ⊗ N_i)` with `N_i = ∫_∂K φ_i n = |K| ∇φ_i`, and the energy
//! is `|K| · ½ ε : C : ε`. The example implements [`CellLaw<2>`], runs the law test kit
//! on a triangle, and stores the law as a `Box<dyn CellLaw<2>>` as a scene would.
//!
//! Run with `cargo run -p porofrac-law --example user_law`.

use nalgebra::DMatrix;
use porofrac_grid::{Grid, Point};
use porofrac_law::kelvin::{from_kelvin, kelvin_sym_outer};
use porofrac_law::testkit::{KitOptions, check_all};
use porofrac_law::{CellGeometry, CellLaw, GeometryBuffer, Kelvin, Scratch, Stiffness, Tensor};

/// P1 elasticity on triangles with a given stiffness.
struct TriangleP1 {
    material: Stiffness<2>,
}

impl TriangleP1 {
    /// Kelvin strain of the nodal displacements.
    fn strain(cell: &CellGeometry<'_, 2>, u: &[f64]) -> Kelvin {
        let mut e = Kelvin::zeros();
        for (i, n) in cell.node_normals.iter().enumerate() {
            e += kelvin_sym_outer::<2>(&Point::<2>::new(u[2 * i], u[2 * i + 1]), n);
        }
        e / cell.volume
    }
}

impl CellLaw<2> for TriangleP1 {
    fn name(&self) -> &str {
        "triangle-p1"
    }

    fn supports(&self, num_nodes: usize) -> bool {
        num_nodes == 3
    }

    fn energy(&self, cell: &CellGeometry<'_, 2>, u: &[f64], _: &mut Scratch) -> f64 {
        let e = Self::strain(cell, u);
        0.5 * cell.volume * e.dot(&self.material.stress_kelvin(&e))
    }

    fn forces(&self, cell: &CellGeometry<'_, 2>, u: &[f64], out: &mut [f64], _: &mut Scratch) {
        // F_i = −∂E/∂u_i = −σ N_i.
        let sigma = from_kelvin::<2>(&self.material.stress_kelvin(&Self::strain(cell, u)));
        for (i, n) in cell.node_normals.iter().enumerate() {
            let f = -(sigma * n);
            out[2 * i] = f[0];
            out[2 * i + 1] = f[1];
        }
    }

    fn stiffness(
        &self,
        cell: &CellGeometry<'_, 2>,
        _u: &[f64],
        out: &mut DMatrix<f64>,
        _: &mut Scratch,
    ) {
        // K_(ia),(jb) = (1/|K|) B_ia · D B_jb with B_ia the Kelvin strain of a unit
        // displacement of node i in direction a.
        let n = cell.coords.len();
        porofrac_law::zero_matrix(out, 2 * n, 2 * n);
        for i in 0..n {
            for a in 0..2 {
                let bi = kelvin_sym_outer::<2>(&Point::<2>::ith(a, 1.0), &cell.node_normals[i]);
                let dbi = self.material.stress_kelvin(&bi);
                for j in 0..n {
                    for b in 0..2 {
                        let bj =
                            kelvin_sym_outer::<2>(&Point::<2>::ith(b, 1.0), &cell.node_normals[j]);
                        out[(2 * i + a, 2 * j + b)] = dbi.dot(&bj) / cell.volume;
                    }
                }
            }
        }
    }

    fn stress(&self, cell: &CellGeometry<'_, 2>, u: &[f64], _: &mut Scratch) -> Tensor<2> {
        from_kelvin::<2>(&self.material.stress_kelvin(&Self::strain(cell, u)))
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let material = Stiffness::<2>::isotropic(10e9, 0.25)?;
    let grid = Grid::from_polygons(
        vec![
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(2.0, 0.3),
            Point::<2>::new(0.4, 1.5),
        ],
        &[0, 3],
        &[0, 1, 2],
    )?;
    let law: Box<dyn CellLaw<2>> = Box::new(TriangleP1 {
        material: material.clone(),
    });
    let mut buf = GeometryBuffer::default();
    let cell = buf.load(&grid, 0);
    let report = check_all(law.as_ref(), &cell, Some(&material), &KitOptions::default())?;
    println!("law '{}' passed the test kit:", law.name());
    println!(
        "  forces = -grad E       worst rel. error {:.2e}",
        report.forces_gradient
    );
    println!(
        "  K = -dF/du             worst rel. error {:.2e}",
        report.stiffness_jacobian
    );
    println!(
        "  K symmetric            worst rel. error {:.2e}",
        report.symmetry
    );
    println!(
        "  rigid-body motions     worst rel. error {:.2e}",
        report.rigid_body
    );
    println!(
        "  linear field energy    rel. error {:.2e}",
        report.linear_energy.unwrap_or(f64::NAN)
    );
    println!(
        "  linear field stress    rel. error {:.2e}",
        report.linear_stress.unwrap_or(f64::NAN)
    );
    Ok(())
}
