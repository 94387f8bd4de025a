//! [`LatticeSolid`]: bonded disks advanced by velocity Verlet.
//!
//! One step of size Δt, with `F` the bond, contact, gravity and applied forces at the
//! current positions and `E` the caller's external forces of the step:
//!
//! 1. `v ← v + ½Δt (F + E)/m`, `ω ← ω + ½Δt (M + E_θ)/I` (damped, see
//!    [`crate::law::Damping`]; prescribed motions overwrite);
//! 2. `x ← x + Δt v`, `θ ← θ + Δt ω` (the increments feed the shear springs);
//! 3. bond forces at the new positions (in parallel over bonds), breakage (in bond
//!    order), contact forces (in parallel over pairs), and the sum per particle by
//!    gathering over its bonds and contacts (in parallel over particles: no atomics, the
//!    result does not depend on the thread count);
//! 4. `v ← v + ½Δt (F + E)/m`, `ω` alike.
//!
//! Without damping and external forces this is the symplectic velocity Verlet scheme.
//!
//! # Stable time step
//!
//! The linearised system `M ü = −K u` (translations and rotations) is stable under
//! velocity Verlet for `Δt < 2/ω_max`. [`LatticeSolid::stable_dt`] bounds
//! `ω_max² = λ_max(M^{-1/2} K M^{-1/2})` by Gershgorin's theorem: per row, the absolute
//! sum of the scaled stiffness entries of every bond (and of every touching pair with
//! the contact law) of the particle, where a 2×2 spring block `k_n nnᵀ + k_s ttᵀ` counts
//! `k_n + k_s` per row and the shear spring couples translations to rotations with the
//! lever `R`. With viscous damping at rate c, `Δt < (2/ω)(√(1+ζ²) − ζ)`, `ζ = c/(2ω)`.
//! A step above it is refused ([`crate::LsmError::TimeStep`]).

use crate::bond::{Bond, BondForce, BreakMode, BrokenBond};
use crate::contact::{ContactForce, Pair};
use crate::law::{BondLaw, ContactLaw, Damping, Motion};
use crate::{LsmError, PressureWall, WallFaces};
use porofrac_particles::Disks;
use porofrac_particles::cells::{CellList, max_radius};
use rayon::prelude::*;

pub mod state;

/// Problems smaller than this run on the calling thread (no pool overhead).
const PAR_MIN: usize = 4096;

/// How a lattice solid is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LsmSpec {
    /// Bond springs and strengths.
    pub bonds: BondLaw,
    /// Contacts between unbonded disks.
    pub contacts: ContactLaw,
    /// Disks closer than `(R_i + R_j)(1 + bond_tolerance)` are bonded (0.01).
    pub bond_tolerance: f64,
    /// Largest initial overlap allowed, as a fraction of the smaller radius (0.01).
    pub overlap_tolerance: f64,
    /// Damping.
    pub damping: Damping,
    /// Gravity (m/s²).
    pub gravity: [f64; 2],
}

impl LsmSpec {
    /// Bonds of `law`, contacts with the same stiffnesses and μ = 0.6, no damping, no
    /// gravity.
    pub fn new(law: BondLaw) -> Self {
        Self {
            bonds: law,
            contacts: ContactLaw::like_bonds(&law),
            bond_tolerance: 0.01,
            overlap_tolerance: 0.01,
            damping: Damping::None,
            gravity: [0.0; 2],
        }
    }
}

/// What a step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Time at the end of the step (s).
    pub time: f64,
    /// Bonds broken in this step.
    pub broken: usize,
    /// Intact bonds after the step.
    pub intact: usize,
    /// Touching unbonded pairs after the step.
    pub contacts: usize,
}

/// Per-particle lists of links (bond or contact indices, side in the low bit) as
/// flat arrays with offsets.
#[derive(Clone, Debug, Default)]
struct Adjacency {
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Adjacency {
    fn build(&mut self, n: usize, links: impl Iterator<Item = (u32, u32)> + Clone) {
        self.start.clear();
        self.start.resize(n + 1, 0);
        for (i, j) in links.clone() {
            self.start[i as usize + 1] += 1;
            self.start[j as usize + 1] += 1;
        }
        for k in 0..n {
            self.start[k + 1] += self.start[k];
        }
        self.items.clear();
        self.items.resize(self.start[n] as usize, 0);
        let mut next: Vec<u32> = self.start[..n].to_vec();
        for (b, (i, j)) in links.enumerate() {
            for (p, side) in [(i, 0u32), (j, 1u32)] {
                let s = &mut next[p as usize];
                self.items[*s as usize] = (b as u32) << 1 | side;
                *s += 1;
            }
        }
    }

    #[inline]
    fn of(&self, i: usize) -> &[u32] {
        &self.items[self.start[i] as usize..self.start[i + 1] as usize]
    }
}

/// Bonded disks (the ESyS-Particle bond model). See the module docs for the scheme.
#[derive(Clone, Debug)]
pub struct LatticeSolid {
    disks: Disks,
    spec: LsmSpec,
    motion: Vec<Motion>,
    bonds: Vec<Bond>,
    bond_force: Vec<BondForce>,
    bond_break: Vec<Option<BreakMode>>,
    bond_adj: Adjacency,
    pairs: Vec<Pair>,
    pair_force: Vec<ContactForce>,
    pair_adj: Adjacency,
    cells: CellList,
    scratch_pairs: Vec<(u32, u32)>,
    scratch: Vec<Pair>,
    x_build: Vec<[f64; 2]>,
    skin: f64,
    force: Vec<[f64; 3]>,
    applied: Vec<[f64; 3]>,
    loads: Vec<[f64; 3]>,
    walls: Vec<PressureWall>,
    dx: Vec<[f64; 3]>,
    time: f64,
    broken: Vec<BrokenBond>,
    stable_dt: f64,
    bond_updates: u64,
    contact_updates: u64,
}

impl LatticeSolid {
    /// Bond the disks closer than the bond tolerance and compute the forces of the
    /// initial configuration. Errors name the bad parameter or the overlapping pair.
    pub fn new(disks: Disks, spec: LsmSpec) -> Result<Self, LsmError> {
        spec.bonds.check()?;
        spec.contacts.check()?;
        spec.damping.check()?;
        if !(spec.bond_tolerance.is_finite() && spec.bond_tolerance >= 0.0) {
            return Err(LsmError::bad(
                "bond_tolerance",
                spec.bond_tolerance,
                "must be non-negative",
            ));
        }
        if !(spec.overlap_tolerance.is_finite() && spec.overlap_tolerance >= 0.0) {
            return Err(LsmError::bad(
                "overlap_tolerance",
                spec.overlap_tolerance,
                "must be non-negative",
            ));
        }
        if !(spec.gravity[0].is_finite() && spec.gravity[1].is_finite()) {
            return Err(LsmError::bad("gravity", spec.gravity[0], "must be finite"));
        }
        let n = disks.len();
        if n == 0 {
            return Err(LsmError::bad("disks", 0.0, "no particles"));
        }
        for i in 0..n {
            let ok = disks.x[i].iter().chain(&disks.v[i]).all(|v| v.is_finite())
                && disks.r[i].is_finite()
                && disks.r[i] > 0.0;
            if !ok {
                return Err(LsmError::NotFinite {
                    index: i,
                    what: "centre, velocity or radius",
                });
            }
        }
        let rmax = max_radius(&disks.r);
        let rmin = disks.radius_range()[0];
        let mut cells = CellList::new();
        let alert = spec.bond_tolerance * 2.0 * rmax;
        cells.build(&disks.x, 2.0 * rmax + alert);
        let mut near = Vec::new();
        cells.pairs(&disks.x, &disks.r, alert, &mut near);
        let mut bonds = Vec::new();
        for &(i, j) in &near {
            let (i, j) = (i as usize, j as usize);
            let (ri, rj) = (disks.r[i], disks.r[j]);
            let d = crate::bond::dist(disks.x[i], disks.x[j]);
            let overlap = ri + rj - d;
            let allowed = spec.overlap_tolerance * ri.min(rj);
            if overlap > allowed {
                return Err(LsmError::Overlap {
                    i,
                    j,
                    overlap,
                    allowed,
                });
            }
            if d <= (ri + rj) * (1.0 + spec.bond_tolerance) {
                bonds.push(Bond::new(&disks, i, j, &spec.bonds));
            }
        }
        let mut bond_adj = Adjacency::default();
        bond_adj.build(n, bonds.iter().map(|b| (b.i, b.j)));
        let mut s = Self {
            motion: vec![Motion::Free; n],
            bond_force: vec![BondForce::default(); bonds.len()],
            bond_break: vec![None; bonds.len()],
            bonds,
            bond_adj,
            pairs: Vec::new(),
            pair_force: Vec::new(),
            pair_adj: Adjacency::default(),
            cells,
            scratch_pairs: near,
            scratch: Vec::new(),
            x_build: Vec::new(),
            skin: 0.2 * rmin,
            force: vec![[0.0; 3]; n],
            applied: vec![[0.0; 3]; n],
            loads: vec![[0.0; 3]; n],
            walls: Vec::new(),
            dx: vec![[0.0; 3]; n],
            time: 0.0,
            broken: Vec::new(),
            stable_dt: 0.0,
            bond_updates: 0,
            contact_updates: 0,
            disks,
            spec,
        };
        s.rebuild_pairs();
        s.stable_dt = s.critical_dt();
        s.compute_forces();
        Ok(s)
    }

    /// The disks.
    pub fn disks(&self) -> &porofrac_particles::Disks {
        &self.disks
    }

    /// The largest time step the scheme is stable with (s); see the module docs.
    pub fn stable_dt(&self) -> f64 {
        self.stable_dt
    }

    /// The bonds broken so far, in order of breakage.
    pub fn broken(&self) -> &[BrokenBond] {
        &self.broken
    }

    /// All bonds (intact or not).
    pub fn bonds(&self) -> &[Bond] {
        &self.bonds
    }

    /// The bond forces of the last step (zero for broken bonds).
    pub fn bond_forces(&self) -> &[BondForce] {
        &self.bond_force
    }

    /// The candidate contact pairs and their last forces.
    pub fn contacts(&self) -> (&[Pair], &[ContactForce]) {
        (&self.pairs, &self.pair_force)
    }

    /// Number of intact bonds.
    pub fn intact_bonds(&self) -> usize {
        self.bonds.iter().filter(|b| b.intact).count()
    }

    /// Unbonded pairs in contact at the last step.
    pub fn touching(&self) -> usize {
        self.pair_force.iter().filter(|f| f.fn_ > 0.0).count()
    }

    /// The parameters.
    pub fn spec(&self) -> &LsmSpec {
        &self.spec
    }

    /// Time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Bond and contact force evaluations so far.
    pub fn updates(&self) -> (u64, u64) {
        (self.bond_updates, self.contact_updates)
    }

    /// The force and moment `[f_x, f_y, m]` on each particle from its bonds, contacts,
    /// gravity and applied loads at the last step (external forces of `step` not
    /// included): the reaction on a driven particle.
    pub fn forces(&self) -> &[[f64; 3]] {
        &self.force
    }

    /// Set how particle `i` moves.
    pub fn set_motion(&mut self, i: usize, m: Motion) {
        self.motion[i] = m;
    }

    /// How particle `i` moves.
    pub fn motion(&self, i: usize) -> Motion {
        self.motion[i]
    }

    /// A force and moment `[f_x, f_y, m]` on particle `i` kept until changed (N/m, N·m/m).
    pub fn set_applied(&mut self, i: usize, f: [f64; 3]) -> Result<(), LsmError> {
        if !f.iter().all(|v| v.is_finite()) {
            return Err(LsmError::NotFinite {
                index: i,
                what: "applied force",
            });
        }
        self.applied[i] = f;
        self.refresh_loads();
        Ok(())
    }

    /// A pressure wall on the circular hole of `centre` and `radius` (see
    /// [`PressureWall`]); returns its index for [`Self::set_wall_pressure`].
    pub fn add_pressure_wall(&mut self, centre: [f64; 2], radius: f64) -> Result<usize, LsmError> {
        self.add_pressure_wall_on(centre, radius, WallFaces::Rays)
    }

    /// A pressure wall on the circular hole of `centre` and `radius` loading `faces`
    /// ([`PressureWall::with_faces`]); returns its index for [`Self::set_wall_pressure`].
    pub fn add_pressure_wall_on(
        &mut self,
        centre: [f64; 2],
        radius: f64,
        faces: WallFaces,
    ) -> Result<usize, LsmError> {
        let w = PressureWall::with_faces(&self.disks, centre, radius, faces)?;
        self.walls.push(w);
        Ok(self.walls.len() - 1)
    }

    /// The pressure walls.
    pub fn walls(&self) -> &[PressureWall] {
        &self.walls
    }

    /// Set the pressure (Pa) of wall `k`.
    pub fn set_wall_pressure(&mut self, k: usize, p: f64) -> Result<(), LsmError> {
        if !p.is_finite() {
            return Err(LsmError::bad("pressure", p, "must be finite"));
        }
        self.walls[k].pressure = p;
        self.refresh_loads();
        Ok(())
    }

    fn refresh_loads(&mut self) {
        let old = std::mem::take(&mut self.loads);
        self.loads = self.applied.clone();
        for w in &self.walls {
            for &(i, a) in &w.members {
                let l = &mut self.loads[i as usize];
                l[0] += w.pressure * a[0];
                l[1] += w.pressure * a[1];
                l[2] += w.pressure * a[2];
            }
        }
        // The force of the current configuration follows the new loads.
        for ((f, new), old) in self.force.iter_mut().zip(&self.loads).zip(&old) {
            for c in 0..3 {
                f[c] += new[c] - old[c];
            }
        }
    }

    /// Cut a notch: break every intact bond whose centre line `x_i → x_j` crosses the
    /// segment `from → to` (m), as a saw cut would. The cut bonds are returned (contact
    /// point, time now, recorded as [`BreakMode::Tensile`]: a notch is an opened crack)
    /// and are *not* added to [`Self::broken`], which keeps the bonds broken by the load.
    /// Their forces leave the particles at the next step. Errors on a non-finite or
    /// zero-length segment.
    pub fn cut(&mut self, from: [f64; 2], to: [f64; 2]) -> Result<Vec<BrokenBond>, LsmError> {
        if !from.iter().chain(&to).all(|v| v.is_finite()) {
            return Err(LsmError::bad("from, to", f64::NAN, "must be finite"));
        }
        let s = [to[0] - from[0], to[1] - from[1]];
        if s[0] == 0.0 && s[1] == 0.0 {
            return Err(LsmError::bad("to", 0.0, "the cut has no length"));
        }
        let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
        let mut cut = Vec::new();
        for (k, b) in self.bonds.iter_mut().enumerate() {
            if !b.intact {
                continue;
            }
            let (i, j) = (b.i as usize, b.j as usize);
            let (xi, xj) = (self.disks.x[i], self.disks.x[j]);
            let e = [xj[0] - xi[0], xj[1] - xi[1]];
            let den = cross(e, s);
            if den == 0.0 {
                continue;
            }
            let w = [from[0] - xi[0], from[1] - xi[1]];
            // x_i + t e = from + u s
            let t = cross(w, s) / den;
            let u = cross(w, e) / den;
            if !((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)) {
                continue;
            }
            b.intact = false;
            self.bond_force[k] = BondForce::default();
            let f = self.disks.r[i] / (self.disks.r[i] + self.disks.r[j]);
            cut.push(BrokenBond {
                time: self.time,
                i,
                j,
                x: xi[0] + f * e[0],
                y: xi[1] + f * e[1],
                mode: BreakMode::Tensile,
            });
        }
        Ok(cut)
    }

    /// Total elastic energy of the intact bonds (J/m).
    pub fn bond_energy(&self) -> f64 {
        let law = &self.spec.bonds;
        self.bonds
            .iter()
            .filter(|b| b.intact)
            .map(|b| b.energy(&self.disks, law))
            .sum()
    }

    /// Advance by `dt` with the external forces `external[i] = [f_x, f_y, torque]`
    /// (N/m, N·m/m) added to particle i's forces during the step (empty: none).
    pub fn step(&mut self, dt: f64, external: &[[f64; 3]]) -> Result<StepReport, LsmError> {
        let n = self.disks.len();
        if !(dt.is_finite() && dt > 0.0) {
            return Err(LsmError::bad("dt", dt, "must be a positive finite number"));
        }
        if dt > self.stable_dt {
            return Err(LsmError::TimeStep {
                dt,
                stable: self.stable_dt,
            });
        }
        if !external.is_empty() && external.len() != n {
            return Err(LsmError::External {
                got: external.len(),
                expected: n,
            });
        }
        if let Some(i) = external
            .iter()
            .position(|e| !e.iter().all(|v| v.is_finite()))
        {
            return Err(LsmError::NotFinite {
                index: i,
                what: "external force",
            });
        }
        self.kick(0.5 * dt, external);
        self.drift(dt);
        let moved = self
            .disks
            .x
            .iter()
            .zip(&self.x_build)
            .any(|(a, b)| crate::bond::dist(*a, *b) > 0.5 * self.skin);
        if moved {
            self.rebuild_pairs();
        }
        let broken = self.compute_forces();
        self.kick(0.5 * dt, external);
        self.time += dt;
        if let Some(i) = (0..n).find(|&i| {
            !(self.disks.v[i][0].is_finite()
                && self.disks.v[i][1].is_finite()
                && self.disks.omega[i].is_finite())
        }) {
            return Err(LsmError::NotFinite {
                index: i,
                what: "velocity (the step diverged)",
            });
        }
        Ok(StepReport {
            time: self.time,
            broken,
            intact: self.intact_bonds(),
            contacts: self.touching(),
        })
    }

    fn kick(&mut self, h: f64, external: &[[f64; 3]]) {
        let d = &mut self.disks;
        let damping = self.spec.damping;
        for i in 0..d.len() {
            let mut f = self.force[i];
            if let Some(e) = external.get(i) {
                f = [f[0] + e[0], f[1] + e[1], f[2] + e[2]];
            }
            let (m, inertia) = (d.mass[i], d.inertia[i]);
            let free = |v: f64, f: f64, m: f64| {
                if m.is_finite() {
                    v + h * damping.apply(f, v, m) / m
                } else {
                    v
                }
            };
            match self.motion[i] {
                Motion::Free => {
                    d.v[i][0] = free(d.v[i][0], f[0], m);
                    d.v[i][1] = free(d.v[i][1], f[1], m);
                    d.omega[i] = free(d.omega[i], f[2], inertia);
                }
                Motion::Fixed => {
                    d.v[i] = [0.0; 2];
                    d.omega[i] = 0.0;
                }
                Motion::Velocity(u) => {
                    d.v[i] = u;
                    d.omega[i] = 0.0;
                }
                Motion::Axis { axis, velocity } => {
                    let other = 1 - axis;
                    d.v[i][axis] = velocity;
                    d.v[i][other] = free(d.v[i][other], f[other], m);
                    d.omega[i] = free(d.omega[i], f[2], inertia);
                }
            }
        }
    }

    fn drift(&mut self, dt: f64) {
        let d = &mut self.disks;
        for i in 0..d.len() {
            let s = [dt * d.v[i][0], dt * d.v[i][1], dt * d.omega[i]];
            d.x[i][0] += s[0];
            d.x[i][1] += s[1];
            d.angle[i] += s[2];
            self.dx[i] = s;
        }
    }

    /// The per-disk index of the candidate contacts (after the pairs were put back).
    pub(crate) fn rebuild_pair_adjacency(&mut self) {
        self.pair_adj
            .build(self.disks.len(), self.pairs.iter().map(|p| (p.i, p.j)));
    }

    /// Rebuild the Verlet list of candidate contacts, keeping the tangential springs of
    /// the pairs already present.
    fn rebuild_pairs(&mut self) {
        let d = &self.disks;
        let rmax = max_radius(&d.r);
        self.cells.build(&d.x, 2.0 * rmax + self.skin);
        self.cells
            .pairs(&d.x, &d.r, self.skin, &mut self.scratch_pairs);
        std::mem::swap(&mut self.pairs, &mut self.scratch);
        self.pairs.clear();
        let mut old = 0;
        let mut bond = 0;
        for &(i, j) in &self.scratch_pairs {
            while old < self.scratch.len() && (self.scratch[old].i, self.scratch[old].j) < (i, j) {
                old += 1;
            }
            let ut = match self.scratch.get(old) {
                Some(p) if (p.i, p.j) == (i, j) => p.ut,
                _ => 0.0,
            };
            while bond < self.bonds.len() && (self.bonds[bond].i, self.bonds[bond].j) < (i, j) {
                bond += 1;
            }
            let b = match self.bonds.get(bond) {
                Some(b) if (b.i, b.j) == (i, j) => bond as u32,
                _ => u32::MAX,
            };
            self.pairs.push(Pair { i, j, bond: b, ut });
        }
        self.pair_force.clear();
        self.pair_force
            .resize(self.pairs.len(), ContactForce::default());
        self.pair_adj
            .build(d.len(), self.pairs.iter().map(|p| (p.i, p.j)));
        self.x_build.clear();
        self.x_build.extend_from_slice(&d.x);
    }

    /// Bond forces, breakage, contact forces and the sum per particle; returns the
    /// number of bonds broken.
    fn compute_forces(&mut self) -> usize {
        let disks = &self.disks;
        let dx = &self.dx;
        let law = self.spec.bonds;
        let tan_phi = law.friction_angle.tan();
        let kernel = |(b, (f, brk)): (&mut Bond, (&mut BondForce, &mut Option<BreakMode>))| {
            if b.intact {
                *f = b.update(disks, dx, &law);
                *brk = b.breaks_with(f, tan_phi);
            } else {
                *f = BondForce::default();
                *brk = None;
            }
        };
        if self.bonds.len() >= PAR_MIN {
            self.bonds
                .par_iter_mut()
                .zip(
                    self.bond_force
                        .par_iter_mut()
                        .zip(self.bond_break.par_iter_mut()),
                )
                .with_min_len(1024)
                .for_each(kernel);
        } else {
            self.bonds
                .iter_mut()
                .zip(self.bond_force.iter_mut().zip(self.bond_break.iter_mut()))
                .for_each(kernel);
        }
        let mut broken = 0;
        for k in 0..self.bonds.len() {
            if let Some(mode) = self.bond_break[k] {
                let b = &mut self.bonds[k];
                b.intact = false;
                self.bond_force[k] = BondForce::default();
                let (i, j) = (b.i as usize, b.j as usize);
                let (xi, xj) = (disks.x[i], disks.x[j]);
                let s = disks.r[i] / (disks.r[i] + disks.r[j]);
                self.broken.push(BrokenBond {
                    time: self.time,
                    i,
                    j,
                    x: xi[0] + s * (xj[0] - xi[0]),
                    y: xi[1] + s * (xj[1] - xi[1]),
                    mode,
                });
                broken += 1;
            }
        }
        let bonds = &self.bonds;
        let claw = self.spec.contacts;
        let ckernel = |(p, f): (&mut Pair, &mut ContactForce)| {
            if p.bond != u32::MAX && bonds[p.bond as usize].intact {
                p.ut = 0.0;
                *f = ContactForce::default();
            } else {
                *f = p.update(disks, dx, &claw);
            }
        };
        if self.pairs.len() >= PAR_MIN {
            self.pairs
                .par_iter_mut()
                .zip(self.pair_force.par_iter_mut())
                .with_min_len(1024)
                .for_each(ckernel);
        } else {
            self.pairs
                .iter_mut()
                .zip(self.pair_force.iter_mut())
                .for_each(ckernel);
        }
        let (bf, ba, pf, pa) = (
            &self.bond_force,
            &self.bond_adj,
            &self.pair_force,
            &self.pair_adj,
        );
        let g = self.spec.gravity;
        let loads = &self.loads;
        let gather = |(i, out): (usize, &mut [f64; 3])| {
            let m = if disks.mass[i].is_finite() {
                disks.mass[i]
            } else {
                0.0
            };
            let mut f = [g[0] * m + loads[i][0], g[1] * m + loads[i][1], loads[i][2]];
            for &l in ba.of(i) {
                let b = &bf[(l >> 1) as usize];
                if l & 1 == 0 {
                    f[0] += b.f[0];
                    f[1] += b.f[1];
                    f[2] += b.mi;
                } else {
                    f[0] -= b.f[0];
                    f[1] -= b.f[1];
                    f[2] += b.mj;
                }
            }
            for &l in pa.of(i) {
                let c = &pf[(l >> 1) as usize];
                if l & 1 == 0 {
                    f[0] += c.f[0];
                    f[1] += c.f[1];
                    f[2] += c.mi;
                } else {
                    f[0] -= c.f[0];
                    f[1] -= c.f[1];
                    f[2] += c.mj;
                }
            }
            *out = f;
        };
        if self.force.len() >= PAR_MIN {
            self.force
                .par_iter_mut()
                .enumerate()
                .with_min_len(1024)
                .for_each(gather);
        } else {
            self.force.iter_mut().enumerate().for_each(gather);
        }
        self.bond_updates += self.bonds.len() as u64;
        self.contact_updates += self.pairs.len() as u64;
        broken
    }

    /// The Gershgorin bound of the module docs.
    fn critical_dt(&self) -> f64 {
        let d = &self.disks;
        let n = d.len();
        let inv_sqrt = |m: f64| if m.is_finite() { 1.0 / m.sqrt() } else { 0.0 };
        let mut row_t = vec![0.0f64; n];
        let mut row_r = vec![0.0f64; n];
        let (bl, cl) = (&self.spec.bonds, &self.spec.contacts);
        let mut link = |i: usize, j: usize, kn: f64, ks: f64, kb: f64| {
            let (si, sj) = (inv_sqrt(d.mass[i]), inv_sqrt(d.mass[j]));
            let (ti, tj) = (inv_sqrt(d.inertia[i]), inv_sqrt(d.inertia[j]));
            let (ri, rj) = (d.r[i], d.r[j]);
            let k = kn + ks;
            for (a, b, sa, sb, ta, tb, ra, rb) in [
                (i, j, si, sj, ti, tj, ri, rj),
                (j, i, sj, si, tj, ti, rj, ri),
            ] {
                let _ = b;
                row_t[a] += k * sa * sa + k * sa * sb + ks * ra * sa * ta + ks * rb * sa * tb;
                row_r[a] += (ks * ra * ra + kb) * ta * ta
                    + 2.0 * ks * ra * ta * (sa + sb)
                    + (ks * ra * rb + kb) * ta * tb;
            }
        };
        for b in &self.bonds {
            let (i, j) = (b.i as usize, b.j as usize);
            let reff = d.r[i] * d.r[j] / (d.r[i] + d.r[j]);
            let kn = bl.kn.max(cl.normal_stiffness(reff));
            link(i, j, kn, bl.ks.max(cl.ks), bl.kb);
        }
        for p in &self.pairs {
            let (i, j) = (p.i as usize, p.j as usize);
            if p.bond == u32::MAX {
                let reff = d.r[i] * d.r[j] / (d.r[i] + d.r[j]);
                link(i, j, cl.normal_stiffness(reff), cl.ks, 0.0);
            }
        }
        let lam = row_t.iter().chain(&row_r).fold(0.0f64, |a, &b| a.max(b));
        if lam <= 0.0 {
            return f64::INFINITY;
        }
        let w = lam.sqrt();
        match self.spec.damping {
            Damping::Viscous { rate } => {
                let z = rate / (2.0 * w);
                2.0 / w * ((1.0 + z * z).sqrt() - z)
            }
            _ => 2.0 / w,
        }
    }
}
