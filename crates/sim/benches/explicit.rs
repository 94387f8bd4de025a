//! Time per explicit step (force evaluation + leapfrog update with local damping) on the
//! E2-size grids (unit square, 2 n² triangles, n = 100 and 300) with the MDEM and VEM laws.

use criterion::{Criterion, criterion_group, criterion_main};
use porofrac_grid::{Point, generate};
use porofrac_law::{CellLaw, Stiffness};
use porofrac_mdem::MdemLaw;
use porofrac_sim::*;
use porofrac_vem::VemLaw;

fn bench(c: &mut Criterion) {
    let st = Stiffness::<2>::isotropic(1.0e9, 0.25).unwrap();
    let mdem = MdemLaw::new(&st).unwrap();
    let vem = VemLaw::new(st.clone());
    for n in [100usize, 300] {
        let grid =
            generate::simplices::<2>(Point::<2>::zeros(), Point::<2>::repeat(1.0), [n, n]).unwrap();
        let disp = [
            Displacement {
                name: "xmin".into(),
                faces: grid.boundary("xmin").unwrap(),
                components: [Some(0.0.into()), None],
            },
            Displacement {
                name: "ymin".into(),
                faces: grid.boundary("ymin").unwrap(),
                components: [None, Some(0.0.into())],
            },
        ];
        let loads = Loads {
            tractions: vec![Traction {
                name: "ymax".into(),
                faces: grid.boundary("ymax").unwrap(),
                traction: [1.0e5.into(), (-1.0e6).into()],
            }],
            ..Loads::default()
        };
        let dofs = DofMap::new(&grid, &disp, &[]).unwrap();
        let pattern = Pattern::new(&grid, &dofs).unwrap();
        let density = vec![2500.0; grid.num_cells()];
        let mut g = c.benchmark_group(format!("explicit_E2_n{n}"));
        g.sample_size(10);
        for (name, law) in [("mdem", &mdem as &dyn CellLaw<2>), ("vem", &vem)] {
            let laws = LawMap::uniform(&grid, law).unwrap();
            let problem = StaticProblem {
                grid: &grid,
                laws: &laws,
                dofs: &dofs,
                pattern: &pattern,
                loads: &loads,
            };
            let mut state = ExplicitState::new(
                &problem,
                &density,
                0.0,
                &ExplicitOptions::default(),
                None,
                None,
            )
            .unwrap();
            state.set_time_frozen(true);
            // Leave the all-zero start (where linear cells are skipped).
            for _ in 0..5 {
                state.step().unwrap();
            }
            eprintln!(
                "E2 n={n} {name}: {} cells, {} equations, duplication {:.4}, dt {:.3e} s",
                grid.num_cells(),
                dofs.num_equations(),
                pattern.duplication(),
                state.time_step()
            );
            g.bench_function(format!("step_{name}"), |b| b.iter(|| state.step().unwrap()));
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
