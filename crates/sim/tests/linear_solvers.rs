//! The linear solver choice of the static solve: CG-AMG against Cholesky.
//!
//! Checks:
//! * 2D (40 × 40 squares in triangles) and 3D (10³ cubes in tetrahedra), clamped on xmin,
//!   a varying body force and a traction: CG-AMG at tolerance 1e-10 gives the Cholesky
//!   displacement to 1e-7 relative (2-norm), and reports its iterations and a residual
//!   ≤ 1e-10;
//! * a second solve with new values reuses the hierarchy (one setup, one numeric
//!   update), a third with the same values neither sets up nor updates, and both match
//!   Cholesky to 1e-7;
//! * an iteration limit of 2 is an error naming the iterations and the residual;
//! * `Auto` resolves by dimension and size.

mod common;

use common::{P1Law, isotropic, side};
use porofrac_grid::{Grid, Point, generate};
use porofrac_sim::*;

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let n: f64 = b.iter().map(|y| y * y).sum();
    (d / n).sqrt()
}

struct Case<const D: usize> {
    grid: Grid<D>,
    dofs: DofMap<D>,
    pattern: Pattern,
    loads: Loads<D>,
}

fn case<const D: usize>(n: usize) -> Case<D> {
    let grid =
        generate::simplices::<D>(Point::<D>::zeros(), Point::<D>::repeat(1.0), [n; D]).unwrap();
    let clamp = side(&grid, "xmin", std::array::from_fn(|_| Some(0.0.into())));
    let dofs = DofMap::new(&grid, &[clamp], &[]).unwrap();
    let pattern = Pattern::new(&grid, &dofs).unwrap();
    let loads = Loads {
        body_force: Some(
            std::array::from_fn(|a| {
                ScalarField::from_fn(move |x, _| {
                    (3.0 * x[0] + a as f64).sin() + x[1] * x[1] - 0.5 * x[D - 1]
                })
            })
            .into(),
        ),
        tractions: vec![Traction {
            name: "xmax".into(),
            faces: grid.boundary("xmax").unwrap(),
            traction: std::array::from_fn(|a| if a == 1 { (-0.3).into() } else { 0.1.into() }),
        }],
        ..Loads::default()
    };
    Case {
        grid,
        dofs,
        pattern,
        loads,
    }
}

fn solve<const D: usize, S: LinearSolve>(
    c: &Case<D>,
    law: &P1Law,
    solver: &mut S,
) -> Result<StaticSolution<D>> {
    let laws = LawMap::uniform(&c.grid, law)?;
    let problem = StaticProblem {
        grid: &c.grid,
        laws: &laws,
        dofs: &c.dofs,
        pattern: &c.pattern,
        loads: &c.loads,
    };
    solve_static(&problem, solver, 0.0, &StaticOptions::default())
}

fn law<const D: usize>(e: f64, nu: f64) -> P1Law {
    P1Law {
        d: isotropic::<D>(e, nu),
    }
}

fn same_as_cholesky<const D: usize>(n: usize) {
    let c = case::<D>(n);
    let mut direct = StaticSolver::new(&c.grid, &c.dofs, &c.pattern, LinearSolver::Cholesky)
        .expect("direct solver");
    let amg_choice = LinearSolver::CgAmg { tolerance: 1e-10 };
    let mut amg =
        StaticSolver::new(&c.grid, &c.dofs, &c.pattern, amg_choice).expect("CG-AMG solver");
    assert_eq!((direct.name(), amg.name()), ("cholesky", "cg-amg"));
    let mut previous_updates = 0;
    for (k, (e, nu)) in [(1.0, 0.3), (7.0, 0.45), (7.0, 0.45)]
        .into_iter()
        .enumerate()
    {
        let l = law::<D>(e, nu);
        let reference = solve(&c, &l, &mut direct).expect("Cholesky solve");
        let sol = solve(&c, &l, &mut amg).expect("CG-AMG solve");
        let diff = rel_diff(&sol.displacement, &reference.displacement);
        eprintln!(
            "{D}D n = {n}, E = {e}, ν = {nu}: {} equations, {} CG iterations, residual {:.2e}, \
             difference to Cholesky {diff:.2e}",
            c.dofs.num_equations(),
            sol.linear_iterations,
            sol.residual
        );
        assert!(
            diff < 1e-7,
            "{D}D: CG-AMG differs from Cholesky by {diff:.2e}"
        );
        assert!(sol.residual <= 1e-10, "residual {:.2e}", sol.residual);
        assert!(sol.linear_iterations > 0 && sol.linear_iterations < 100);
        assert_eq!(reference.linear_iterations, 0);
        let StaticSolver::CgAmg(a) = &amg else {
            panic!("not CG-AMG")
        };
        assert_eq!(a.setups(), 1, "the hierarchy is set up once");
        // New values: one numeric update; the same values again: none.
        let want = if k == 1 { 1 } else { previous_updates };
        assert_eq!(a.updates(), want, "solve {k}: numeric updates");
        previous_updates = a.updates();
    }
    assert_eq!(amg.symbolic_factorizations(), 1);
    assert_eq!(amg.numeric_factorizations(), 2);
}

#[test]
fn cg_amg_equals_cholesky_2d() {
    same_as_cholesky::<2>(40);
}

#[test]
fn cg_amg_equals_cholesky_3d() {
    same_as_cholesky::<3>(10);
}

#[test]
fn iteration_limit_is_an_error() {
    let c = case::<3>(10);
    let mut solver = AmgSolver::new(&c.grid, &c.dofs, &c.pattern, 1e-10).unwrap();
    solver.set_max_iterations(2);
    let err = solve(&c, &law::<3>(1.0, 0.3), &mut solver).unwrap_err();
    let msg = err.to_string();
    eprintln!("{msg}");
    assert!(matches!(err, SimError::Iterative(_)), "{err:?}");
    assert!(msg.contains("did not converge in 2 iterations"), "{msg}");
    assert!(msg.contains("relative residual"), "{msg}");
    // The reached residual is in the message and above the tolerance.
    let residual: f64 = msg
        .split("relative residual ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .expect("a residual in the message");
    assert!(residual > 1e-10 && residual < 10.0, "{residual}");
}

#[test]
fn a_bad_tolerance_is_an_error() {
    let c = case::<2>(4);
    for tol in [0.0, -1.0, 1.0, f64::NAN] {
        assert!(AmgSolver::new(&c.grid, &c.dofs, &c.pattern, tol).is_err());
    }
}

#[test]
fn auto_resolves_by_dimension_and_size() {
    let amg = LinearSolver::CgAmg {
        tolerance: linear::DEFAULT_TOLERANCE,
    };
    let auto = LinearSolver::Auto;
    assert_eq!(auto.resolve(3, 5_000), LinearSolver::Cholesky);
    assert_eq!(auto.resolve(3, linear::AUTO_MIN_EQUATIONS_3D), amg);
    assert_eq!(auto.resolve(2, 200_000), LinearSolver::Cholesky);
    assert_eq!(auto.resolve(2, linear::AUTO_MIN_EQUATIONS_2D), amg);
    assert_eq!(
        LinearSolver::Cholesky.resolve(3, 10_000_000),
        LinearSolver::Cholesky
    );
    assert_eq!(LinearSolver::default(), auto);
}
