//! Disks coupled with the lattice Boltzmann fluid and heat, against independent
//! references:
//!
//! * a sedimenting disk reaches the speed, relative to the fluid, at which the same disk
//!   held fixed on the same lattice feels a drag equal to its buoyancy-corrected weight
//!   (within 3 %);
//! * fluid plus disks conserve momentum to round-off in a closed periodic box (with
//!   two-step loads, counting the half-load still owed to the disk);
//! * a hot disk cooling in fluid: every joule is accounted for by the heat books;
//! * a disk below the resolution limit is an error naming it.

use porofrac_lbm::{
    Collision, Lattice, LatticeConfig, Obstacle, Shape, SideKind, ThermalSide, Units,
};
use porofrac_particle_fluid::{
    CouplingError, CouplingOptions, LoadAveraging, ParticleFluid, RigidDisks, ThermalSetup,
};
use porofrac_particles::Disks;

const DX: f64 = 1e-4;
const NU: f64 = 1e-6;
const RHO: f64 = 1000.0;

fn units(tau: f64) -> Units {
    Units::from_viscosity(DX, NU, RHO, tau).unwrap()
}

/// Mean fluid velocity (lattice units).
fn mean_fluid_velocity(l: &Lattice) -> [f64; 2] {
    let p = l.momentum();
    let m = l.mass();
    [p[0] / m, p[1] / m]
}

#[test]
fn sedimenting_disk_reaches_the_fixed_disk_terminal_speed() {
    // 64² periodic box, disk of radius 6.3 spacings, density ratio 2; the fluid carries a
    // uniform body force that balances the disk's net weight, so the box does not
    // accelerate (the usual periodic sedimentation set-up).
    let (n, tau) = (64usize, 1.0);
    let u = units(tau);
    let r = 6.3 * DX;
    let rho_s = 2.0 * RHO;
    let g_lattice = 1.0e-4;
    let g = g_lattice * DX / (u.dt * u.dt);
    let x0 = [30.2 * DX, 40.7 * DX];
    let disks = Disks::new(&[x0], &[r], rho_s).unwrap();
    let mut solver = RigidDisks::new(disks);
    solver.gravity = [0.0, -g];
    solver.fluid_density = RHO;
    let weight = solver.net_weight(0)[1]; // N/m, negative
    let fluid_area = (n * n) as f64 * DX * DX - std::f64::consts::PI * r * r;
    let accel = -weight / (RHO * fluid_area); // m/s², upwards
    let mut cfg = LatticeConfig::periodic(n, n, tau);
    cfg.accel = [0.0, u.acceleration(accel)];
    let lat = Lattice::new(cfg.clone()).unwrap();
    let mut sim =
        ParticleFluid::new(&solver, lat, u, [0.0, 0.0], CouplingOptions::default()).unwrap();
    let (steps, window) = (7000, 2500);
    let mut rel = 0.0;
    let mut samples = 0;
    for s in 0..steps {
        sim.step(&mut solver).unwrap();
        if s >= steps - window && s % 10 == 0 {
            let v = u.velocity(solver.disks.v[0][1]);
            let uf = mean_fluid_velocity(sim.lattice())[1];
            rel += v - uf;
            samples += 1;
        }
    }
    let settling = rel / samples as f64;

    // The reference: the same disk held fixed in the same box, the fluid driven by the same
    // body force; at steady state its drag is the net weight, at relative speed -ū.
    let mut fixed = Lattice::new(cfg).unwrap();
    let k = fixed
        .add_obstacle(Obstacle {
            shape: Shape::Circle {
                center: [x0[0] / DX, x0[1] / DX],
                radius: r / DX,
            },
            velocity: [0.0, 0.0],
            angular_velocity: 0.0,
        })
        .unwrap();
    // the mean flow relaxes with time constant M_fluid/K ≈ 2200 steps: 20000 steps leave
    // e^-9 of the start-up
    for _ in 0..20000 {
        fixed.step().unwrap();
    }
    let reference = -mean_fluid_velocity(&fixed)[1];
    let drag = u.force_si(fixed.force(k)[1]);
    eprintln!(
        "settling speed {settling:.6e}, fixed-disk speed {reference:.6e} (lattice), drag {drag:.4e} N/m vs weight {weight:.4e}"
    );
    // the reference is converged: its drag balances the weight
    assert!((drag / -weight - 1.0).abs() < 0.01, "{drag} vs {weight}");
    // Stokes regime (Re ≈ 0.4): drag ∝ speed, so the drag at the settling speed is the
    // weight times settling/reference.
    assert!(
        (settling / reference - 1.0).abs() < 0.03,
        "settling {settling} vs fixed-disk {reference}"
    );
}

#[test]
fn fluid_and_disk_momentum_is_conserved_in_a_closed_periodic_box() {
    // A disk launched through fluid at rest, crossing the periodic sides; no gravity.
    let cases = [
        (Collision::Bgk, LoadAveraging::Step),
        (Collision::trt(), LoadAveraging::Step),
        (Collision::Bgk, LoadAveraging::TwoSteps),
    ];
    for (collision, loads) in cases {
        let (n, tau) = (48usize, 0.8);
        let u = units(tau);
        let mut cfg = LatticeConfig::periodic(n, n, tau);
        cfg.collision = collision;
        let lat = Lattice::new(cfg).unwrap();
        let mut disks = Disks::new(&[[45.1 * DX, 20.6 * DX]], &[5.3 * DX], 1.5 * RHO).unwrap();
        disks.v[0] = [u.velocity_si(0.04), u.velocity_si(0.015)];
        disks.omega[0] = 0.005 / u.dt;
        let m = disks.mass[0];
        let p0 = [m * disks.v[0][0], m * disks.v[0][1]];
        let mut solver = RigidDisks::new(disks);
        let options = CouplingOptions {
            loads,
            ..CouplingOptions::default()
        };
        let mut sim = ParticleFluid::new(&solver, lat, u, [0.0, 0.0], options).unwrap();
        let scale = (p0[0] * p0[0] + p0[1] * p0[1]).sqrt();
        let mut worst: f64 = 0.0;
        for _ in 0..600 {
            sim.step(&mut solver).unwrap();
            // with two-step loads, half the last load is still owed to the disk
            let (pf, owed) = (sim.fluid_momentum(), sim.pending_impulse());
            let v = solver.disks.v[0];
            for a in 0..2 {
                worst = worst.max((pf[a] + owed[a] + m * v[a] - p0[a]).abs() / scale);
            }
        }
        let v = solver.disks.v[0];
        eprintln!(
            "{collision:?} {loads:?}: momentum defect {worst:.2e}; disk speed now {v:?}, x {:?}",
            solver.disks.x[0]
        );
        // the disk gave most of its momentum to the fluid, and crossed a side
        assert!(v[0].abs() < 0.5 * p0[0] / m);
        assert!(solver.disks.x[0][0] > n as f64 * DX);
        assert!(
            worst < 1e-12,
            "{collision:?} {loads:?}: relative momentum defect {worst:e}"
        );
    }
}

#[test]
fn a_hot_moving_disk_cools_and_every_joule_is_booked() {
    // Closed box with no-slip walls held at 0 °C; a disk at 100 °C launched through fluid
    // at 0 °C. The solid conducts four times better than the fluid.
    let (n, tau) = (48usize, 0.8);
    let u = units(tau);
    let mut cfg = LatticeConfig::periodic(n, n, tau);
    cfg.periodic = [false, false];
    cfg.sides = [SideKind::Wall; 4];
    let lat = Lattice::new(cfg).unwrap();
    let mut disks = Disks::new(&[[15.4 * DX, 22.7 * DX]], &[6.2 * DX], 2.0 * RHO).unwrap();
    disks.v[0] = [u.velocity_si(0.03), 0.0];
    let chi = 1.4e-7;
    let setup = ThermalSetup {
        diffusivity: chi,
        solid_diffusivity: 4.0 * chi,
        sides: [ThermalSide::Temperature(0.0); 4],
    };
    let mut solver = RigidDisks::new(disks);
    let mut sim = ParticleFluid::new(&solver, lat, u, [0.0, 0.0], CouplingOptions::default())
        .unwrap()
        .with_thermal(setup, |_| 0.0, &[100.0])
        .unwrap();
    let h0 = *sim.heat();
    assert!(h0.particles > 0.0 && h0.fluid == 0.0);
    let mut worst: f64 = 0.0;
    let mut worst_particle: f64 = 0.0;
    for _ in 0..1500 {
        sim.step(&mut solver).unwrap();
        let h = sim.heat();
        worst = worst.max(h.defect().abs() / h0.initial);
        worst_particle = worst_particle.max(h.particle_defect().abs() / h0.initial);
    }
    let h = *sim.heat();
    let t = sim.particle_temperature(0).unwrap();
    eprintln!(
        "heat: disk {:.4e} → {:.4e} J/m (T = {t:.2} °C), fluid {:.4e}, out through walls {:.4e}, through the disk surface {:.4e}, carried {:.4e}; defects {worst:.1e} {worst_particle:.1e}",
        h0.particles, h.particles, h.fluid, -h.sides_in, h.from_particles, h.carried
    );
    // the disk cooled, the fluid warmed, the walls took heat out
    assert!(h.particles < 0.8 * h0.particles && t < 80.0);
    assert!(h.fluid > 0.0 && h.sides_in < 0.0);
    // the moving disk took and left heat with the nodes it crossed: a real term
    assert!(h.carried.abs() > 1e-4 * h0.initial);
    // books: total = start + side inflow; disk = start − surface outflow + carried
    assert!(worst < 1e-12, "total heat defect {worst:e}");
    assert!(
        worst_particle < 1e-12,
        "disk heat defect {worst_particle:e}"
    );
}

#[test]
fn a_disk_below_two_spacings_is_an_error_naming_it() {
    let u = units(0.8);
    let lat = || Lattice::new(LatticeConfig::periodic(32, 32, 0.8)).unwrap();
    let disks = Disks::new(
        &[[8.0 * DX, 8.0 * DX], [20.0 * DX, 20.0 * DX]],
        &[3.0 * DX, 1.9 * DX],
        RHO,
    )
    .unwrap();
    let err = ParticleFluid::new(
        &RigidDisks::new(disks.clone()),
        lat(),
        u,
        [0.0, 0.0],
        CouplingOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, CouplingError::TooSmall { particle: 1, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("particle 1"), "{err}");
    // at two spacings it is accepted
    let mut ok = disks;
    ok.r[1] = 2.0 * DX;
    assert!(
        ParticleFluid::new(
            &RigidDisks::new(ok),
            lat(),
            u,
            [0.0, 0.0],
            CouplingOptions::default()
        )
        .is_ok()
    );
}

#[test]
fn injection_adds_the_ramped_mass_and_reaches_the_ramped_pressure() {
    use porofrac_particle_fluid::InjectionControl;
    let (n, tau) = (40usize, 0.8);
    let u = units(tau);
    let mut cfg = LatticeConfig::periodic(n, n, tau);
    cfg.periodic = [false, false];
    let disks = Disks::new(&[[10.0 * DX, 10.0 * DX]], &[3.0 * DX], 2.0 * RHO).unwrap();
    let centre = [20.0 * DX, 20.0 * DX];
    // rate control: Q(t) = Q_max min(t/T, 1); no disk, so no interpolated bounce-back
    // (which does not conserve mass exactly) and all mass stays in the fluid
    let (q_max, ramp) = (1e-6, 100.0 * u.dt);
    let mut none = RigidDisks::new(Disks::new(&[], &[], 2.0 * RHO).unwrap());
    let mut sim = ParticleFluid::new(
        &none,
        Lattice::new(cfg.clone()).unwrap(),
        u,
        [0.0, 0.0],
        CouplingOptions::default(),
    )
    .unwrap()
    .with_injection(
        centre,
        2.0 * DX,
        InjectionControl::Rate {
            peak: q_max,
            ramp_time: ramp,
        },
    )
    .unwrap();
    let m0 = sim.lattice().mass();
    let steps = 300;
    for _ in 0..steps {
        sim.step(&mut none).unwrap();
    }
    // ∫Q dt of the steps' rates, Q taken at the start of each step
    let want: f64 = (0..steps)
        .map(|s| q_max * (s as f64 * u.dt / ramp).min(1.0) * u.dt)
        .sum();
    let to_si = RHO * DX * DX;
    let injected = sim.lattice().injected_mass() * to_si;
    assert!(
        (injected / want - 1.0).abs() < 1e-12,
        "{injected} vs {want}"
    );
    // and it is all in the fluid, to the round-off of summing the box's mass
    let gained = (sim.lattice().mass() - m0) * to_si;
    assert!(
        (gained - want).abs() < 1e-12 * m0 * to_si,
        "{gained} vs {want}"
    );
    // the analytic ramp integral, to the first-order error of sampling at step starts
    let analytic = q_max * (steps as f64 * u.dt - 0.5 * ramp);
    assert!((injected / analytic - 1.0).abs() < 0.01);

    // pressure control in the closed box: the source nodes follow the ramp
    let peak = 0.05; // Pa: lattice density 1 + 0.015 at this spacing and time step
    let mut solver = RigidDisks::new(disks);
    let mut sim = ParticleFluid::new(
        &solver,
        Lattice::new(cfg).unwrap(),
        u,
        [0.0, 0.0],
        CouplingOptions::default(),
    )
    .unwrap()
    .with_injection(
        centre,
        2.0 * DX,
        InjectionControl::Pressure {
            peak,
            ramp_time: 400.0 * u.dt,
            gain: 1.0,
        },
    )
    .unwrap();
    // with gain 1 the 12 source nodes fill the 1600-node box with a lag of about
    // 1600/12 ≈ 130 steps
    for _ in 0..2000 {
        sim.step(&mut solver).unwrap();
    }
    let inj = sim.injection().unwrap();
    let p = inj.pressure(sim.lattice(), sim.units());
    assert_eq!(inj.target_pressure(sim.time()), Some(peak));
    assert!(
        (p / peak - 1.0).abs() < 0.02,
        "source pressure {p} Pa vs {peak}"
    );
    // the whole box was pressurised: the mean density rose by about the target
    let mean = sim.lattice().mass() / sim.lattice().fluid_nodes() as f64;
    let p_mean = sim.units().pressure_si(mean);
    assert!(
        (p_mean / peak - 1.0).abs() < 0.05,
        "box pressure {p_mean} Pa vs {peak}"
    );
}
