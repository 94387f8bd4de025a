//! A cell law defined outside porofrac, registered by name and used in a scene.
//!
//! The law is linear (P1) elasticity on simplices: the displacement is linear, its strain
//! is constant, `ε = (1/|K|) Σ_i sym(u_i ⊗ N_i)` with `N_i = ∫_∂K φ_i n = |K| ∇φ_i`, and
//! the energy is `|K| · ½ ε : C : ε`. The example
//!
//! 1. implements [`CellLaw<D>`] for any dimension and runs the law test kit on a
//!    triangle and a tetrahedron;
//! 2. registers it once for 2D and 3D ([`LawFamily::build`] is generic over the
//!    dimension) under the name `"p1"`;
//! 3. runs the same scene (uniaxial compression on triangles) with `law = "p1"` and with
//!    the built-in `law = "mdem"`: on simplices P1 and MDEM are the same law, so the
//!    probes agree to rounding.
//!
//! Run with `cargo run --release -p porofrac-scene --example user_law`.

use nalgebra::DMatrix;
use porofrac_grid::{Grid, Point};
use porofrac_law::kelvin::{from_kelvin, kelvin_sym_outer};
use porofrac_law::testkit::{KitOptions, check_all};
use porofrac_law::{
    CellGeometry, CellLaw, GeometryBuffer, Kelvin, LawError, Scratch, Stiffness, Tensor,
};
use porofrac_scene::laws::{LawFamily, PostFailure};
use porofrac_scene::{LawRegistry, Scene, Silent};

/// P1 elasticity on simplices (triangles, tetrahedra) with a given stiffness.
struct SimplexP1<const D: usize> {
    material: Stiffness<D>,
}

impl<const D: usize> SimplexP1<D> {
    /// Kelvin strain of the nodal displacements.
    fn strain(cell: &CellGeometry<'_, D>, u: &[f64]) -> Kelvin {
        let mut e = Kelvin::zeros();
        for (i, n) in cell.node_normals.iter().enumerate() {
            e += kelvin_sym_outer::<D>(&Point::<D>::from_column_slice(&u[D * i..D * i + D]), n);
        }
        e / cell.volume
    }
}

impl<const D: usize> CellLaw<D> for SimplexP1<D> {
    fn name(&self) -> &str {
        "simplex-p1"
    }

    fn supports(&self, num_nodes: usize) -> bool {
        num_nodes == D + 1
    }

    fn energy(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        _: &mut Scratch,
    ) -> Result<f64, LawError> {
        let e = Self::strain(cell, u);
        Ok(0.5 * cell.volume * e.dot(&self.material.stress_kelvin(&e)))
    }

    fn forces(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut [f64],
        _: &mut Scratch,
    ) -> Result<(), LawError> {
        // F_i = −∂E/∂u_i = −σ N_i.
        let sigma = from_kelvin::<D>(&self.material.stress_kelvin(&Self::strain(cell, u)));
        for (i, n) in cell.node_normals.iter().enumerate() {
            let f = -(sigma * n);
            out[D * i..D * i + D].copy_from_slice(f.as_slice());
        }
        Ok(())
    }

    fn stiffness(
        &self,
        cell: &CellGeometry<'_, D>,
        _u: &[f64],
        out: &mut DMatrix<f64>,
        _: &mut Scratch,
    ) -> Result<(), LawError> {
        // K_(ia),(jb) = (1/|K|) B_ia · D B_jb with B_ia the Kelvin strain of a unit
        // displacement of node i in direction a.
        let n = cell.coords.len();
        porofrac_law::zero_matrix(out, D * n, D * n);
        for i in 0..n {
            for a in 0..D {
                let bi = kelvin_sym_outer::<D>(
                    &Point::<D>::from_fn(|k, _| f64::from(u8::from(k == a))),
                    &cell.node_normals[i],
                );
                let dbi = self.material.stress_kelvin(&bi);
                for j in 0..n {
                    for b in 0..D {
                        let bj = kelvin_sym_outer::<D>(
                            &Point::<D>::from_fn(|k, _| f64::from(u8::from(k == b))),
                            &cell.node_normals[j],
                        );
                        out[(D * i + a, D * j + b)] = dbi.dot(&bj) / cell.volume;
                    }
                }
            }
        }
        Ok(())
    }

    fn stress(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        _: &mut Scratch,
    ) -> Result<Tensor<D>, LawError> {
        Ok(from_kelvin::<D>(
            &self.material.stress_kelvin(&Self::strain(cell, u)),
        ))
    }
}

/// The family of [`SimplexP1`] laws, one per dimension.
struct P1;

impl LawFamily for P1 {
    fn build<const D: usize>(&self, s: &Stiffness<D>) -> Result<Box<dyn CellLaw<D>>, String> {
        Ok(Box::new(SimplexP1 {
            material: s.clone(),
        }))
    }
}

/// Run the test kit on one cell of `grid` and print the worst errors.
fn kit<const D: usize>(grid: &Grid<D>) -> Result<(), Box<dyn std::error::Error>> {
    let material = Stiffness::<D>::isotropic(10e9, 0.25)?;
    let law = SimplexP1 {
        material: material.clone(),
    };
    let mut buf = GeometryBuffer::default();
    let cell = buf.load(grid, 0);
    let r = check_all(&law, &cell, Some(&material), &KitOptions::default())?;
    println!(
        "{D}D: test kit passed (forces = -grad E {:.1e}, K = -dF/du {:.1e}, symmetry {:.1e}, \
         rigid-body {:.1e}, linear-field stress {:.1e})",
        r.forces_gradient,
        r.stiffness_jacobian,
        r.symmetry,
        r.rigid_body,
        r.linear_stress.unwrap_or(f64::NAN)
    );
    Ok(())
}

const SCENE: &str = r#"
[scene]
name = "LAW"
dim = 2

[grid]
kind = "triangles"
extent = [[0.0, 0.0], [1.0, 1.0]]
cells = [8, 8]
perturb = 0.2

[[region]]
name = "all"
select = { all = true }
law = "LAW"
material = "rock"

[material.rock]
youngs_modulus = 1.0e9
poisson_ratio = 0.25

[[bc]]
boundary = "ymin"
displacement = ["free", 0.0]

[[bc]]
boundary = "xmin"
displacement = [0.0, "free"]

[[bc]]
boundary = "ymax"
traction = ["-1.0e5*x", -1.0e6]

[output]
vtk = false
plots = false

[[output.probe]]
name = "uy_top"
field = "uy"
at = [0.5, 1.0]

[[output.probe]]
name = "sxy"
field = "sxy"
at = [0.3, 0.7]
"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    kit(&Grid::from_polygons(
        vec![
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(2.0, 0.3),
            Point::<2>::new(0.4, 1.5),
        ],
        &[0, 3],
        &[0, 1, 2],
    )?)?;
    kit(&porofrac_grid::generate::simplices(
        Point::<3>::zeros(),
        Point::<3>::new(1.0, 1.0, 1.0),
        [1, 1, 1],
    )?)?;

    let mut laws = LawRegistry::default();
    laws.register("p1", P1, PostFailure::Keep);
    let dir = std::env::temp_dir().join("porofrac-user-law");
    let mut rows = Vec::new();
    for law in ["mdem", "p1"] {
        let scene = Scene::parse(
            &SCENE.replace("LAW", law),
            &dir.join(format!("{law}.toml")),
            laws.clone(),
        )?;
        let out = dir.join(law);
        scene.run(&out, &mut Silent)?;
        let probes = std::fs::read_to_string(out.join("probes.csv"))?;
        let row: Vec<f64> = probes
            .lines()
            .nth(1)
            .ok_or("probes.csv has no row")?
            .split(',')
            .map(str::parse)
            .collect::<Result<_, _>>()?;
        println!(
            "law = {law:5}: uy(top) = {:.12e} m, sxy = {:.12e} Pa",
            row[1], row[2]
        );
        rows.push(row);
    }
    let diff = (rows[0][1] - rows[1][1]).abs() / rows[0][1].abs();
    println!("p1 against mdem: relative difference of uy {diff:.1e}");
    Ok(())
}
