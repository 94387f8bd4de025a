//! Injection at a borehole: a mass source on the fluid nodes of a disk (Mora et al. (2015)
//! Fig. 9: a source term in the LBM, `f_α += w_α S Δt`), ramped in time.
//!
//! * [`InjectionControl::Pressure`]: the gauge pressure of the source nodes is driven
//!   towards `p(t) = p_max min(t/t_ramp, 1)`; each step every source node receives
//!   `S = g (ρ*(t) − ρ̄)` lattice mass, `ρ*(t)` the lattice density of `p(t)`, `ρ̄` the
//!   mean density of the source nodes and `g ∈ (0, 1]` the fraction of the gap closed per
//!   step (a sink when the pressure is above the target).
//! * [`InjectionControl::Rate`]: a mass rate per metre of depth
//!   `Q(t) = Q_max min(t/t_ramp, 1)` (kg/(m·s)), `S = Q Δt/(ρ Δx² n)` on each of the `n`
//!   nodes.

use porofrac_lbm::{Lattice, Units};

use crate::CouplingError;

/// How the injection is driven.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InjectionControl {
    /// Target gauge pressure ramped linearly to `peak` (Pa) over `ramp_time` (s).
    Pressure {
        /// Final gauge pressure (Pa).
        peak: f64,
        /// Ramp duration (s); 0 is a step.
        ramp_time: f64,
        /// Fraction of the density gap closed per step, in (0, 1].
        gain: f64,
    },
    /// Mass rate ramped linearly to `peak` (kg per metre of depth per second).
    Rate {
        /// Final rate (kg/(m·s)).
        peak: f64,
        /// Ramp duration (s); 0 is a step.
        ramp_time: f64,
    },
}

/// An injection on a lattice source.
#[derive(Clone, Debug)]
pub struct Injection {
    source: usize,
    nodes: usize,
    control: InjectionControl,
}

impl Injection {
    /// A source on the interior nodes whose centre lies within `radius` (m) of `center` (m);
    /// `origin` is the SI position of the lattice corner.
    pub fn new(
        lattice: &mut Lattice,
        units: &Units,
        origin: [f64; 2],
        center: [f64; 2],
        radius: f64,
        control: InjectionControl,
    ) -> Result<Self, CouplingError> {
        let (peak, ramp) = match control {
            InjectionControl::Pressure {
                peak,
                ramp_time,
                gain,
            } => {
                if !(gain > 0.0 && gain <= 1.0) {
                    return Err(CouplingError::argument("gain", gain, "must be in (0, 1]"));
                }
                (peak, ramp_time)
            }
            InjectionControl::Rate { peak, ramp_time } => (peak, ramp_time),
        };
        if !peak.is_finite() {
            return Err(CouplingError::argument("peak", peak, "must be finite"));
        }
        if !(ramp.is_finite() && ramp >= 0.0) {
            return Err(CouplingError::argument(
                "ramp_time",
                ramp,
                "must be finite and not negative",
            ));
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(CouplingError::argument(
                "radius",
                radius,
                "must be positive",
            ));
        }
        let (nx, ny) = lattice.size();
        let c = [
            (center[0] - origin[0]) / units.dx,
            (center[1] - origin[1]) / units.dx,
        ];
        let r = radius / units.dx;
        let mut nodes = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let d = [i as f64 + 0.5 - c[0], j as f64 + 0.5 - c[1]];
                if d[0] * d[0] + d[1] * d[1] <= r * r {
                    nodes.push((i, j));
                }
            }
        }
        if nodes.is_empty() {
            return Err(CouplingError::argument(
                "radius",
                radius,
                "covers no lattice node (at least half a spacing around a node)",
            ));
        }
        let source = lattice.add_source(&nodes)?;
        Ok(Injection {
            source,
            nodes: nodes.len(),
            control,
        })
    }

    /// The control.
    pub fn control(&self) -> InjectionControl {
        self.control
    }

    /// Nodes of the source.
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    /// Target gauge pressure at time `t` (pressure control), else `None`.
    pub fn target_pressure(&self, t: f64) -> Option<f64> {
        match self.control {
            InjectionControl::Pressure {
                peak, ramp_time, ..
            } => Some(peak * ramp(t, ramp_time)),
            InjectionControl::Rate { .. } => None,
        }
    }

    /// Set the source rate of the step that starts at time `t`.
    pub fn apply(&self, lattice: &mut Lattice, units: &Units, t: f64) -> Result<(), CouplingError> {
        let s = match self.control {
            InjectionControl::Pressure {
                peak,
                ramp_time,
                gain,
            } => {
                let target = units.pressure_density(peak * ramp(t, ramp_time));
                gain * (target - lattice.source_density(self.source))
            }
            InjectionControl::Rate { peak, ramp_time } => {
                let q = peak * ramp(t, ramp_time);
                q * units.dt / (units.density * units.dx * units.dx * self.nodes as f64)
            }
        };
        lattice.set_source_rate(self.source, s)?;
        Ok(())
    }

    /// Gauge pressure (Pa) of the source nodes now.
    pub fn pressure(&self, lattice: &Lattice, units: &Units) -> f64 {
        units.pressure_si(lattice.source_density(self.source))
    }
}

fn ramp(t: f64, ramp_time: f64) -> f64 {
    if ramp_time <= 0.0 {
        1.0
    } else {
        (t / ramp_time).clamp(0.0, 1.0)
    }
}
