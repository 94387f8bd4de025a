//! A run kept in memory (`Scene::run_in_memory`) gives the numbers of a run that writes
//! its files, hands its observer every probe row, line and snapshot, and writes nothing.

use std::path::Path;

use porofrac_scene::common::snapshot::Snapshot;
use porofrac_scene::{LawRegistry, Observer, Scene};

#[derive(Default)]
struct Recorder {
    columns: Vec<String>,
    rows: Vec<Vec<f64>>,
    written: Vec<f64>,
    snapshots: Vec<Snapshot>,
}

impl Observer for Recorder {
    fn records(&self) -> bool {
        true
    }
    fn columns(&mut self, probes: &[String], _lines: &[Vec<String>]) {
        self.columns = probes.to_vec();
    }
    fn sampled(&mut self, time: f64, probes: &[f64]) {
        let mut r = vec![time];
        r.extend_from_slice(probes);
        self.rows.push(r);
    }
    fn written(&mut self, time: f64, _lines: &[Vec<Vec<f64>>], snapshot: Option<Snapshot>) {
        self.written.push(time);
        self.snapshots.extend(snapshot);
    }
}

fn scene(rel: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel);
    let text = std::fs::read_to_string(&path).unwrap();
    Scene::parse(&text, &path, LawRegistry::default()).unwrap()
}

/// The patch test in memory: the rows of probes.csv bit for bit, the summary's numbers,
/// and a snapshot whose displacement is the prescribed affine field at every node.
#[test]
fn a_run_in_memory_gives_the_numbers_of_a_run_into_files() {
    let s = scene("scenes/patch_test.toml");
    let dir = std::env::temp_dir().join(format!("porofrac-memory-{}", std::process::id()));
    let written = s.run(&dir, &mut porofrac_scene::Silent).unwrap();
    let csv = std::fs::read_to_string(dir.join("probes.csv")).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let mut rec = Recorder::default();
    let memory = s.run_in_memory(&mut rec).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), rec.columns.join(","));
    let file_rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(file_rows, rec.rows);
    assert_eq!(memory.field_extrema, written.field_extrema);
    assert_eq!(memory.status, "ok");
    assert_eq!(rec.written, vec![0.0]);
    let snap = &rec.snapshots[0];
    let mesh = snap.mesh.as_ref().unwrap();
    assert_eq!((mesh.num_points(), mesh.num_cells()), (81, 64));
    let u = &snap.point_data[0];
    assert_eq!((u.name.as_str(), u.components), ("displacement", 2));
    for (p, d) in mesh.points.chunks(3).zip(u.values.chunks(2)) {
        let (x, y) = (p[0], p[1]);
        assert!((d[0] - (1e-4 + 1e-3 * x + 2e-4 * y)).abs() < 1e-15);
        assert!((d[1] - (-2e-4 - 5e-4 * x + 3e-4 * y)).abs() < 1e-15);
    }
}

/// Nothing is written by a run kept in memory, and an observer that does not record
/// gets no snapshot.
#[test]
fn a_run_in_memory_writes_nothing() {
    let s = scene("scenes/nscd/column.toml");
    let before: Vec<_> = std::fs::read_dir(".").unwrap().collect();
    let summary = s.run_in_memory(&mut porofrac_scene::Silent).unwrap();
    let after: Vec<_> = std::fs::read_dir(".").unwrap().collect();
    assert_eq!(before.len(), after.len());
    assert_eq!(summary.status, "ok");
    let mut rec = Recorder::default();
    s.run_in_memory(&mut rec).unwrap();
    // 50 steps written every 10: t = 0, 0.01, ..., 0.05; every snapshot has the disks.
    assert_eq!(rec.written.len(), 6);
    assert!(
        rec.snapshots
            .iter()
            .all(|s| s.particles.as_ref().unwrap().radii.len() == 10)
    );
}
