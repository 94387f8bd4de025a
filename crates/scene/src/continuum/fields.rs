//! The fields of the continuum model that probes, lines and `field_extrema` sample.
//!
//! Every field is either correct for the scene's dimension and plane setting or refused
//! with an error naming the key:
//!
//! - `ux uy` (and `uz` in 3D) are nodal, interpolated in the containing cell;
//!   `uz` in a 2D scene is an error.
//! - `sxx syy sxy` (and `szz syz sxz` in 3D) are the cell's effective stress. In 2D the
//!   out-of-plane shears `syz sxz` are zero for both plane settings; `szz` is 0 in plane
//!   stress and, in plane strain, `σ_zz = λ (ε_xx + ε_yy) = ν (σ_xx + σ_yy)` with the
//!   Poisson ratio of the cell's material (isotropic elasticity; a failed DEM cell
//!   reports it from its in-plane stress the same way).
//! - `smax smin` are the largest and smallest principal stress of the cell
//!   ([`porofrac_law::principal()`]); in 2D the in-plane ones.
//! - `pressure` needs flow; `fractured` is 0 or 1.

use porofrac_law::Tensor;

/// A field of the continuum model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// Displacement component (0, 1, 2 = x, y, z).
    Displacement(usize),
    /// Stress component `σ_ij`.
    Stress(usize, usize),
    /// Largest principal stress.
    Smax,
    /// Smallest principal stress.
    Smin,
    /// Pore pressure (Pa).
    Pressure,
    /// 1 for a failed cell, else 0.
    Fractured,
}

/// Every field name, for messages.
pub const NAMES: [&str; 13] = [
    "pressure",
    "ux",
    "uy",
    "uz",
    "sxx",
    "syy",
    "szz",
    "sxy",
    "syz",
    "sxz",
    "smax",
    "smin",
    "fractured",
];

/// The unit of a field of [`NAMES`] (`"m"`, `"Pa"`; `"1"` for `fractured`).
pub fn unit(name: &str) -> &'static str {
    match name {
        "ux" | "uy" | "uz" => "m",
        "fractured" => "1",
        _ => "Pa",
    }
}

impl Field {
    /// The field called `name` in a `dim`-D scene (`flow`: the scene solves flow), or why
    /// it is not available.
    pub fn parse(name: &str, dim: usize, flow: bool) -> Result<Self, String> {
        let f = match name {
            "ux" => Self::Displacement(0),
            "uy" => Self::Displacement(1),
            "uz" => Self::Displacement(2),
            "sxx" => Self::Stress(0, 0),
            "syy" => Self::Stress(1, 1),
            "szz" => Self::Stress(2, 2),
            "sxy" => Self::Stress(0, 1),
            "syz" => Self::Stress(1, 2),
            "sxz" => Self::Stress(0, 2),
            "smax" => Self::Smax,
            "smin" => Self::Smin,
            "pressure" => Self::Pressure,
            "fractured" => Self::Fractured,
            _ => {
                return Err(format!(
                    "= \"{name}\" is not a field (known: {})",
                    NAMES.join(", ")
                ));
            }
        };
        match f {
            Self::Displacement(a) if a >= dim => Err(format!(
                "= \"{name}\" is not a field of a {dim}D scene (the displacement has {dim} \
                 components)"
            )),
            Self::Pressure if !flow => Err("= \"pressure\" needs [physics] flow = true".into()),
            f => Ok(f),
        }
    }

    /// The value of a cell field from the cell's stress; `nu` is the Poisson ratio of the
    /// cell's material and `plane_strain` the 2D setting (see the module docs). `None` for
    /// nodal fields, pressure and the failure flag.
    pub fn of_stress<const D: usize>(
        self,
        s: &Tensor<D>,
        nu: f64,
        plane_strain: bool,
    ) -> Option<f64> {
        Some(match self {
            Self::Stress(i, j) if i < D && j < D => s[(i, j)],
            Self::Stress(2, 2) if plane_strain => nu * (s[(0, 0)] + s[(1, 1)]),
            Self::Stress(..) => 0.0,
            Self::Smax => porofrac_law::principal(s).values[0],
            Self::Smin => porofrac_law::principal(s).values[D - 1],
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_follow_the_dimension_and_the_plane_setting() {
        assert!(Field::parse("uz", 2, false).unwrap_err().contains("2D"));
        assert_eq!(Field::parse("uz", 3, false), Ok(Field::Displacement(2)));
        assert!(Field::parse("pressure", 2, false).is_err());
        assert!(
            Field::parse("sigma", 2, true)
                .unwrap_err()
                .contains("known")
        );
        // Plane strain, E = 1, ν = 0.25: uniaxial strain ε_xx = 1e-3 gives
        // σ_xx = (λ + 2μ) ε, σ_yy = σ_zz = λ ε.
        let (e, nu) = (1.0, 0.25);
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        let eps = 1e-3;
        let s = Tensor::<2>::new((lambda + 2.0 * mu) * eps, 0.0, 0.0, lambda * eps);
        let szz = Field::Stress(2, 2).of_stress(&s, nu, true).unwrap();
        assert!((szz - lambda * eps).abs() <= 1e-15, "{szz}");
        assert_eq!(Field::Stress(2, 2).of_stress(&s, nu, false), Some(0.0));
        assert_eq!(Field::Stress(1, 2).of_stress(&s, nu, true), Some(0.0));
        assert_eq!(
            NAMES.map(unit),
            [
                "Pa", "m", "m", "m", "Pa", "Pa", "Pa", "Pa", "Pa", "Pa", "Pa", "Pa", "1"
            ]
        );
        let smax = Field::Smax.of_stress(&s, nu, true).unwrap();
        assert!((smax - (lambda + 2.0 * mu) * eps).abs() <= 1e-15);
    }
}
