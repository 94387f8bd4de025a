//! The lattice Boltzmann model on MPI ranks through the binary: `mpirun -n P porofrac
//! run` (P = 1, 2, 4, oversubscribed) writes the serial run's numbers, bit for bit
//! (`cargo test -p porofrac-cli --features mpi --test mpi_lbm`; `scripts/test-mpi`).
//!
//! Two scenes, 110 × 20 nodes, 100 lattice steps:
//! * **channel**: a parabolic inlet, a pressure outlet, walls, TRT; a disk across the
//!   border of 2 ranks (column 55) and a box across a border of 4 (column 27);
//! * **heated**: the same channel with a temperature lattice (hot inlet, outflow,
//!   conducting obstacles).
//!
//! Checked against the serial run (`porofrac run`): `probes.csv` (obstacle force, torque,
//! pressure and temperature probes) and `lines/axis.csv` byte for byte, `field_extrema`,
//! the lattice's Mach number and fluid nodes in `summary.json`, and every point array of
//! every written step: the `.pvti` lists one `.vti` piece per rank, the pieces tile the
//! lattice (sharing their border column) and their values are the bits of the serial
//! `.vti`. A scene with a moving obstacle is refused naming its key.

#![cfg(feature = "mpi")]

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::{mpirun, porofrac, summary, tmp_dir};

const CHANNEL: &str = r#"
[scene]
name = "chan"
model = "lbm"
dim = 2

[lbm]
extent = [[0.0, 0.0], [2.2, 0.4]]
spacing = 0.02
density = 1.0
viscosity = 1.0e-3
tau = 0.56
collision = "trt"

[[lbm.boundary]]
side = "xmin"
kind = "velocity"
velocity = ["4 * 0.3 * y * (0.4 - y) / 0.4^2", 0.0]

[[lbm.boundary]]
side = "xmax"
kind = "pressure"
pressure = 0.0

[[lbm.boundary]]
side = "ymin"
kind = "wall"

[[lbm.boundary]]
side = "ymax"
kind = "wall"

[[obstacle]]
name = "cylinder"
shape = { circle = { center = [1.1, 0.2], radius = 0.1 } }

[[obstacle]]
name = "block"
shape = { box = [[0.5, 0.05], [0.62, 0.17]] }

[schedule]
end_time = 0.8
dt = 0.08

[output]
vtk = true
every = 5

[[output.probe]]
name = "drag"
field = "fx"
obstacle = "cylinder"

[[output.probe]]
name = "lift"
field = "fy"
obstacle = "cylinder"

[[output.probe]]
name = "torque"
field = "torque"
obstacle = "block"

[[output.probe]]
name = "p_front"
field = "pressure"
at = [0.95, 0.2]

[[output.line]]
name = "axis"
field = "vx"
from = [0.0, 0.2]
to = [2.2, 0.2]
points = 45
"#;

const HEAT: &str = r#"
[thermal]
diffusivity = 2.0e-3
solid_diffusivity = 1.0e-3
initial = "20 + 5 * sin(3 * x)"

[[thermal.boundary]]
side = "xmin"
temperature = 80.0

[[thermal.boundary]]
side = "xmax"
outflow = true

[[output.probe]]
name = "t_mid"
field = "temperature"
at = [1.13, 0.33]
"#;

/// `(extent, arrays by name)` of a `.vti` written with raw appended data.
fn read_vti(path: &Path) -> ([usize; 6], BTreeMap<String, Vec<f64>>) {
    let bytes = std::fs::read(path).unwrap();
    let mark = b"<AppendedData encoding=\"raw\">";
    let at = bytes
        .windows(mark.len())
        .position(|w| w == mark)
        .expect("appended data");
    let head = String::from_utf8_lossy(&bytes[..at]).into_owned();
    let data = at
        + mark.len()
        + bytes[at + mark.len()..]
            .iter()
            .position(|&b| b == b'_')
            .unwrap()
        + 1;
    let attr = |tag: &str, name: &str| -> String {
        let k = tag.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
        tag[k..k + tag[k..].find('"').unwrap()].to_string()
    };
    let piece = &head[head.find("<Piece").unwrap()..];
    let e: Vec<usize> = attr(piece, "Extent")
        .split(' ')
        .map(|x| x.parse().unwrap())
        .collect();
    let mut arrays = BTreeMap::new();
    for tag in head.split("<DataArray").skip(1) {
        let name = attr(tag, "Name");
        let off: usize = attr(tag, "offset").parse().unwrap();
        let start = data + off;
        let n = u64::from_le_bytes(bytes[start..start + 8].try_into().unwrap()) as usize;
        let v = bytes[start + 8..start + 8 + n]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        arrays.insert(name, v);
    }
    ([e[0], e[1], e[2], e[3], e[4], e[5]], arrays)
}

/// Every point array of every written step of the distributed run in `dir` equals the
/// serial run's in `serial`, bit for bit.
fn same_fields(serial: &Path, dir: &Path, ranks: usize) {
    let mut steps = 0;
    for entry in std::fs::read_dir(serial.join("vtk")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        let Some(stem) = name.strip_suffix(".vti") else {
            continue;
        };
        steps += 1;
        let (whole, want) = read_vti(&serial.join("vtk").join(&name));
        let nx = whole[1] + 1;
        let pvti = std::fs::read_to_string(dir.join("vtk").join(format!("{stem}.pvti"))).unwrap();
        assert_eq!(pvti.matches("<Piece ").count(), ranks, "{pvti}");
        let mut seen = vec![0usize; nx];
        for r in 0..ranks {
            let piece = format!("{stem}_p{r}.vti");
            assert!(pvti.contains(&format!("Source=\"{piece}\"")), "{pvti}");
            let (e, got) = read_vti(&dir.join("vtk").join(&piece));
            let w = e[1] - e[0] + 1;
            assert_eq!(
                got.keys().collect::<Vec<_>>(),
                want.keys().collect::<Vec<_>>()
            );
            for (name, values) in &got {
                let comps = want[name].len() / (nx * (whole[3] + 1));
                for (p, v) in values.iter().enumerate() {
                    let (node, c) = (p / comps, p % comps);
                    let (i, j) = (e[0] + node % w, node / w);
                    let s = want[name][(j * nx + i) * comps + c];
                    assert_eq!(
                        v.to_bits(),
                        s.to_bits(),
                        "{ranks} ranks, {piece}: {name} at node ({i}, {j}): {v:e}, serial {s:e}"
                    );
                }
            }
            for i in e[0]..=e[1] {
                seen[i] += 1;
            }
        }
        // the pieces tile the lattice, neighbours sharing one column
        assert!(seen.iter().all(|&n| n >= 1), "{seen:?}");
        assert_eq!(seen.iter().filter(|&&n| n == 2).count(), ranks - 1);
    }
    assert_eq!(steps, 3, "steps 0, 5 and 10 are written");
}

fn check(name: &str, text: &str) {
    let dir = tmp_dir(&format!("mpi-lbm-{name}"));
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    let serial = dir.join("serial");
    let (code, _, err) = porofrac(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        serial.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let s = summary(&serial);
    for ranks in [1, 2, 4] {
        let out = dir.join(format!("ranks{ranks}"));
        let (code, err) = mpirun(
            ranks,
            &[
                "run",
                scene.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
        );
        assert_eq!(code, 0, "{ranks} ranks: {err}");
        for file in ["probes.csv", "lines/axis.csv"] {
            let a = std::fs::read_to_string(serial.join(file)).unwrap();
            let b = std::fs::read_to_string(out.join(file)).unwrap();
            assert!(a.lines().count() > 2, "{file}: {a}");
            assert_eq!(a, b, "{ranks} ranks: {file}");
        }
        let m = summary(&out);
        assert_eq!(m["field_extrema"], s["field_extrema"], "{ranks} ranks");
        for key in ["mach", "fluid_nodes", "nodes", "lattice_steps"] {
            assert_eq!(m["lattice"][key], s["lattice"][key], "{ranks} ranks: {key}");
        }
        if ranks > 1 {
            assert_eq!(m["mpi"]["ranks"], ranks);
            same_fields(&serial, &out, ranks);
        }
    }
}

#[test]
fn channel_on_1_2_4_ranks_is_the_serial_run() {
    check("channel", CHANNEL);
}

#[test]
fn heated_channel_on_1_2_4_ranks_is_the_serial_run() {
    check("heated", &format!("{CHANNEL}{HEAT}"));
}

#[test]
fn a_moving_obstacle_is_refused_naming_its_key() {
    let dir = tmp_dir("mpi-lbm-moving");
    let scene = dir.join("scene.toml");
    let text = CHANNEL.replace(
        "name = \"block\"\n",
        "name = \"block\"\nvelocity = [0.01, 0.0]\n",
    );
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("out");
    let (code, err) = mpirun(
        2,
        &[
            "run",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert_ne!(code, 0, "{err}");
    assert!(
        err.contains(
            "scene.toml:39: obstacle[1].velocity is given: a moving obstacle has no \
             distributed path yet: run the scene without mpirun (or with -n 1)"
        ),
        "{err}"
    );
    assert_eq!(err.matches("error:").count(), 1, "{err}");
}
