//! Smoothed-aggregation AMG on the standard problems E3 (n = 20) and E2 (n = 300): setup,
//! numeric rebuild, one V-cycle, one product with the matrix, and a full CG solve to a
//! relative residual of 1e-8; and the same with the finest matrix in single precision (the
//! default of the mechanics solver), whose CG multiplies by the double-precision upper
//! triangle (`*_single`: setup, V-cycle, solve).

#[path = "../tests/elasticity_systems/mod.rs"]
#[allow(missing_docs)]
mod common;

use common::System;
use criterion::{Criterion, criterion_group, criterion_main};
use porofrac_amg::{Amg, AmgOptions, Precision, SymCsr};

fn group<const D: usize>(c: &mut Criterion, name: &str, sys: &System<D>) {
    let options = AmgOptions::default();
    let build = || Amg::elasticity(sys.sym(), &sys.coords, D, &sys.eq_dofs, &options).unwrap();
    let mut amg = build();
    let n = sys.n();
    eprintln!(
        "{name}: {n} equations, levels {:?}, operator complexity {:.2}",
        amg.level_info().iter().map(|l| l.rows).collect::<Vec<_>>(),
        amg.operator_complexity()
    );
    let mut g = c.benchmark_group(name);
    g.sample_size(10);
    g.bench_function("setup", |b| b.iter(build));
    g.bench_function("update_values", |b| {
        b.iter(|| amg.update_values(&sys.values).unwrap())
    });
    let r = sys.rhs.clone();
    let mut z = vec![0.0; n];
    g.bench_function("vcycle", |b| b.iter(|| amg.apply(&r, &mut z).unwrap()));
    g.bench_function("spmv", |b| b.iter(|| amg.matrix().mul(&r, &mut z).unwrap()));
    let mut x = vec![0.0; n];
    g.bench_function("solve_1e-8", |b| {
        b.iter(|| {
            x.fill(0.0);
            amg.solve(&mut x, &sys.rhs, 1e-8, 500).unwrap()
        })
    });
    g.finish();

    let single = || {
        let a = SymCsr::from_upper_csc_in(
            Precision::Single,
            n,
            sys.pattern.col_ptr(),
            sys.pattern.row_idx(),
            &sys.values,
        )
        .unwrap();
        Amg::elasticity(a, &sys.coords, D, &sys.eq_dofs, &options).unwrap()
    };
    let mut amg = single();
    let mut g = c.benchmark_group(format!("{name}_single"));
    g.sample_size(10);
    g.bench_function("setup", |b| b.iter(single));
    g.bench_function("vcycle", |b| b.iter(|| amg.apply(&r, &mut z).unwrap()));
    g.bench_function("solve_1e-8", |b| {
        b.iter(|| {
            x.fill(0.0);
            amg.solve_upper(&sys.values, &mut x, &sys.rhs, 1e-8, 500)
                .unwrap()
        })
    });
    g.finish();
}

fn bench(c: &mut Criterion) {
    group(c, "E3_n20", &common::e3(20));
    group(c, "E2_n300", &common::e2(300));
}

criterion_group!(benches, bench);
criterion_main!(benches);
