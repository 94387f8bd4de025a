//! The lattice of `[lbm]` and the heat of `[thermal]`, shared by every model that has a
//! fluid (model `lbm`, and model `lsm` with a fluid): the sections ([`sections`]), their
//! checks ([`check`]), the lattice without obstacles (`lattice_of`) and field images
//! ([`images`]).
//!
//! Nodes sit at the centres of the `Δx` cells covering `extent`; SI values are converted
//! to lattice units by [`Units`] (`Δt` from spacing, viscosity and tau); the thermal
//! relaxation time is `τ_g = ½ + 3 χ Δt/Δx²`.

pub mod check;
pub mod images;
pub mod sections;

use porofrac_lbm::{
    Collision, Lattice, LatticeConfig, MomentumExchange, Side, SideKind, ThermalSide, Units,
};

use crate::common::expr::Expr;
use crate::common::loaded::{LoadedScene, k};
use crate::common::model::RunError;
use crate::common::sections::NumOrExpr;
use sections::{
    AxisChoice, BoundaryKindChoice, CollisionChoice, ExchangeChoice, LbmSection, SideChoice,
    ThermalSection,
};

/// Thermal relaxation time of diffusivity `chi` (m²/s): `τ_g = ½ + 3 χ Δt/Δx²`.
pub(crate) fn thermal_tau(chi: f64, u: &Units) -> f64 {
    0.5 + 3.0 * chi * u.dt / (u.dx * u.dx)
}

/// Nodes along x and y for the extent and spacing (as floats, for checks).
pub(crate) fn nodes(l: &LbmSection) -> (f64, f64) {
    let n = |a: usize| {
        ((l.extent[1][a] - l.extent[0][a]) / l.spacing)
            .round()
            .max(0.0)
    };
    (n(0), n(1))
}

/// A velocity given as numbers or expressions.
#[derive(Clone, Debug)]
pub(crate) enum VelocityExpr {
    Const([f64; 2]),
    Vary([Expr; 2]),
}

impl VelocityExpr {
    pub(crate) fn new(v: &[NumOrExpr]) -> Self {
        let e: Vec<Expr> = v
            .iter()
            .map(|c| match c {
                NumOrExpr::Num(x) => Expr::constant(*x),
                NumOrExpr::Expr(s) => Expr::parse(s).unwrap_or_else(|_| Expr::constant(f64::NAN)),
            })
            .collect();
        match (e[0].as_constant(), e[1].as_constant()) {
            (Some(a), Some(b)) => VelocityExpr::Const([a, b]),
            _ => VelocityExpr::Vary([e[0].clone(), e[1].clone()]),
        }
    }
    pub(crate) fn at(&self, x: [f64; 2], t: f64) -> [f64; 2] {
        match self {
            VelocityExpr::Const(v) => *v,
            VelocityExpr::Vary(e) => [e[0].eval(&x, t), e[1].eval(&x, t)],
        }
    }
    pub(crate) fn varies_in_time(&self) -> bool {
        match self {
            VelocityExpr::Const(_) => false,
            VelocityExpr::Vary(e) => e.iter().any(Expr::depends_on_time),
        }
    }
}

/// The lattice of `[lbm]` without obstacles: units, the SI corner, the lattice and the
/// velocities of its sides (every model that has a fluid).
pub(crate) struct LatticeParts {
    /// The lattice.
    pub lat: Lattice,
    /// SI ↔ lattice units.
    pub units: Units,
    /// SI position of the lattice corner.
    pub origin: [f64; 2],
    /// Sides with a prescribed velocity.
    pub sides: Vec<(Side, VelocityExpr)>,
}

/// Set the velocities of `sides` at time `t` (lattice corner at `origin`).
pub(crate) fn set_side_velocities(
    lat: &mut Lattice,
    sides: &[(Side, VelocityExpr)],
    units: &Units,
    origin: [f64; 2],
    t: f64,
) {
    let (u, o, dx) = (*units, origin, units.dx);
    for (side, v) in sides {
        lat.set_side_velocity(*side, |p| {
            let w = v.at([o[0] + p[0] * dx, o[1] + p[1] * dx], t);
            [u.velocity(w[0]), u.velocity(w[1])]
        });
    }
}

fn side_of(s: SideChoice) -> Side {
    match s {
        SideChoice::Xmin => Side::XMin,
        SideChoice::Xmax => Side::XMax,
        SideChoice::Ymin => Side::YMin,
        SideChoice::Ymax => Side::YMax,
    }
}

/// Build the lattice of a checked `[lbm]`.
pub(crate) fn lattice_of(ls: &LoadedScene) -> Result<LatticeParts, RunError> {
    window_of(ls, None)
}

/// Build the lattice of a checked `[lbm]`, or its columns `window[0] .. window[1]`
/// ([`Lattice::window`], a rank's part of a distributed run).
pub(crate) fn window_of(
    ls: &LoadedScene,
    window: Option<[usize; 2]>,
) -> Result<LatticeParts, RunError> {
    let s = &ls.scene;
    let l = s.lbm.as_ref().expect("checked");
    let units = Units::from_viscosity(l.spacing, l.viscosity, l.density, l.tau)
        .map_err(|e| ls.error(&k(&["lbm", "tau"]), e))?;
    let (nx, ny) = nodes(l);
    let (nx, ny) = (nx as usize, ny as usize);
    let origin = [l.extent[0][0], l.extent[0][1]];
    let mut periodic = [false; 2];
    for a in &l.periodic {
        periodic[match a {
            AxisChoice::X => 0,
            AxisChoice::Y => 1,
        }] = true;
    }
    let mut kinds = [SideKind::Wall; 4];
    let mut sides = Vec::new();
    for b in &l.boundary {
        let side = side_of(b.side);
        kinds[side.index()] = match b.kind {
            BoundaryKindChoice::Wall => SideKind::Wall,
            BoundaryKindChoice::Velocity => SideKind::Velocity,
            BoundaryKindChoice::Pressure => SideKind::Pressure {
                density: units.pressure_density(b.pressure.unwrap_or(0.0)),
            },
        };
        if let Some(v) = &b.velocity {
            sides.push((side, VelocityExpr::new(v)));
        }
    }
    let body = l.body_force.clone().unwrap_or(vec![0.0, 0.0]);
    let cfg = LatticeConfig {
        nx,
        ny,
        tau: l.tau,
        collision: match l.collision {
            CollisionChoice::Bgk => Collision::Bgk,
            CollisionChoice::Trt => Collision::Trt {
                magic: l.magic.unwrap_or(3.0 / 16.0),
            },
        },
        periodic,
        sides: kinds,
        accel: [units.acceleration(body[0]), units.acceleration(body[1])],
        momentum_exchange: match l.momentum_exchange {
            ExchangeChoice::Standard => MomentumExchange::Standard,
            ExchangeChoice::GalileanInvariant => MomentumExchange::GalileanInvariant,
        },
        obstacle_mass: porofrac_lbm::ObstacleMass::Conserved,
    };
    let mut lat = match window {
        None => Lattice::new(cfg),
        Some([a, b]) => Lattice::window(cfg, a, b - a),
    }
    .map_err(|e| ls.error(&k(&["lbm"]), e))?;
    if l.precision == sections::PrecisionChoice::Single {
        lat.set_precision(porofrac_lbm::Precision::Single);
    }
    Ok(LatticeParts {
        lat,
        units,
        origin,
        sides,
    })
}

/// The thermal side conditions of a checked `[thermal]`.
pub(crate) fn thermal_sides(t: &ThermalSection, units: &Units) -> [ThermalSide; 4] {
    let mut tsides = [ThermalSide::Adiabatic; 4];
    for b in &t.boundary {
        tsides[side_of(b.side).index()] = match (b.temperature, b.flux, b.outflow) {
            (_, _, true) => ThermalSide::Outflow,
            (Some(v), _, _) => ThermalSide::Temperature(v),
            (None, f, _) => ThermalSide::Flux(f.unwrap_or(0.0) * units.dt / units.dx),
        };
    }
    tsides
}

/// The initial temperature of a checked `[thermal]` (0 if not given).
pub(crate) fn thermal_initial(t: &ThermalSection) -> Expr {
    match &t.initial {
        None => Expr::constant(0.0),
        Some(NumOrExpr::Num(x)) => Expr::constant(*x),
        Some(NumOrExpr::Expr(e)) => Expr::parse(e).unwrap_or_else(|_| Expr::constant(f64::NAN)),
    }
}
