//! The crack network of broken bonds ([`porofrac_particle_fluid::bond_cracks`]) in a
//! coupled step, against closed forms.
//!
//! Two rows of disks (radius 3 Δx, all gaps 0.3 Δx, a hexagonal pair of rows) lie in an
//! impermeable wall (two fixed boxes) that splits a box into two chambers (held at two
//! densities by pressure sides, or closed); the
//! disks at the two ends of the rows stick out into the chambers. Every bond between the
//! rows is broken: the crack is a chain of `n = 2M` channels of aperture 0.3 Δx and
//! length 2R through the pores of the triangles between the rows, open to the left
//! chamber at one end and to the right one at the other. The disks are held.
//!
//! * Topology: `n` channels, `n − 1` pores (one per triangle shared by two consecutive
//!   broken bonds), two mouths.
//! * Once steady (the chambers held by pressure sides; means over 3 000 steps, as the
//!   chambers ring with sound), every channel carries the series cubic law of its mouths'
//!   densities, `K Δρ / n` with `K = w³ c_s² / (12 ν L)` (5e-5; measured 9e-6), and its
//!   gauge pressure falls linearly along the chain: channel `c` is at
//!   `c_s² (ρ_L + (ρ_R − ρ_L)(c + ½)/n − 1)` (5e-5 of the drop; measured 2.6e-6).
//! * Mass (the chambers closed by walls): lattice plus pores minus the pores' initial
//!   content changes by less than 1e-13 relative per step, every step (measured 7e-15).
//! * Loads: the crack pressure's loads on the disks have zero net force and zero net
//!   moment to round-off (1e-12 of `Σ |F|` and of `Σ |F| · |x|`; measured 2.6e-16) every
//!   step, and each is
//!   `Σ ±p L n` over the disk's channels.
//! * A non-positive minimum aperture or viscosity is refused, naming it.

use porofrac_lbm::d2q9::CS2;
use porofrac_lbm::{Lattice, LatticeConfig, Obstacle, Shape, SideKind, Units};
use porofrac_particle_fluid::{
    BondCrackOptions, CouplingError, CouplingOptions, ParticleFluid, ParticleSolver, RigidDiskError,
};
use porofrac_particles::Disks;

const NX: usize = 110;
const NY: usize = 40;
const DX: f64 = 0.05;
const R: f64 = 3.0 * DX;
const GAP: f64 = 0.3 * DX;
/// Disks per row A (row B has one fewer).
const M: usize = 8;
/// Coupled steps, and the last ones averaged over (the chambers ring with sound).
const STEPS: usize = 6000;
const AVERAGE: usize = 3000;

/// Held disks with a bond list and the bonds broken so far.
struct Held {
    disks: Disks,
    bonds: Vec<[usize; 2]>,
    broken: Vec<[usize; 2]>,
}

impl ParticleSolver for Held {
    type Error = RigidDiskError;
    fn disks(&self) -> &Disks {
        &self.disks
    }
    fn stable_dt(&self) -> f64 {
        f64::INFINITY
    }
    fn advance(&mut self, _dt: f64, _external: &[[f64; 3]]) -> Result<(), RigidDiskError> {
        Ok(())
    }
    fn bond_pairs(&self) -> Vec<[usize; 2]> {
        self.bonds.clone()
    }
    fn broken_pairs(&self, from: usize, out: &mut Vec<[usize; 2]>) {
        out.extend_from_slice(&self.broken[from..]);
    }
}

/// Rows A (`M` disks, indices `0..M`) and B (`M − 1`, indices `M..2M−1`), centre
/// spacing `2R + GAP`, row A at height `y0`; all bonds of the pair of rows, and the
/// inter-row ones broken in order along the crack. Returns the model and the x of the
/// first and last centres of row A (m).
fn rows() -> (Held, f64, f64) {
    let d = 2.0 * R + GAP;
    let (x0, y0) = (1.5, 0.5 * NY as f64 * DX - 0.5 * 3f64.sqrt() * d * 0.5);
    let mut c = Vec::new();
    for m in 0..M {
        c.push([x0 + d * m as f64, y0]);
    }
    for m in 0..M - 1 {
        c.push([x0 + 0.5 * d + d * m as f64, y0 + 0.5 * 3f64.sqrt() * d]);
    }
    let radii = vec![R; c.len()];
    let disks = Disks::new(&c, &radii, 2600.0).unwrap();
    let (a, b) = (|m: usize| m, |m: usize| M + m);
    let mut bonds = Vec::new();
    let mut broken = Vec::new();
    for m in 0..M - 1 {
        bonds.push([a(m), a(m + 1)]);
        broken.push([a(m), b(m)]);
        broken.push([b(m), a(m + 1)]);
        if m + 1 < M - 1 {
            bonds.push([b(m), b(m + 1)]);
        }
    }
    bonds.extend_from_slice(&broken);
    (
        Held {
            disks,
            bonds,
            broken,
        },
        x0,
        x0 + d * (M - 1) as f64,
    )
}

/// The closed box with the wall from the centre of the first disk of row A to that of the
/// last, one box per chamber side; left chamber at density `rho_left`.
fn coupled(
    held: &Held,
    xa: f64,
    xb: f64,
    rho_left: f64,
    viscosity: Option<f64>,
    open: bool,
) -> Result<ParticleFluid, CouplingError> {
    let mut cfg = LatticeConfig::periodic(NX, NY, 0.8);
    cfg.periodic = [false, false];
    cfg.sides = [SideKind::Wall; 4];
    if open {
        cfg.sides[0] = SideKind::Pressure { density: rho_left };
        cfg.sides[1] = SideKind::Pressure { density: 1.0 };
    }
    let mut lat = Lattice::new(cfg).unwrap();
    let mid = 0.5 * (xa + xb) / DX;
    for (lo, hi) in [(xa / DX, mid), (mid, xb / DX)] {
        lat.add_obstacle(Obstacle {
            shape: Shape::aligned_box([lo, 0.0], [hi, NY as f64]),
            velocity: [0.0, 0.0],
            angular_velocity: 0.0,
        })
        .unwrap();
    }
    lat.init(|p| (if p[0] < mid { rho_left } else { 1.0 }, [0.0, 0.0]));
    let u = Units::from_viscosity(DX, 0.76, 1000.0, 0.8).unwrap();
    ParticleFluid::new(held, lat, u, [0.0, 0.0], CouplingOptions::default())?.with_crack_flow(
        held,
        BondCrackOptions {
            min_aperture: 1e-5,
            viscosity,
        },
    )
}

#[test]
fn a_crack_of_broken_bonds_carries_the_series_cubic_law_and_pushes_its_faces_apart() {
    let (mut held, xa, xb) = rows();
    let u = Units::from_viscosity(DX, 0.76, 1000.0, 0.8).unwrap();
    // a crack fluid of lattice viscosity 1e-3 (the lattice's is 0.1): K = 0.125 per step
    let nu_lat = 1e-3;
    let nu_si = nu_lat * DX * DX / u.dt;
    let mut pf = coupled(&held, xa, xb, 1.02, Some(nu_si), true).unwrap();
    let n = held.broken.len();
    let (w, l) = (GAP / DX, 2.0 * R / DX);
    let k = w.powi(3) * CS2 / (12.0 * nu_lat * l);
    // c_s² ρ₀ (Δx/Δt)²: Pa per unit of lattice density
    let scale = u.pressure_si(2.0);
    let mut worst_load: f64 = 0.0;
    // sums over the last AVERAGE steps: mouth densities, channel fluxes and pressures
    let mut mean_rho = [0.0; 2];
    let mut mean_q = vec![0.0; n];
    let mut mean_p = vec![0.0; n];
    for step in 0..STEPS {
        // the mouths' densities the step's exchange uses
        let rho_at = |pf: &ParticleFluid, c: usize, e: usize| {
            pf.crack_flow()
                .and_then(|f| f.mouth_nodes(c)[e])
                .map(|(i, j)| pf.lattice().moments(i, j).0)
        };
        let mouths = if step > 0 {
            Some((
                rho_at(&pf, 0, 0).or(rho_at(&pf, 0, 1)).unwrap(),
                rho_at(&pf, n - 1, 1).or(rho_at(&pf, n - 1, 0)).unwrap(),
            ))
        } else {
            None
        };
        pf.step(&mut held).unwrap();
        let c = pf.crack_flow().unwrap();
        // loads: zero net force and moment, each the sum of its channels' p L n
        let loads = c.loads();
        let d = held.disks();
        let (mut f, mut t, mut size, mut arm) = ([0.0; 2], 0.0, 0.0, 0.0);
        let mut rebuilt = vec![[0.0f64; 2]; d.len()];
        for ch in 0..n {
            let [i, j] = c.channel_disks(ch);
            let e = [d.x[j][0] - d.x[i][0], d.x[j][1] - d.x[i][1]];
            let len = e[0].hypot(e[1]);
            let g = c.pressure(ch) * 2.0 * R / len;
            for a in 0..2 {
                rebuilt[j][a] += g * e[a];
                rebuilt[i][a] -= g * e[a];
            }
        }
        for (q, lq) in loads.iter().enumerate() {
            f[0] += lq[0];
            f[1] += lq[1];
            t += d.x[q][0] * lq[1] - d.x[q][1] * lq[0];
            size += lq[0].hypot(lq[1]);
            arm += lq[0].hypot(lq[1]) * d.x[q][0].hypot(d.x[q][1]);
            assert_eq!(lq[2], 0.0);
            for a in 0..2 {
                assert!((lq[a] - rebuilt[q][a]).abs() <= 1e-12 * size.max(1.0));
            }
        }
        if size > 0.0 {
            worst_load = worst_load.max(f[0].hypot(f[1]) / size).max(t.abs() / arm);
        }
        if let Some(m) = mouths
            && step >= STEPS - AVERAGE
        {
            mean_rho[0] += m.0 / AVERAGE as f64;
            mean_rho[1] += m.1 / AVERAGE as f64;
            for ch in 0..n {
                mean_q[ch] += c.carried(ch) / AVERAGE as f64;
                mean_p[ch] += c.pressure(ch) / AVERAGE as f64;
            }
        }
    }
    let c = pf.crack_flow().unwrap();
    assert_eq!(c.channels(), n);
    assert_eq!(c.mouths(), 2, "mouths");
    assert_eq!(c.pores(), n - 1, "pores");
    let [rl, rr] = mean_rho;
    let q = k * (rl - rr) / n as f64;
    eprintln!(
        "series flux {q:e} (K = {k:.4}, Δρ = {:e}), carried {:e} … {:e}; \
         loads {worst_load:e}; sweeps {:?}",
        rl - rr,
        mean_q[0],
        mean_q[n - 1],
        c.stats()
    );
    assert!(rl - rr > 1e-3, "the chambers still differ: {rl} {rr}");
    let eq = (0..n)
        .map(|ch| (mean_q[ch] / q - 1.0).abs())
        .fold(0.0, f64::max);
    let ep = (0..n)
        .map(|ch| {
            let rho = rl + (rr - rl) * (ch as f64 + 0.5) / n as f64;
            (mean_p[ch] - (rho - 1.0) * scale).abs() / ((rl - rr) * scale)
        })
        .fold(0.0, f64::max);
    eprintln!("largest flux error {eq:e} (relative), pressure error {ep:e} (of the drop)");
    for ch in 0..n {
        assert!(
            (mean_q[ch] / q - 1.0).abs() < 5e-5,
            "channel {ch}: {:e} vs {q:e}",
            mean_q[ch]
        );
        let rho = rl + (rr - rl) * (ch as f64 + 0.5) / n as f64;
        let p = (rho - 1.0) * scale;
        assert!(
            (mean_p[ch] - p).abs() < 5e-5 * (rl - rr) * scale,
            "channel {ch}: {} vs {p}",
            mean_p[ch]
        );
    }
    assert!(worst_load < 1e-12, "loads {worst_load:e}");
}

#[test]
fn bad_crack_options_are_named() {
    let (held, xa, xb) = rows();
    let e = coupled(&held, xa, xb, 1.0, Some(-1.0), false).unwrap_err();
    assert!(e.to_string().starts_with("crack viscosity = -1"), "{e}");
    let mut cfg = LatticeConfig::periodic(NX, NY, 0.8);
    cfg.periodic = [true, true];
    let lat = Lattice::new(cfg).unwrap();
    let u = Units::from_viscosity(DX, 0.76, 1000.0, 0.8).unwrap();
    let pf = ParticleFluid::new(&held, lat, u, [0.0, 0.0], CouplingOptions::default()).unwrap();
    let e = pf
        .with_crack_flow(
            &held,
            BondCrackOptions {
                min_aperture: 0.0,
                viscosity: None,
            },
        )
        .unwrap_err();
    assert!(e.to_string().starts_with("crack min_aperture = 0"), "{e}");
}

#[test]
fn lattice_and_pores_keep_their_mass_every_step_in_a_closed_box() {
    let (mut held, xa, xb) = rows();
    let u = Units::from_viscosity(DX, 0.76, 1000.0, 0.8).unwrap();
    let nu_si = 1e-3 * DX * DX / u.dt;
    let mut pf = coupled(&held, xa, xb, 1.02, Some(nu_si), false).unwrap();
    let mut before: Option<f64> = None;
    let mut worst: f64 = 0.0;
    let mut moved = 0.0;
    for _ in 0..2000 {
        pf.step(&mut held).unwrap();
        let c = pf.crack_flow().unwrap();
        let total = pf.lattice().mass() + c.pore_mass() - c.created_mass();
        if let Some(m) = before {
            worst = worst.max((total - m).abs() / m);
        }
        before = Some(total);
        moved = c.carried(0);
    }
    let c = pf.crack_flow().unwrap();
    eprintln!(
        "closed box: largest relative mass change in a step {worst:e}; pores {:e} (created \
         {:e}); last flux {moved:e}",
        c.pore_mass(),
        c.created_mass()
    );
    assert!(moved > 1e-5, "the crack carries {moved:e}");
    assert!(c.pore_mass() > c.created_mass());
    assert!(worst < 1e-13, "mass {worst:e}");
}
