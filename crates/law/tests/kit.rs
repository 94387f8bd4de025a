//! The test kit on reference laws: it accepts a correct law (in 2D and 3D), rejects
//! broken ones, and works through `Box<dyn CellLaw<D>>` (object safety).

use nalgebra::DMatrix;
use porofrac_grid::{CellFaceLoops, Grid, Point};
use porofrac_law::kelvin::{from_kelvin, kelvin_sym_outer};
use porofrac_law::testkit::{self, KitOptions, check_all};
use porofrac_law::{
    CellGeometry, CellLaw, GeometryBuffer, Kelvin, LawError, Scratch, Stiffness, Tensor,
};

/// Constant-strain law on any cell: energy |K|·½ ε:C:ε with ε from the node normals
/// (exact on simplices), plus an optional deliberate defect.
struct ConstantStrain<const D: usize> {
    material: Stiffness<D>,
    defect: Defect,
}

#[derive(Clone, Copy, PartialEq)]
enum Defect {
    None,
    /// Forces scaled by 1.01: no longer the energy gradient.
    ForceScale,
    /// An extra non-symmetric stiffness term.
    Asymmetric,
    /// A spring to the origin: translations cost energy.
    Anchor,
    /// Every evaluation fails, as on a degenerate cell.
    Fails,
}

impl<const D: usize> ConstantStrain<D> {
    fn strain(cell: &CellGeometry<'_, D>, u: &[f64]) -> Kelvin {
        let mut e = Kelvin::zeros();
        for (i, n) in cell.node_normals.iter().enumerate() {
            e += kelvin_sym_outer::<D>(&Point::<D>::from_column_slice(&u[D * i..D * i + D]), n);
        }
        e / cell.volume
    }

    fn fails(&self, cell: &CellGeometry<'_, D>) -> Result<(), LawError> {
        if self.defect == Defect::Fails {
            return Err(LawError::DegenerateCell {
                volume: cell.volume,
                scale: 1.0,
            });
        }
        Ok(())
    }
}

impl<const D: usize> CellLaw<D> for ConstantStrain<D> {
    fn name(&self) -> &str {
        "constant-strain"
    }
    fn energy(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        _: &mut Scratch,
    ) -> Result<f64, LawError> {
        self.fails(cell)?;
        let e = Self::strain(cell, u);
        let mut w = 0.5 * cell.volume * e.dot(&self.material.stress_kelvin(&e));
        if self.defect == Defect::Anchor {
            w += 0.5 * u.iter().map(|v| v * v).sum::<f64>();
        }
        Ok(w)
    }
    fn forces(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut [f64],
        _: &mut Scratch,
    ) -> Result<(), LawError> {
        self.fails(cell)?;
        let s = from_kelvin::<D>(&self.material.stress_kelvin(&Self::strain(cell, u)));
        let scale = if self.defect == Defect::ForceScale {
            1.01
        } else {
            1.0
        };
        for (i, n) in cell.node_normals.iter().enumerate() {
            let f = -(s * n) * scale;
            out[D * i..D * i + D].copy_from_slice(f.as_slice());
        }
        if self.defect == Defect::Anchor {
            out.iter_mut().zip(u).for_each(|(f, v)| *f -= v);
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
        self.fails(cell)?;
        let n = cell.coords.len();
        porofrac_law::zero_matrix(out, D * n, D * n);
        for i in 0..n {
            for a in 0..D {
                let bi = kelvin_sym_outer::<D>(&unit::<D>(a), &cell.node_normals[i]);
                let dbi = self.material.stress_kelvin(&bi);
                for j in 0..n {
                    for b in 0..D {
                        let bj = kelvin_sym_outer::<D>(&unit::<D>(b), &cell.node_normals[j]);
                        out[(D * i + a, D * j + b)] = dbi.dot(&bj) / cell.volume;
                    }
                }
            }
        }
        match self.defect {
            Defect::Asymmetric => out[(0, 1)] += 1e-3 * out.amax(),
            Defect::Anchor => (0..D * n).for_each(|k| out[(k, k)] += 1.0),
            _ => {}
        }
        Ok(())
    }
    fn stress(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        _: &mut Scratch,
    ) -> Result<Tensor<D>, LawError> {
        self.fails(cell)?;
        Ok(from_kelvin::<D>(
            &self.material.stress_kelvin(&Self::strain(cell, u)),
        ))
    }
}

fn unit<const D: usize>(a: usize) -> Point<D> {
    let mut e = Point::<D>::zeros();
    e[a] = 1.0;
    e
}

fn triangle() -> Grid<2> {
    Grid::from_polygons(
        vec![
            Point::<2>::new(0.1, -0.2),
            Point::<2>::new(1.7, 0.4),
            Point::<2>::new(0.5, 1.3),
        ],
        &[0, 3],
        &[0, 1, 2],
    )
    .unwrap()
}

fn tetrahedron() -> Grid<3> {
    let nodes = vec![
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(1.2, 0.1, -0.1),
        Point::<3>::new(0.2, 0.9, 0.1),
        Point::<3>::new(0.1, 0.3, 1.1),
    ];
    let mut loops = CellFaceLoops::new();
    for f in [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]] {
        loops.push_face(&f);
    }
    loops.finish_cell();
    Grid::from_cell_faces(nodes, &loops).unwrap()
}

/// A correct law passes every check; the reported discrepancies are round-off sized.
#[test]
fn correct_law_passes_in_2d_and_3d() {
    let opts = KitOptions::default();
    let g2 = triangle();
    let mut b2 = GeometryBuffer::default();
    let m2 = Stiffness::<2>::isotropic(3.0, 0.2).unwrap();
    let law2 = ConstantStrain {
        material: m2.clone(),
        defect: Defect::None,
    };
    let r = check_all(&law2, &b2.load(&g2, 0), Some(&m2), &opts).unwrap();
    assert!(
        r.forces_gradient < 1e-8 && r.stiffness_jacobian < 1e-8,
        "{r:?}"
    );
    assert!(
        r.linear_energy.unwrap() < 1e-12 && r.linear_stress.unwrap() < 1e-12,
        "{r:?}"
    );

    let g3 = tetrahedron();
    let mut b3 = GeometryBuffer::default();
    let aniso: Vec<f64> = {
        // An SPD anisotropic Kelvin matrix: isotropic plus a rank-one term.
        let iso = Stiffness::<3>::isotropic(2.0, 0.3).unwrap().to_dmatrix();
        let v = nalgebra::DVector::from_vec(vec![1.0, -0.5, 0.2, 0.3, 0.1, -0.4]);
        let m = iso + &v * v.transpose();
        m.transpose().as_slice().to_vec()
    };
    let m3 = Stiffness::<3>::from_kelvin_rows(&aniso).unwrap();
    let law3 = ConstantStrain {
        material: m3.clone(),
        defect: Defect::None,
    };
    let r = check_all(&law3, &b3.load(&g3, 0), Some(&m3), &opts).unwrap();
    assert!(r.rigid_body < 1e-13 && r.symmetry < 1e-14, "{r:?}");
}

/// Each defect is caught by the check meant for it, and the others still pass.
#[test]
fn broken_laws_fail_the_right_check() {
    let opts = KitOptions::default();
    let g = triangle();
    let mut buf = GeometryBuffer::default();
    let cell = buf.load(&g, 0);
    let m = Stiffness::<2>::isotropic(3.0, 0.2).unwrap();
    let mut u = vec![0.0; 6];
    testkit::sample_displacement(&cell, 1e-3, 7, &mut u);
    let mut s = Scratch::default();

    let law = ConstantStrain {
        material: m.clone(),
        defect: Defect::ForceScale,
    };
    let e = testkit::check_forces_gradient(&law, &cell, &u, &opts, &mut s).unwrap_err();
    // Forces are 1.01 × the gradient: relative error 0.01/1.01.
    assert!((e.error - 0.01 / 1.01).abs() < 1e-6, "{e}");
    assert!(testkit::check_stiffness_symmetric(&law, &cell, &u, &opts, &mut s).is_ok());

    let law = ConstantStrain {
        material: m.clone(),
        defect: Defect::Asymmetric,
    };
    let e = testkit::check_stiffness_symmetric(&law, &cell, &u, &opts, &mut s).unwrap_err();
    assert!(e.error > 9e-4 && e.location.contains("(0, 1)"), "{e}");
    assert!(testkit::check_forces_gradient(&law, &cell, &u, &opts, &mut s).is_ok());

    let law = ConstantStrain {
        material: m.clone(),
        defect: Defect::Anchor,
    };
    let e = testkit::check_rigid_body_motions(&law, &cell, &opts, &mut s).unwrap_err();
    assert!(e.error > 1e-3, "{e}");
    assert!(testkit::check_stiffness_jacobian(&law, &cell, &u, &opts, &mut s).is_ok());
    let grad = Tensor::<2>::new(1e-3, 0.0, 0.0, 0.0);
    let e =
        testkit::check_linear_field(&law, &cell, &m, &grad, &Point::<2>::zeros(), &opts, &mut s)
            .unwrap_err();
    assert_eq!(e.check, "linear field energy");
}

/// The trait is object safe: laws live in a `Vec<Box<dyn CellLaw<D>>>` and the kit runs
/// on trait objects.
#[test]
fn laws_as_trait_objects() {
    let m = Stiffness::<2>::isotropic(1.0, 0.3).unwrap();
    let laws: Vec<Box<dyn CellLaw<2>>> = vec![
        Box::new(ConstantStrain {
            material: m.clone(),
            defect: Defect::None,
        }),
        Box::new(ConstantStrain {
            material: m.clone(),
            defect: Defect::ForceScale,
        }),
    ];
    let g = triangle();
    let mut buf = GeometryBuffer::default();
    let cell = buf.load(&g, 0);
    let results: Vec<bool> = laws
        .iter()
        .map(|l| check_all(l.as_ref(), &cell, Some(&m), &KitOptions::default()).is_ok())
        .collect();
    assert_eq!(results, [true, false]);
    assert_eq!(laws[0].name(), "constant-strain");
}

/// A law that returns an error fails the first check that evaluates it, naming the error.
#[test]
fn failing_law_fails_the_checks() {
    let m = Stiffness::<2>::isotropic(1.0, 0.3).unwrap();
    let law = ConstantStrain {
        material: m.clone(),
        defect: Defect::Fails,
    };
    let g = triangle();
    let mut buf = GeometryBuffer::default();
    let cell = buf.load(&g, 0);
    let e = check_all(&law, &cell, Some(&m), &KitOptions::default()).unwrap_err();
    assert_eq!(e.check, "forces = -grad energy");
    assert_eq!(e.error, f64::INFINITY);
    assert!(e.location.contains("degenerate cell"), "{e}");
    let e = testkit::check_rigid_body_motions(
        &law,
        &cell,
        &KitOptions::default(),
        &mut Scratch::default(),
    )
    .unwrap_err();
    assert_eq!(e.check, "rigid-body motions");
}

/// zero_matrix reuses the buffer and zeroes it.
#[test]
fn zero_matrix_resizes_and_clears() {
    let mut m = DMatrix::from_element(6, 6, 3.0);
    porofrac_law::zero_matrix(&mut m, 4, 4);
    assert_eq!(m.shape(), (4, 4));
    assert_eq!(m.amax(), 0.0);
    m[(1, 1)] = 2.0;
    porofrac_law::zero_matrix(&mut m, 4, 4);
    assert_eq!(m.amax(), 0.0);
}
