//! VTK PolyData files (`.vtp`) for particles and contacts, written with
//! [`porofrac_vtk`]: atomically (a temporary file, then a rename) and streamed to the file
//! (the flattened vector arrays are the only copies made).
//!
//! * particles: one vertex per disk, point data `radius` (the active scalars), `velocity`
//!   (3 components, z = 0), `omega`, `displacement` (3 components), `id` (`Int64`), then
//!   the caller's extra scalars;
//! * contacts: one line per contact between the two centres (or the centre and the
//!   contact point on a rigid body), cell data `normal_force` (the active scalars),
//!   `tangential_force`, `bonded` (`Int64` 0/1), then the caller's extra scalars.
//!
//! Arrays are `format="binary"`: each is one base64 stream of a `UInt64` byte count
//! followed by the little-endian values (`header_type="UInt64"`), which ParaView and the
//! VTK readers take as they are. Against ASCII decimal text this writes about a third of
//! the bytes and needs no float formatting (a million bonded disks: 14 s of output per
//! frame in ASCII).

use std::path::Path;

use porofrac_vtk::{Attributes, CellArray, DataArray, Encoding, PolyData, VtkError};

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

fn io_err(path: &Path) -> impl Fn(VtkError) -> ParticleError + '_ {
    move |e| ParticleError::Io {
        path: path.display().to_string(),
        message: match e {
            VtkError::Io { source, .. } => source.to_string(),
            other => other.to_string(),
        },
    }
}

/// `[x, y, 0]` per point, flat.
fn plane_to_3d(v: impl Iterator<Item = [f64; 2]>) -> Vec<f64> {
    v.flat_map(|p| [p[0], p[1], 0.0]).collect()
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
    if let Some((name, v)) = extra.iter().find(|(_, v)| v.len() != n) {
        return Err(ParticleError::Io {
            path: path.display().to_string(),
            message: format!("point data `{name}` has {} values for {n} disks", v.len()),
        });
    }
    let points = plane_to_3d(d.x.iter().copied());
    let velocity = plane_to_3d(d.v.iter().copied());
    let displacement = plane_to_3d((0..n).map(|k| d.displacement(k)));
    let ids: Vec<i64> = (0..n as i64).collect();
    let offsets: Vec<i64> = (1..=n as i64).collect();
    let mut arrays = vec![
        DataArray::new("radius", 1, &d.r[..]),
        DataArray::new("velocity", 3, &velocity[..]),
        DataArray::new("omega", 1, &d.omega[..]),
        DataArray::new("displacement", 3, &displacement[..]),
        DataArray::new("id", 1, &ids[..]),
    ];
    arrays.extend(extra.iter().map(|(name, v)| DataArray::new(name, 1, *v)));
    PolyData {
        points: &points,
        verts: CellArray {
            connectivity: &ids,
            offsets: &offsets,
        },
        point_data: Attributes::new(&arrays).with_scalars("radius"),
        ..PolyData::default()
    }
    .write(path, Encoding::Base64)
    .map_err(io_err(path))
}

/// Write contacts as lines with cell data.
pub fn write_contacts(path: &Path, lines: &[ContactLine]) -> Result<(), ParticleError> {
    write_contacts_with(path, lines, &[])
}

/// Write contacts as lines with their cell data and the extra scalar cell data `extra`
/// (name, one value per line; a bonded model's bending moments).
pub fn write_contacts_with(
    path: &Path,
    lines: &[ContactLine],
    extra: &[(&str, &[f64])],
) -> Result<(), ParticleError> {
    let n = lines.len();
    if let Some((name, v)) = extra.iter().find(|(_, v)| v.len() != n) {
        return Err(ParticleError::Io {
            path: path.display().to_string(),
            message: format!("cell data `{name}` has {} values for {n} lines", v.len()),
        });
    }
    let points: Vec<f64> = lines
        .iter()
        .flat_map(|l| [l.a[0], l.a[1], 0.0, l.b[0], l.b[1], 0.0])
        .collect();
    let connectivity: Vec<i64> = (0..2 * n as i64).collect();
    let offsets: Vec<i64> = (1..=n as i64).map(|k| 2 * k).collect();
    let normal: Vec<f64> = lines.iter().map(|l| l.normal_force).collect();
    let tangential: Vec<f64> = lines.iter().map(|l| l.tangential_force).collect();
    let bonded: Vec<i64> = lines.iter().map(|l| i64::from(l.bonded)).collect();
    let mut arrays = vec![
        DataArray::new("normal_force", 1, &normal[..]),
        DataArray::new("tangential_force", 1, &tangential[..]),
        DataArray::new("bonded", 1, &bonded[..]),
    ];
    arrays.extend(extra.iter().map(|(name, v)| DataArray::new(name, 1, *v)));
    PolyData {
        points: &points,
        lines: CellArray {
            connectivity: &connectivity,
            offsets: &offsets,
        },
        cell_data: Attributes::new(&arrays).with_scalars("normal_force"),
        ..PolyData::default()
    }
    .write(path, Encoding::Base64)
    .map_err(io_err(path))
}
