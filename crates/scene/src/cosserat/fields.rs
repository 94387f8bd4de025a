//! Probe and line fields of the Cosserat model (docs/models/cosserat.md): `ux uy uz`, `phi` (2D)
//! or `phix phiy phiz` (3D), stresses `sxx sxy syx syy …` (`sxy` = σ_xy, the x-component
//! of the traction on a face of normal y), couple stresses `mx my` (2D: `m_3x, m_3y`) or
//! `mxx … mzz` (3D), and the totals `energy` (stored), `kinetic` and `work` (external).

use porofrac_cosserat::strain_index;

/// A field name resolved for dimension `D`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// Generalised displacement component `a` (`u` then `φ`), P1-reconstructed.
    Dof(usize),
    /// Entry of the generalised stress vector (σ or m), cell value.
    Stress(usize),
    /// Stored energy (elastic + penalty), total.
    Energy,
    /// Kinetic energy, total.
    Kinetic,
    /// Work of the external loads so far.
    Work,
}

const AXES: [&str; 3] = ["x", "y", "z"];

impl Field {
    /// Every field name of dimension `d`.
    pub fn names(d: usize) -> Vec<String> {
        let mut v: Vec<String> = AXES[..d].iter().map(|a| format!("u{a}")).collect();
        if d == 2 {
            v.push("phi".into());
        } else {
            v.extend(AXES.iter().map(|a| format!("phi{a}")));
        }
        for i in 0..d {
            for j in 0..d {
                v.push(format!("s{}{}", AXES[i], AXES[j]));
            }
        }
        if d == 2 {
            v.extend(["mx".to_string(), "my".to_string()]);
        } else {
            for i in 0..3 {
                for j in 0..3 {
                    v.push(format!("m{}{}", AXES[i], AXES[j]));
                }
            }
        }
        v.extend(["energy", "kinetic", "work"].map(String::from));
        v
    }

    /// The unit of field `name` in dimension `d`: displacements m, rotations rad,
    /// stresses Pa, couple stresses N/m, energies and work J (per metre of thickness in
    /// 2D: J/m); `"1"` for a name that is not a field.
    pub fn unit(name: &str, d: usize) -> &'static str {
        match Self::parse(name, d) {
            Ok(Self::Dof(a)) if a < d => "m",
            Ok(Self::Dof(_)) => "rad",
            Ok(Self::Stress(_)) if name.starts_with('m') => "N/m",
            Ok(Self::Stress(_)) => "Pa",
            Ok(Self::Energy | Self::Kinetic | Self::Work) if d == 2 => "J/m",
            Ok(Self::Energy | Self::Kinetic | Self::Work) => "J",
            Err(_) => "1",
        }
    }

    /// Parse a field name, or an error listing the known ones.
    pub fn parse(name: &str, d: usize) -> Result<Self, String> {
        let ax = |c: u8| AXES[..d].iter().position(|a| a.as_bytes()[0] == c);
        let b = name.as_bytes();
        let f = match name {
            "energy" => Some(Self::Energy),
            "kinetic" => Some(Self::Kinetic),
            "work" => Some(Self::Work),
            "phi" if d == 2 => Some(Self::Dof(2)),
            _ if b.len() == 2 && b[0] == b'u' => ax(b[1]).map(Self::Dof),
            _ if d == 3 && b.len() == 4 && name.starts_with("phi") => {
                ax(b[3]).map(|k| Self::Dof(3 + k))
            }
            _ if b.len() == 3 && b[0] == b's' => match (ax(b[1]), ax(b[2])) {
                (Some(i), Some(j)) => Some(Self::Stress(strain_index(d, i, j))),
                _ => None,
            },
            _ if d == 2 && b.len() == 2 && b[0] == b'm' => {
                ax(b[1]).map(|j| Self::Stress(strain_index(2, 2, j)))
            }
            _ if d == 3 && b.len() == 3 && b[0] == b'm' => match (ax(b[1]), ax(b[2])) {
                (Some(i), Some(j)) => Some(Self::Stress(strain_index(3, 3 + i, j))),
                _ => None,
            },
            _ => None,
        };
        f.ok_or_else(|| {
            format!(
                "= \"{name}\" is not a field of the cosserat model in {d}D (known: {})",
                Self::names(d).join(" ")
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_listed_name_parses_and_others_do_not() {
        for d in [2, 3] {
            for n in Field::names(d) {
                assert!(Field::parse(&n, d).is_ok(), "{n} in {d}D");
            }
        }
        assert_eq!(Field::parse("sxy", 2), Ok(Field::Stress(1)));
        assert_eq!(Field::parse("syx", 2), Ok(Field::Stress(2)));
        assert_eq!(Field::parse("my", 2), Ok(Field::Stress(5)));
        assert!(Field::parse("uz", 2).is_err());
        let units: Vec<&str> = ["ux", "phi", "sxy", "my", "energy"]
            .iter()
            .map(|n| Field::unit(n, 2))
            .collect();
        assert_eq!(units, ["m", "rad", "Pa", "N/m", "J/m"]);
        assert_eq!(Field::unit("phiz", 3), "rad");
        assert_eq!(Field::unit("mzz", 3), "N/m");
        assert_eq!(Field::unit("work", 3), "J");
        assert!(Field::parse("phi", 3).is_err());
        assert!(Field::parse("pressure", 2).unwrap_err().contains("known"));
    }
}
