//! A lattice cut into slabs on 1, 2 and 4 MPI ranks computes the serial run's numbers bit
//! for bit (`cargo test -p porofrac-lbm --features mpi --test slab_mpi`; MPI from
//! `scripts/install-mpi`).
//!
//! * **Channel**: a parabolic velocity inlet, a pressure outlet, walls, TRT, 201 steps
//!   (both layouts of the AA pattern are checked: after 100 and after 201 steps), with
//!   a disk across the border of 2 ranks (column 64) and a box across a border of 4
//!   (32), both with the mass-conserving rule (which reads every cut link of a body at
//!   once), a disk inside a slab, and a border of 4 ranks (96) that only the halo
//!   crosses: density and velocity of every node and the force and torque on every
//!   obstacle equal the serial run's bits.
//! * **Heated**: the same channel with a temperature lattice (hot inlet, outflow,
//!   adiabatic walls, a conducting obstacle): the temperature of every node too.
//! * **Single**: the channel with `f32` populations and a wall block overhanging the top
//!   side across the border of 2 ranks (clipped to the lattice): the same bits again (the
//!   halo carries the `f32` values widened to `f64`, which is exact).
//!
//! The test starts `mpirun -n P --oversubscribe` on its own executable, which then runs
//! the distributed part (the environment variable below says so); rank 0 computes the
//! serial run and compares.

#![cfg(feature = "mpi")]

use porofrac_lbm::slab::{Exchange, Plan};
use porofrac_lbm::{
    Collision, Lattice, LatticeConfig, Obstacle, ObstacleOverhang, Precision, Shape, Side,
    SideKind, Thermal, ThermalSide,
};

const CHILD: &str = "POROFRAC_LBM_SLAB_TEST_CHILD";
const NX: usize = 128;
const NY: usize = 34;

fn config() -> LatticeConfig {
    let mut c = LatticeConfig::periodic(NX, NY, 0.62);
    c.periodic = [false, false];
    c.collision = Collision::Trt { magic: 3.0 / 16.0 };
    c.sides = [
        SideKind::Velocity,
        SideKind::Pressure { density: 1.0 },
        SideKind::Wall,
        SideKind::Wall,
    ];
    c.accel = [1e-6, 0.0];
    c
}

fn shapes() -> Vec<Shape> {
    vec![
        Shape::Circle {
            center: [64.3, 17.2],
            radius: 6.1,
        },
        Shape::aligned_box([30.5, 5.0], [34.25, 12.0]),
        Shape::Circle {
            center: [116.6, 24.9],
            radius: 4.3,
        },
    ]
}

/// The obstacles of a run: [`shapes`], and with `single` a wall block overhanging the top.
fn shapes_of(single: bool) -> Vec<Shape> {
    let mut s = shapes();
    if single {
        s.push(Shape::aligned_box([50.3, 30.2], [80.0, 40.0]));
    }
    s
}

/// The channel: the whole lattice (`window` `None`) or the columns `x0 .. x0 + width`;
/// with `single`, `f32` populations and the overhanging block.
fn channel(window: Option<[usize; 2]>, heated: bool, single: bool) -> (Lattice, Option<Thermal>) {
    let mut lat = match window {
        None => Lattice::new(config()).unwrap(),
        Some([x0, x1]) => Lattice::window(config(), x0, x1 - x0).unwrap(),
    };
    if single {
        lat.set_precision(Precision::Single);
        lat.set_obstacle_overhang(ObstacleOverhang::Clipped);
    }
    for shape in shapes_of(single) {
        lat.add_obstacle(Obstacle {
            shape,
            velocity: [0.0, 0.0],
            angular_velocity: 0.0,
        })
        .unwrap();
    }
    let h = NY as f64;
    lat.set_side_velocity(Side::XMin, |p| [0.24 * p[1] * (h - p[1]) / (h * h), 0.0]);
    lat.init(|p| {
        (
            1.0 + 0.01 * (0.3 * p[0]).sin(),
            [0.02, 0.005 * (0.2 * p[1]).cos()],
        )
    });
    let thermal = heated.then(|| {
        let mut sides = [
            ThermalSide::Temperature(1.0),
            ThermalSide::Outflow,
            ThermalSide::Adiabatic,
            ThermalSide::Adiabatic,
        ];
        // a window's own sides inside the box: anything (their columns are overwritten)
        if let Some([x0, x1]) = window {
            if x0 > 0 {
                sides[0] = ThermalSide::Adiabatic;
            }
            if x1 < NX {
                sides[1] = ThermalSide::Adiabatic;
            }
        }
        Thermal::new(&lat, 0.8, 0.65, sides, |p| 0.1 * (0.25 * p[0]).cos()).unwrap()
    });
    (lat, thermal)
}

/// Density, velocity (and temperature) of every node, columns then rows.
fn node_values(lat: &Lattice, th: Option<&Thermal>, i: usize, j: usize, v: &mut Vec<f64>) {
    let (rho, u) = lat.moments(i, j);
    v.extend([rho, u[0], u[1]]);
    if let Some(th) = th {
        v.push(th.temperature(i, j));
    }
}

fn step(lat: &mut Lattice, th: Option<&mut Thermal>, ex: Option<&Exchange>) {
    if let Some(th) = th {
        th.step(lat);
        if let Some(ex) = ex {
            ex.thermal(th);
        }
    }
    lat.step().unwrap();
    if let Some(ex) = ex {
        ex.lattice(lat);
    }
}

fn serial(heated: bool, single: bool, checks: &[usize]) -> Vec<(Vec<f64>, Vec<[f64; 3]>)> {
    let (mut lat, mut th) = channel(None, heated, single);
    let mut out = Vec::new();
    for n in 1..=*checks.last().unwrap() {
        step(&mut lat, th.as_mut(), None);
        if checks.contains(&n) {
            let mut v = Vec::new();
            for i in 0..NX {
                for j in 0..NY {
                    node_values(&lat, th.as_ref(), i, j, &mut v);
                }
            }
            let f = (0..lat.obstacles().len()).map(|k| lat.force(k)).collect();
            out.push((v, f));
        }
    }
    out
}

/// The distributed run on the ranks of `mpirun`, compared on rank 0.
fn child(heated: bool, single: bool) {
    use mpi::traits::Communicator;
    let universe = mpi::initialize().unwrap();
    let world = universe.world();
    let plan = Plan::new(NX, world.size() as usize, &shapes_of(single)).unwrap();
    let ex = Exchange::new(&world, plan);
    let (mut lat, mut th) = channel(Some(ex.slab().window), heated, single);
    let checks = [100, 201];
    let mut got = Vec::new();
    for n in 1..=checks[1] {
        step(&mut lat, th.as_mut(), Some(&ex));
        if checks.contains(&n) {
            let v = ex.gather_owned(NY, |i, j, v| node_values(&lat, th.as_ref(), i, j, v));
            got.push((v, ex.forces(&lat)));
        }
    }
    if world.rank() != 0 {
        return;
    }
    let want = serial(heated, single, &checks);
    for ((n, (v, f)), (wv, wf)) in checks.iter().zip(got).zip(want) {
        let v = v.unwrap();
        assert_eq!(v.len(), wv.len());
        let per = if heated { 4 } else { 3 };
        for (idx, (a, b)) in v.iter().zip(&wv).enumerate() {
            let (node, what) = (idx / per, idx % per);
            assert!(
                a.to_bits() == b.to_bits(),
                "{} ranks, step {n}: node ({}, {}) value {what}: {a:e} distributed, {b:e} serial",
                world.size(),
                node / NY,
                node % NY
            );
        }
        for (k, (a, b)) in f.iter().zip(&wf).enumerate() {
            let bits = |x: &[f64; 3]| x.map(f64::to_bits);
            assert!(b[0] != 0.0, "obstacle {k} feels no force");
            assert_eq!(bits(a), bits(b), "obstacle {k}, step {n}: {a:?} vs {b:?}");
        }
    }
}

/// Run this test's executable under `mpirun -n ranks` in child mode.
fn on_ranks(test: &str, ranks: usize) {
    let exe = std::env::current_exe().unwrap();
    let o = std::process::Command::new("mpirun")
        .args(["--oversubscribe", "--timeout", "300", "-n"])
        .arg(ranks.to_string())
        .arg(exe)
        .args([test, "--exact", "--test-threads=1", "--nocapture"])
        .env(CHILD, "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .expect("mpirun (scripts/install-mpi installs it)");
    assert!(
        o.status.success(),
        "{test} on {ranks} ranks:\n{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn channel_with_obstacles_across_borders_is_the_serial_run() {
    if std::env::var_os(CHILD).is_some() {
        return child(false, false);
    }
    for ranks in [1, 2, 4] {
        on_ranks(
            "channel_with_obstacles_across_borders_is_the_serial_run",
            ranks,
        );
    }
}

#[test]
fn heated_channel_is_the_serial_run() {
    if std::env::var_os(CHILD).is_some() {
        return child(true, false);
    }
    for ranks in [1, 2, 4] {
        on_ranks("heated_channel_is_the_serial_run", ranks);
    }
}

#[test]
fn single_precision_channel_with_an_overhanging_block_is_the_serial_run() {
    if std::env::var_os(CHILD).is_some() {
        return child(false, true);
    }
    for ranks in [1, 2, 4] {
        on_ranks(
            "single_precision_channel_with_an_overhanging_block_is_the_serial_run",
            ranks,
        );
    }
}

/// Windows hold every obstacle they reach whole; owned columns tile the box.
#[test]
fn plan_tiles_the_box_and_widens_windows_over_obstacles() {
    let plan = Plan::new(NX, 4, &shapes()).unwrap();
    let owned: Vec<[usize; 2]> = plan.slabs.iter().map(|s| s.owned).collect();
    assert_eq!(owned, [[0, 32], [32, 64], [64, 96], [96, 128]]);
    // the box (columns 30..33) reaches 30 − 6 .. 34 + 7 and crosses 32: ranks 0 and 1
    // hold it whole, rank 0 first; the disk inside rank 3's slab only rank 3
    assert_eq!(plan.holders, [1, 0, 3]);
    // nothing widens the windows at the border 96
    assert_eq!(plan.slabs[3].window[0], 92);
    for s in &plan.slabs {
        assert!(s.window[0] <= s.owned[0].saturating_sub(4));
        assert!(s.window[1] >= (s.owned[1] + 4).min(NX));
    }
    // the disk at 64.3 (columns 58..69, reach 51..77) is whole in ranks 1 and 2
    assert!(plan.slabs[1].window[1] >= 77 && plan.slabs[2].window[0] <= 51);
    assert!(Plan::new(7, 4, &[]).is_err());
}
