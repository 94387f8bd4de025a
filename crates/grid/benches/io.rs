//! Reading `.vtu` files: a 3D grid of 98 304 tetrahedra written as polyhedra, in each of
//! the writer's encodings; reading and processing a faulted corner-point deck of 40³
//! cells (the deck of `examples/grdecl_speed.rs`, which times 100³).
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

fn corner_point(c: &mut Criterion) {
    use porofrac_grid::io::grdecl::{Deck, corner_point_grid, read_deck};
    let n = 40;
    let deck = Deck::on_vertical_pillars([n, n, n], [10.0, 10.0], |[i, _], x, _, k| {
        let throw = if i >= n / 2 { 1.0 } else { 0.0 };
        1000.0 + (k - k / 10) as f64 * 2.0 + 0.02 * x + throw
    });
    let path = std::env::temp_dir().join(format!(
        "porofrac_grdecl_bench_{}.grdecl",
        std::process::id()
    ));
    let mut text = Vec::new();
    deck.write_text(&mut text).expect("in memory");
    std::fs::write(&path, text).expect("deck written");
    let mut group = c.benchmark_group("grdecl_40");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(8));
    group.bench_function("read_deck", |b| b.iter(|| read_deck(&path).expect("read")));
    group.bench_function("corner_point_grid", |b| {
        b.iter(|| corner_point_grid(&deck).expect("processed"))
    });
    group.finish();
    let _ = std::fs::remove_file(&path);
}

criterion_group!(benches, read, corner_point);
criterion_main!(benches);
