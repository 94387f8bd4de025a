//! Parallel unstructured grids (`.pvtu`): one header that names the pieces (`.vtu` files,
//! one per process of a distributed run) and declares their arrays, so that ParaView opens
//! the pieces as one data set.
//!
//! ```text
//! <?xml version="1.0"?>
//! <VTKFile type="PUnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">
//!   <PUnstructuredGrid GhostLevel="0">
//!     <PPointData> <PDataArray type="Float64" Name="displacement" NumberOfComponents="3"/> </PPointData>
//!     <PCellData> … </PCellData>
//!     <PPoints> <PDataArray type="Float64" Name="Points" NumberOfComponents="3"/> </PPoints>
//!     <Piece Source="step_0001_p0.vtu"/>  …
//!   </PUnstructuredGrid>
//! </VTKFile>
//! ```
//!
//! The declarations must match the pieces' arrays (name, type, components): they are
//! taken from the [`DataArray`]s of one piece, so a caller writes the pieces and the header
//! from the same arrays.

use std::fmt::Write as _;
use std::path::Path;

use crate::array::{DataArray, Values};
use crate::atomic::write_atomic;
use crate::error::VtkError;

/// The VTK type name of an array's values.
fn type_name(v: &Values<'_>) -> &'static str {
    match v {
        Values::F64(_) => "Float64",
        Values::I32(_) => "Int32",
        Values::I64(_) => "Int64",
        Values::U8(_) => "UInt8",
    }
}

/// XML-escape an attribute value.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

fn declare(out: &mut String, section: &str, arrays: &[DataArray<'_>]) {
    if arrays.is_empty() {
        return;
    }
    let _ = writeln!(out, "    <{section}>");
    for a in arrays {
        let _ = writeln!(
            out,
            "      <PDataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"/>",
            type_name(&a.values),
            escape(a.name),
            a.components
        );
    }
    let _ = writeln!(out, "    </{section}>");
}

/// The text of a `.pvtu` header for the pieces `sources` (paths relative to the header)
/// whose point and cell arrays are those of `point_data` and `cell_data` (the values are
/// not read, only names, types and components).
pub fn pvtu_text(
    sources: &[String],
    point_data: &[DataArray<'_>],
    cell_data: &[DataArray<'_>],
) -> String {
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\"?>\n");
    s.push_str(
        "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
    );
    s.push_str("  <PUnstructuredGrid GhostLevel=\"0\">\n");
    declare(&mut s, "PPointData", point_data);
    declare(&mut s, "PCellData", cell_data);
    s.push_str("    <PPoints>\n");
    s.push_str("      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n");
    s.push_str("    </PPoints>\n");
    for src in sources {
        let _ = writeln!(s, "    <Piece Source=\"{}\"/>", escape(src));
    }
    s.push_str("  </PUnstructuredGrid>\n</VTKFile>\n");
    s
}

/// Write a `.pvtu` header ([`pvtu_text`]) atomically to `path`.
///
/// Errors: no pieces, or the file cannot be written.
pub fn write_pvtu(
    path: impl AsRef<Path>,
    sources: &[String],
    point_data: &[DataArray<'_>],
    cell_data: &[DataArray<'_>],
) -> Result<(), VtkError> {
    if sources.is_empty() {
        return Err(VtkError::Input(
            "a .pvtu file needs at least one piece".into(),
        ));
    }
    write_atomic(
        path.as_ref(),
        pvtu_text(sources, point_data, cell_data).as_bytes(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_declares_every_array_and_piece() {
        let d = [0.0f64; 6];
        let f = [1i32, 0];
        let pd = [DataArray::new("displacement", 3, &d[..])];
        let cd = [DataArray::new("rank", 1, &f[..])];
        let t = pvtu_text(&["a_0.vtu".into(), "a_1.vtu".into()], &pd, &cd);
        assert!(t.contains(
            "<PDataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\"/>"
        ));
        assert!(t.contains(
            "<PCellData>\n      <PDataArray type=\"Int32\" Name=\"rank\" NumberOfComponents=\"1\"/>"
        ));
        assert_eq!(t.matches("<Piece Source=").count(), 2);
        assert!(t.contains("<Piece Source=\"a_1.vtu\"/>"));
        assert!(t.starts_with("<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\""));
        assert!(t.ends_with("</VTKFile>\n"));
        assert!(write_pvtu("/nonexistent-dir/x.pvtu", &[], &pd, &cd).is_err());
    }
}
