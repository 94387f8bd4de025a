//! VTK PolyData files (`.vtp`, ASCII) for particles and contacts, written atomically
//! (to a temporary file, then renamed).
//!
//! * particles: one vertex per disk, point data `radius`, `velocity` (3 components,
//!   z = 0), `omega`, `displacement` (3 components), `id`;
//! * contacts: one line per contact between the two centres (or the centre and the
//!   contact point on a rigid body), cell data `normal_force`, `tangential_force`,
//!   `bonded` (0/1).

use std::fmt::Write as _;
use std::path::Path;

use crate::{Disks, ParticleError};

/// A contact line for [`write_contacts`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactLine {
    /// First end (m).
    pub a: [f64; 2],
    /// Second end (m).
    pub b: [f64; 2],
    /// Normal force (N/m, positive in compression).
    pub normal_force: f64,
    /// Tangential force (N/m).
    pub tangential_force: f64,
    /// A bond (bonded-particle models) rather than a contact.
    pub bonded: bool,
}

fn write_atomic(path: &Path, text: &str) -> Result<(), ParticleError> {
    let err = |e: std::io::Error| ParticleError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let tmp = path.with_extension("vtp.tmp");
    std::fs::write(&tmp, text).map_err(err)?;
    std::fs::rename(&tmp, path).map_err(err)
}

fn array(s: &mut String, kind: &str, name: &str, comps: usize, values: impl Iterator<Item = f64>) {
    let _ = writeln!(
        s,
        "<DataArray type=\"{kind}\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"ascii\">"
    );
    for v in values {
        if kind == "Float64" {
            let _ = write!(s, "{v:e} ");
        } else {
            let _ = write!(s, "{} ", v as i64);
        }
    }
    s.push_str("\n</DataArray>\n");
}

/// Write the disks as vertices with their point data.
pub fn write_particles(path: &Path, d: &Disks) -> Result<(), ParticleError> {
    write_particles_with(path, d, &[])
}

/// Write the disks as vertices with their point data and the extra scalar point data
/// `extra` (name, one value per disk).
pub fn write_particles_with(
    path: &Path,
    d: &Disks,
    extra: &[(&str, &[f64])],
) -> Result<(), ParticleError> {
    let n = d.len();
    let mut s = String::with_capacity(200 * n + 1000);
    let _ = write!(
        s,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n<Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n<Points>\n"
    );
    array(
        &mut s,
        "Float64",
        "Points",
        3,
        d.x.iter().flat_map(|p| [p[0], p[1], 0.0]),
    );
    s.push_str("</Points>\n<Verts>\n");
    array(&mut s, "Int64", "connectivity", 1, (0..n).map(|i| i as f64));
    array(&mut s, "Int64", "offsets", 1, (1..=n).map(|i| i as f64));
    s.push_str("</Verts>\n<PointData Scalars=\"radius\">\n");
    array(&mut s, "Float64", "radius", 1, d.r.iter().copied());
    array(
        &mut s,
        "Float64",
        "velocity",
        3,
        d.v.iter().flat_map(|v| [v[0], v[1], 0.0]),
    );
    array(&mut s, "Float64", "omega", 1, d.omega.iter().copied());
    array(
        &mut s,
        "Float64",
        "displacement",
        3,
        (0..n).flat_map(|i| {
            let u = d.displacement(i);
            [u[0], u[1], 0.0]
        }),
    );
    array(&mut s, "Int64", "id", 1, (0..n).map(|i| i as f64));
    for (name, values) in extra {
        array(&mut s, "Float64", name, 1, values.iter().copied());
    }
    s.push_str("</PointData>\n</Piece>\n</PolyData>\n</VTKFile>\n");
    write_atomic(path, &s)
}

/// Write contacts as lines with cell data.
pub fn write_contacts(path: &Path, lines: &[ContactLine]) -> Result<(), ParticleError> {
    let n = lines.len();
    let mut s = String::with_capacity(200 * n + 1000);
    let _ = write!(
        s,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n<Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{n}\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n<Points>\n",
        2 * n
    );
    array(
        &mut s,
        "Float64",
        "Points",
        3,
        lines
            .iter()
            .flat_map(|l| [l.a[0], l.a[1], 0.0, l.b[0], l.b[1], 0.0]),
    );
    s.push_str("</Points>\n<Lines>\n");
    array(
        &mut s,
        "Int64",
        "connectivity",
        1,
        (0..2 * n).map(|i| i as f64),
    );
    array(
        &mut s,
        "Int64",
        "offsets",
        1,
        (1..=n).map(|i| 2.0 * i as f64),
    );
    s.push_str("</Lines>\n<CellData Scalars=\"normal_force\">\n");
    array(
        &mut s,
        "Float64",
        "normal_force",
        1,
        lines.iter().map(|l| l.normal_force),
    );
    array(
        &mut s,
        "Float64",
        "tangential_force",
        1,
        lines.iter().map(|l| l.tangential_force),
    );
    array(
        &mut s,
        "Int64",
        "bonded",
        1,
        lines.iter().map(|l| l.bonded as u8 as f64),
    );
    s.push_str("</CellData>\n</Piece>\n</PolyData>\n</VTKFile>\n");
    write_atomic(path, &s)
}
