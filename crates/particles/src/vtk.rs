//! VTK PolyData files (`.vtp`) for particles and contacts, written atomically (to a
//! temporary file, then renamed) and streamed: nothing is held in memory but the write
//! buffer.
//!
//! * particles: one vertex per disk, point data `radius`, `velocity` (3 components,
//!   z = 0), `omega`, `displacement` (3 components), `id`;
//! * contacts: one line per contact between the two centres (or the centre and the
//!   contact point on a rigid body), cell data `normal_force`, `tangential_force`,
//!   `bonded` (0/1).
//!
//! Arrays are `format="binary"`: each is one base64 stream of a `UInt64` byte count
//! followed by the little-endian values (`header_type="UInt64"`), which ParaView and the
//! VTK readers take as they are. Against ASCII decimal text this writes about a third of
//! the bytes and needs no float formatting (a million bonded disks: 14 s of output per
//! frame in ASCII).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use base64::engine::general_purpose::STANDARD;
use base64::write::EncoderWriter;

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

/// Write `path` through `body` into a temporary file, then rename it into place.
fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<(), ParticleError> {
    let err = |e: std::io::Error| ParticleError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let tmp = path.with_extension("vtp.tmp");
    let mut w = BufWriter::with_capacity(1 << 20, File::create(&tmp).map_err(err)?);
    body(&mut w).and_then(|()| w.flush()).map_err(err)?;
    drop(w);
    std::fs::rename(&tmp, path).map_err(err)
}

/// The element types of the arrays.
#[derive(Clone, Copy)]
enum Kind {
    Float64,
    Int64,
}

/// One `DataArray` of `count` values (`count` known before the values are streamed).
fn array(
    w: &mut impl Write,
    kind: Kind,
    name: &str,
    comps: usize,
    count: usize,
    values: impl Iterator<Item = f64>,
) -> std::io::Result<()> {
    let ty = match kind {
        Kind::Float64 => "Float64",
        Kind::Int64 => "Int64",
    };
    writeln!(
        w,
        "<DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"binary\">"
    )?;
    {
        // values gathered in blocks: the encoder is fast on long writes only
        const BLOCK: usize = 3 << 13;
        let mut enc = EncoderWriter::new(&mut *w, &STANDARD);
        let mut buf = Vec::with_capacity(BLOCK + 8);
        buf.extend_from_slice(&(8 * count as u64).to_le_bytes());
        let mut written = 0usize;
        for v in values {
            match kind {
                Kind::Float64 => buf.extend_from_slice(&v.to_le_bytes()),
                Kind::Int64 => buf.extend_from_slice(&(v as i64).to_le_bytes()),
            }
            written += 1;
            if buf.len() >= BLOCK {
                enc.write_all(&buf)?;
                buf.clear();
            }
        }
        enc.write_all(&buf)?;
        debug_assert_eq!(written, count, "{name}: value count");
        enc.finish()?;
    }
    w.write_all(b"\n</DataArray>\n")
}

/// The file's opening up to the `Piece` element.
fn header(w: &mut impl Write, piece: &str) -> std::io::Result<()> {
    writeln!(
        w,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<PolyData>\n{piece}"
    )
}

const FOOTER: &[u8] = b"</Piece>\n</PolyData>\n</VTKFile>\n";

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
    write_atomic(path, |w| {
        header(
            w,
            &format!(
                "<Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n<Points>"
            ),
        )?;
        let (f, i) = (Kind::Float64, Kind::Int64);
        array(
            w,
            f,
            "Points",
            3,
            3 * n,
            d.x.iter().flat_map(|p| [p[0], p[1], 0.0]),
        )?;
        w.write_all(b"</Points>\n<Verts>\n")?;
        array(w, i, "connectivity", 1, n, (0..n).map(|k| k as f64))?;
        array(w, i, "offsets", 1, n, (1..=n).map(|k| k as f64))?;
        w.write_all(b"</Verts>\n<PointData Scalars=\"radius\">\n")?;
        array(w, f, "radius", 1, n, d.r.iter().copied())?;
        array(
            w,
            f,
            "velocity",
            3,
            3 * n,
            d.v.iter().flat_map(|v| [v[0], v[1], 0.0]),
        )?;
        array(w, f, "omega", 1, n, d.omega.iter().copied())?;
        array(
            w,
            f,
            "displacement",
            3,
            3 * n,
            (0..n).flat_map(|k| {
                let u = d.displacement(k);
                [u[0], u[1], 0.0]
            }),
        )?;
        array(w, i, "id", 1, n, (0..n).map(|k| k as f64))?;
        for (name, values) in extra {
            array(w, f, name, 1, n, values.iter().copied())?;
        }
        w.write_all(b"</PointData>\n")?;
        w.write_all(FOOTER)
    })
}

/// Write contacts as lines with cell data.
pub fn write_contacts(path: &Path, lines: &[ContactLine]) -> Result<(), ParticleError> {
    let n = lines.len();
    write_atomic(path, |w| {
        header(
            w,
            &format!(
                "<Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{n}\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n<Points>",
                2 * n
            ),
        )?;
        let (f, i) = (Kind::Float64, Kind::Int64);
        array(
            w,
            f,
            "Points",
            3,
            6 * n,
            lines
                .iter()
                .flat_map(|l| [l.a[0], l.a[1], 0.0, l.b[0], l.b[1], 0.0]),
        )?;
        w.write_all(b"</Points>\n<Lines>\n")?;
        array(w, i, "connectivity", 1, 2 * n, (0..2 * n).map(|k| k as f64))?;
        array(w, i, "offsets", 1, n, (1..=n).map(|k| 2.0 * k as f64))?;
        w.write_all(b"</Lines>\n<CellData Scalars=\"normal_force\">\n")?;
        array(
            w,
            f,
            "normal_force",
            1,
            n,
            lines.iter().map(|l| l.normal_force),
        )?;
        array(
            w,
            f,
            "tangential_force",
            1,
            n,
            lines.iter().map(|l| l.tangential_force),
        )?;
        array(
            w,
            i,
            "bonded",
            1,
            n,
            lines.iter().map(|l| l.bonded as u8 as f64),
        )?;
        w.write_all(b"</CellData>\n")?;
        w.write_all(FOOTER)
    })
}
