//! Bad input gives an error that names what is wrong and where, never a panic.

use porofrac_flow::{
    FlowError, FlowModel, FlowProblem, Fluid, Permeability, Rock, ScalarField, SourceRate, Tensor,
    Well, WellControl,
};
use porofrac_grid::generate::cartesian;
use porofrac_grid::{Grid, Point};

fn grid() -> Grid<2> {
    cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(4.0, 3.0), [4, 3]).unwrap()
}

fn base(g: &Grid<2>) -> FlowProblem<2> {
    let n = g.num_cells();
    FlowProblem::new(
        Rock::new(vec![0.2; n], Permeability::uniform(n, 1e-13).unwrap()),
        Fluid::water(),
    )
}

fn model_err(g: &Grid<2>, p: &FlowProblem<2>) -> FlowError {
    match FlowModel::new(g, p) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    }
}

#[test]
fn bad_permeability() {
    let mut k = vec![1e-13; 12];
    k[5] = 0.0;
    assert!(matches!(
        Permeability::<2>::from_scalars(&k),
        Err(FlowError::Cell { cell: 5, .. })
    ));
    k[5] = -1e-13;
    assert!(matches!(
        Permeability::<2>::from_scalars(&k),
        Err(FlowError::Cell { cell: 5, .. })
    ));
    k[5] = f64::NAN;
    let e = Permeability::<2>::from_scalars(&k).unwrap_err();
    assert!(matches!(e, FlowError::Cell { cell: 5, .. }));
    assert!(e.to_string().contains("cell 5"), "{e}");
    let mut d = vec![[1e-13, 1e-13]; 12];
    d[2] = [1e-13, -1e-14];
    assert!(matches!(
        Permeability::<2>::from_diagonals(&d),
        Err(FlowError::Cell { cell: 2, .. })
    ));
    // Symmetric but indefinite, and non-symmetric.
    let indef = Tensor::<2>::new(1.0, 2.0, 2.0, 1.0);
    let nonsym = Tensor::<2>::new(1.0, 0.5, 0.0, 1.0);
    let mut t = vec![Tensor::<2>::identity(); 12];
    t[7] = indef;
    assert!(matches!(
        Permeability::from_tensors(t.clone()),
        Err(FlowError::Cell { cell: 7, .. })
    ));
    t[7] = nonsym;
    assert!(matches!(
        Permeability::from_tensors(t),
        Err(FlowError::Cell { cell: 7, .. })
    ));
    // Wrong length.
    let g = grid();
    let mut p = base(&g);
    p.rock.permeability = Permeability::uniform(5, 1e-13).unwrap();
    assert!(matches!(
        model_err(&g, &p),
        FlowError::Length {
            what: "permeability",
            got: 5,
            expected: 12
        }
    ));
}

#[test]
fn bad_porosity_and_fluid() {
    let g = grid();
    for bad in [0.0, -0.1, 1.5, f64::NAN] {
        let mut p = base(&g);
        p.rock.porosity[9] = bad;
        assert!(
            matches!(model_err(&g, &p), FlowError::Cell { cell: 9, .. }),
            "{bad}"
        );
    }
    for bad in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        let mut p = base(&g);
        p.fluid.viscosity = bad;
        assert!(matches!(
            model_err(&g, &p),
            FlowError::Fluid {
                property: "viscosity",
                ..
            }
        ));
    }
    for bad in [-1e-9, f64::NAN] {
        let mut p = base(&g);
        p.fluid.compressibility = bad;
        assert!(matches!(
            model_err(&g, &p),
            FlowError::Fluid {
                property: "compressibility",
                ..
            }
        ));
    }
    let mut p = base(&g);
    p.rock.solid_bulk_modulus = -1.0;
    assert!(matches!(
        model_err(&g, &p),
        FlowError::Rock {
            property: "solid_bulk_modulus",
            ..
        }
    ));
    let mut p = base(&g);
    p.rock.solid_bulk_modulus = 1e10;
    p.rock.biot_alpha[3] = 0.1; // α < φ = 0.2: negative storage
    assert!(matches!(model_err(&g, &p), FlowError::Cell { cell: 3, .. }));
}

#[test]
fn bad_sources_wells_and_boundaries() {
    let g = grid();
    let e = model_err(&g, &base(&g).source("inj", vec![], SourceRate::Total(1.0)));
    assert!(matches!(&e, FlowError::Source { name, .. } if name == "inj"));
    assert!(e.to_string().contains("empty"), "{e}");
    let e = model_err(
        &g,
        &base(&g).source("inj", vec![1, 99], SourceRate::Total(1.0)),
    );
    assert!(e.to_string().contains("99"), "{e}");
    let e = model_err(
        &g,
        &base(&g).source("inj", vec![1], SourceRate::Total(f64::NAN)),
    );
    assert!(matches!(e, FlowError::Source { .. }));

    let e = model_err(
        &g,
        &base(&g).well(Well::new("w1", 50, 0.1, WellControl::Bhp(1e6))),
    );
    assert!(matches!(&e, FlowError::Well { name, .. } if name == "w1"));
    // r_w larger than the equivalent radius (0.14 √2 ≈ 0.2 m here).
    let e = model_err(
        &g,
        &base(&g).well(Well::new("w2", 4, 0.5, WellControl::Bhp(1e6))),
    );
    assert!(matches!(&e, FlowError::Well { name, .. } if name == "w2"));
    let e = model_err(
        &g,
        &base(&g).well(Well::new("w3", 4, -0.1, WellControl::Rate(1.0))),
    );
    assert!(matches!(&e, FlowError::Well { name, .. } if name == "w3"));

    // Interior face, face in two conditions, empty set, out of range.
    let interior = (0..g.num_faces())
        .find(|&f| !g.is_boundary_face(f))
        .unwrap();
    let e = model_err(&g, &base(&g).pressure_bc(vec![interior], 1e5));
    assert!(matches!(e, FlowError::Face { face, .. } if face == interior));
    let xmin = g.boundary("xmin").unwrap();
    let e = model_err(
        &g,
        &base(&g)
            .pressure_bc(xmin.clone(), 1e5)
            .flux_bc(vec![xmin[1]], 0.0),
    );
    assert!(matches!(e, FlowError::Face { face, .. } if face == xmin[1]));
    let e = model_err(&g, &base(&g).pressure_bc(vec![], 1e5));
    assert!(matches!(
        e,
        FlowError::Boundary {
            index: 0,
            kind: "pressure",
            ..
        }
    ));
    let e = model_err(&g, &base(&g).flux_bc(vec![10_000], 0.0));
    assert!(matches!(
        e,
        FlowError::Boundary {
            index: 0,
            kind: "flux",
            ..
        }
    ));
    // A function returning NaN is reported at solve time with the face.
    let p = base(&g).pressure_bc(
        xmin.clone(),
        ScalarField::from_fn(|x, _| if x[1] > 2.0 { f64::NAN } else { 0.0 }),
    );
    let mut m = FlowModel::new(&g, &p).unwrap();
    let e = m.solve_steady(0.0).unwrap_err();
    assert!(
        matches!(e, FlowError::Face { face, .. } if xmin.contains(&face)),
        "{e}"
    );
}

#[test]
fn singular_systems() {
    let g = grid();
    let n = g.num_cells();
    // No Dirichlet and zero storage.
    let mut p = base(&g);
    p.fluid.compressibility = 0.0;
    let mut m = FlowModel::new(&g, &p).unwrap();
    assert!(matches!(
        m.step(&vec![0.0; n], 1.0, 0.0),
        Err(FlowError::Singular(_))
    ));
    assert!(matches!(m.solve_steady(0.0), Err(FlowError::Singular(_))));
    // Storage but no anchor: transient is fine, steady is singular.
    let mut m = FlowModel::new(&g, &base(&g)).unwrap();
    let r = m.step(&vec![1e5; n], 1.0, 0.0).unwrap();
    assert!(r.pressure.iter().all(|&v| (v - 1e5).abs() < 1e-6));
    assert!(matches!(m.solve_steady(0.0), Err(FlowError::Singular(_))));
    // Bad steps.
    assert!(matches!(
        m.step(&vec![0.0; n], 0.0, 0.0),
        Err(FlowError::Time(_))
    ));
    assert!(matches!(
        m.step(&vec![0.0; n], f64::NAN, 0.0),
        Err(FlowError::Time(_))
    ));
    assert!(matches!(
        m.step(&[0.0; 3], 1.0, 0.0),
        Err(FlowError::Length { .. })
    ));
    let mut bad = vec![0.0; n];
    bad[4] = f64::NAN;
    assert!(matches!(
        m.step(&bad, 1.0, 0.0),
        Err(FlowError::Cell { cell: 4, .. })
    ));
}
