//! Tracked cells: the stress, fabric and shape of a set of particles followed through a
//! run (Renouf, Dubois & Alart 2006, eqs. 7–11).
//!
//! A cell is the set Ω of the particles whose centre lies inside a circle (centre c,
//! radius R) at the time it is created. With the contacts α counted (both particles in
//! Ω; with [`TrackedCell::include_boundary`], also the contacts of a member with a rigid
//! body), the force r_α on the candidate i and the branch vector l_α from the
//! antagonist's centre (or the contact point on a rigid body) to the centre of i:
//!
//! * eq. 7: σ = (1/V) Σ_α r_α ⊗ l_α. With this sign a compressive contact gives a
//!   positive stress: **σ, p are positive in compression**, as in the paper;
//! * eq. 8: p = (σ₁ + σ₂)/2, q = (σ₁ − σ₂)/2 from the eigenvalues of the symmetric part
//!   of σ;
//! * eqs. 9–10: fabric f = Σ_α n_α ⊗ n_α and anisotropy a = (f₁ − f₂)/2, normalised by
//!   the number of contacts ([`CellState::anisotropy`], dimensionless, the usual
//!   convention) and by V as printed in the paper ([`CellState::anisotropy_volume`],
//!   1/m²);
//! * eq. 11: λ_x = (max x − min x)(t) / (max x − min x)(t₀) over the centres of Ω, and
//!   the same for y (1 if the initial extent is zero).
//!
//! The volume V is πR² unless given ([`TrackedCell::with_volume`]): rigid disks keep
//! their area, so "Σ particle areas / initial packing fraction of the cell" is πR² at
//! every time.

/// One contact as the cell sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellContact {
    /// Candidate particle.
    pub i: usize,
    /// Antagonist particle, or `None` for a rigid body.
    pub j: Option<usize>,
    /// Unit normal, from the antagonist to i.
    pub normal: [f64; 2],
    /// Branch vector, from the antagonist's centre (or the contact point) to i's centre (m).
    pub branch: [f64; 2],
    /// Force on i (N per metre of thickness).
    pub force: [f64; 2],
}

/// What a tracked cell measures at one time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellState {
    /// Cell stress σ (eq. 7, compression positive), `sigma[a][b] = (1/V) Σ r_a l_b` (Pa).
    pub sigma: [[f64; 2]; 2],
    /// Mean stress (eq. 8, Pa).
    pub p: f64,
    /// Deviatoric stress (eq. 8, Pa).
    pub q: f64,
    /// Fabric anisotropy normalised by the number of contacts.
    pub anisotropy: f64,
    /// Fabric anisotropy normalised by V, as in the paper (1/m²).
    pub anisotropy_volume: f64,
    /// Dilatation along x (eq. 11).
    pub dilation_x: f64,
    /// Dilatation along y (eq. 11).
    pub dilation_y: f64,
    /// Contacts counted.
    pub contacts: usize,
}

/// A set of particles followed through a run.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackedCell {
    /// Centre of the selecting circle (m).
    pub center: [f64; 2],
    /// Radius of the selecting circle (m).
    pub radius: f64,
    /// `member[i]`: particle i is in the cell.
    pub member: Vec<bool>,
    /// Number of members.
    pub count: usize,
    /// Volume V of eq. 7 (m² per metre).
    pub volume: f64,
    /// Count the contacts of members with rigid bodies too.
    pub include_boundary: bool,
    extent0: [f64; 2],
}

fn extent(x: &[[f64; 2]], member: &[bool]) -> [f64; 2] {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for (p, _) in x.iter().zip(member).filter(|(_, m)| **m) {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    if lo[0] > hi[0] {
        return [0.0; 2];
    }
    [hi[0] - lo[0], hi[1] - lo[1]]
}

/// `(λ₁, λ₂)` of a symmetric 2×2 matrix `[[a, b], [b, d]]`, λ₁ ≥ λ₂, as (mean, radius).
fn mean_radius(a: f64, b: f64, d: f64) -> (f64, f64) {
    (0.5 * (a + d), (0.25 * (a - d).powi(2) + b * b).sqrt())
}

impl TrackedCell {
    /// The particles with centres `x` inside the circle (`center`, `radius`), V = πR².
    pub fn new(x: &[[f64; 2]], center: [f64; 2], radius: f64) -> Self {
        let member: Vec<bool> = x
            .iter()
            .map(|p| (p[0] - center[0]).powi(2) + (p[1] - center[1]).powi(2) <= radius * radius)
            .collect();
        let count = member.iter().filter(|m| **m).count();
        let extent0 = extent(x, &member);
        Self {
            center,
            radius,
            member,
            count,
            volume: std::f64::consts::PI * radius * radius,
            include_boundary: false,
            extent0,
        }
    }

    /// The same cell with another volume V.
    pub fn with_volume(mut self, volume: f64) -> Self {
        self.volume = volume;
        self
    }

    /// The same cell, counting the contacts of members with rigid bodies.
    pub fn with_boundary(mut self, include: bool) -> Self {
        self.include_boundary = include;
        self
    }

    /// Whether a contact counts for this cell.
    pub fn counts(&self, c: &CellContact) -> bool {
        self.member.get(c.i).copied().unwrap_or(false)
            && match c.j {
                Some(j) => self.member.get(j).copied().unwrap_or(false),
                None => self.include_boundary,
            }
    }

    /// Stress, fabric and dilatations at the centres `x` with the contacts `contacts`.
    pub fn measure(&self, x: &[[f64; 2]], contacts: &[CellContact]) -> CellState {
        let mut s = [[0.0; 2]; 2];
        let mut f = [[0.0; 2]; 2];
        let mut nc = 0usize;
        for c in contacts.iter().filter(|c| self.counts(c)) {
            nc += 1;
            for a in 0..2 {
                for b in 0..2 {
                    s[a][b] += c.force[a] * c.branch[b];
                    f[a][b] += c.normal[a] * c.normal[b];
                }
            }
        }
        let v = self.volume;
        let sigma = [[s[0][0] / v, s[0][1] / v], [s[1][0] / v, s[1][1] / v]];
        let (p, q) = mean_radius(sigma[0][0], 0.5 * (sigma[0][1] + sigma[1][0]), sigma[1][1]);
        let (_, fa) = mean_radius(f[0][0], f[0][1], f[1][1]);
        let e = extent(x, &self.member);
        let ratio = |a: usize| {
            if self.extent0[a] > 0.0 {
                e[a] / self.extent0[a]
            } else {
                1.0
            }
        };
        CellState {
            sigma,
            p,
            q,
            anisotropy: if nc > 0 { fa / nc as f64 } else { 0.0 },
            anisotropy_volume: fa / v,
            dilation_x: ratio(0),
            dilation_y: ratio(1),
            contacts: nc,
        }
    }
}
