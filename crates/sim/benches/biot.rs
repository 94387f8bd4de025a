//! One monolithic Biot step (VEM on Cartesian quadrilaterals + TPFA, 2D plane strain) on a
//! square with 100² = 1e4 and 316² ≈ 1e5 cells: load on the top, rollers on the left and
//! bottom, drained top. Measured: a step with a new `Δt` (numeric `LDLᵀ` factorization +
//! solve + right-hand side) and a step reusing the factorization (same `Δt`).

use criterion::{Criterion, criterion_group, criterion_main};
use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock};
use porofrac_grid::{Point, generate};
use porofrac_law::stiffness::Stiffness;
use porofrac_sim::*;
use porofrac_vem::VemLaw;

fn bench(c: &mut Criterion) {
    let law = VemLaw::<2>::new(Stiffness::<2>::isotropic(1e10, 0.25).unwrap());
    for n in [100usize, 316] {
        let grid = generate::cartesian::<2>(Point::<2>::zeros(), Point::<2>::repeat(100.0), [n, n])
            .unwrap();
        let roller = |side: &str, a: usize| Displacement {
            name: side.into(),
            faces: grid.boundary(side).unwrap(),
            components: std::array::from_fn(|k| (k == a).then(|| 0.0.into())),
        };
        let dofs = DofMap::new(&grid, &[roller("xmin", 0), roller("ymin", 1)], &[]).unwrap();
        let pattern = Pattern::new(&grid, &dofs).unwrap();
        let loads = Loads {
            tractions: vec![Traction {
                name: "top".into(),
                faces: grid.boundary("ymax").unwrap(),
                traction: [0.0.into(), (-1e7).into()],
            }],
            ..Loads::default()
        };
        let nc = grid.num_cells();
        let problem = FlowProblem::new(
            Rock::new(vec![0.1; nc], Permeability::uniform(nc, 1e-15).unwrap()),
            Fluid::water(),
        )
        .pressure_bc(grid.boundary("ymax").unwrap(), 1e7);
        let flow = FlowModel::new(&grid, &problem).unwrap();
        let laws = LawMap::uniform(&grid, &law).unwrap();
        let mech = StaticProblem {
            grid: &grid,
            laws: &laws,
            dofs: &dofs,
            pattern: &pattern,
            loads: &loads,
        };
        let sys = BiotSystem::new(mech, &flow, vec![1.0; nc], vec![1e7; nc]).unwrap();
        let mut mono = Monolithic::new(&sys, None).unwrap();
        let state = sys.rest_state();
        eprintln!("biot n={n}: {nc} cells, {} unknowns", mono.num_unknowns());
        let mut g = c.benchmark_group(format!("biot_{nc}_cells"));
        g.sample_size(10);
        let mut k = 0u32;
        g.bench_function("step_new_dt", |b| {
            b.iter(|| {
                k += 1;
                let dt = 100.0 + (k % 2) as f64;
                mono.step(&sys, &state, 0.0, dt).unwrap()
            })
        });
        g.bench_function("step_same_dt", |b| {
            b.iter(|| mono.step(&sys, &state, 0.0, 100.0).unwrap())
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
