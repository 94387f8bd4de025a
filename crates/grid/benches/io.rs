//! Reading `.vtu` files: a 3D grid of 98 304 tetrahedra written as polyhedra, in each of
//! the writer's encodings.
//!
//! `cargo bench -p porofrac-grid --bench io`

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use porofrac_grid::generate::simplices;
use porofrac_grid::io::{Encoding, read_vtu, write_vtu_with};
use porofrac_grid::{Grid, Point};

fn read(c: &mut Criterion) {
    let g = simplices(
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(1.0, 1.0, 1.0),
        [32, 32, 16],
    )
    .expect("valid grid");
    let dir = std::env::temp_dir().join(format!("porofrac_io_bench_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let mut group = c.benchmark_group("read_vtu");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(8));
    for enc in [Encoding::Ascii, Encoding::Base64] {
        let path = dir.join(format!("tets_{enc:?}.vtu"));
        write_vtu_with(&path, &g, &[], &[], enc).expect("written");
        let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        group.bench_function(format!("{enc:?} ({:.1} MB)", size as f64 / 1e6), |b| {
            b.iter(|| read_vtu::<3>(&path).expect("read back"))
        });
        let back: Grid<3> = read_vtu(&path).expect("read back");
        assert!(back == g);
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, read);
criterion_main!(benches);
