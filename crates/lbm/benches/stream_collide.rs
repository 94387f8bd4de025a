//! One fused stream–collide step on a periodic D2Q9 lattice: in-place AA streaming against
//! the two-array push kernel, from cache-resident to memory-bound sizes; `aa_f32` the AA
//! kernel on `f32` storage; `lattice_step` is the whole `Lattice::step` (kernel and
//! periodic copies), `lattice_step_single` the same with `f32` populations; `memory/copy_256MB` the copy
//! bandwidth of the machine for comparison, and `memory/update_256MB` the bandwidth of the
//! AA kernel's own traffic pattern (each 8-byte value read and written back in place, no
//! write-allocate), on the rayon pool's threads (`RAYON_NUM_THREADS`).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use porofrac_lbm::d2q9::{Q, W, feq};
use porofrac_lbm::kernel::{Grid, Layout, Physics, Storage, aa_step, push_step_periodic};
use porofrac_lbm::{Collision, Lattice, LatticeConfig, Precision};

fn bench(c: &mut Criterion) {
    let phys = Physics {
        rates: Collision::Bgk.rates(0.8).expect("tau"),
        accel: [0.0, 0.0],
    };
    let mut group = c.benchmark_group("d2q9_step");
    group.sample_size(10);
    for n in [64usize, 256, 1024, 2048, 4096] {
        let g = Grid { nx: n, ny: n };
        group.throughput(Throughput::Elements((n * n) as u64));
        let mut pop = vec![0.0; Q * g.np()];
        for q in 0..Q {
            for v in &mut pop[q * g.np()..(q + 1) * g.np()] {
                *v = feq(q, 1.0, [0.01, 0.0]);
            }
        }
        let mut layout = Layout::Natural;
        group.bench_with_input(BenchmarkId::new("aa", n), &n, |b, _| {
            b.iter(|| layout = aa_step(&mut pop, g, layout, None, phys))
        });
        // f32 storage of f − w, collision in f64: half the bytes per node
        let mut pop32: Vec<f32> = (0..Q * g.np())
            .map(|i| f32::store(pop[i], W[i / g.np()]))
            .collect();
        let mut layout32 = Layout::Natural;
        group.bench_with_input(BenchmarkId::new("aa_f32", n), &n, |b, _| {
            b.iter(|| layout32 = aa_step(&mut pop32, g, layout32, None, phys))
        });
        drop(pop32);
        let mut src = pop.clone();
        let mut dst = pop.clone();
        group.bench_with_input(BenchmarkId::new("two_array_push", n), &n, |b, _| {
            b.iter(|| {
                push_step_periodic(&src, &mut dst, g, phys);
                std::mem::swap(&mut src, &mut dst);
            })
        });
        drop((src, dst));
        let mut lat = Lattice::new(LatticeConfig::periodic(n, n, 0.8)).expect("lattice");
        group.bench_with_input(BenchmarkId::new("lattice_step", n), &n, |b, _| {
            b.iter(|| lat.step().expect("step"))
        });
        lat.set_precision(Precision::Single);
        group.bench_with_input(BenchmarkId::new("lattice_step_single", n), &n, |b, _| {
            b.iter(|| lat.step().expect("step"))
        });
    }
    group.finish();
    // The memory bandwidth the kernels compete for: copy 2 × 256 MB (bytes read + written).
    let mut group = c.benchmark_group("memory");
    group.sample_size(10);
    let n = 32 << 20;
    let src = vec![1.0f64; n];
    let mut dst = vec![0.0f64; n];
    group.throughput(Throughput::Bytes((16 * n) as u64));
    group.bench_function("copy_256MB", |b| b.iter(|| dst.copy_from_slice(&src)));
    // In place, like AA streaming: 16 bytes per value (read + write of the same line).
    group.bench_function("update_256MB", |b| {
        use rayon::prelude::*;
        b.iter(|| {
            dst.par_chunks_mut(1 << 16)
                .for_each(|c| c.iter_mut().for_each(|v| *v = 0.5 * *v + 1.0))
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
