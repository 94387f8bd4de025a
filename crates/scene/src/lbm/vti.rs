//! VTK XML image data (`.vti`) with appended raw binary point data.

/// The bytes of a `.vti` file: `n` points per axis, the first at `origin`, `spacing`
/// apart; `arrays` are `(name, components, values)` in x-fastest order.
pub(crate) fn image_data(
    n: [usize; 2],
    origin: [f64; 2],
    spacing: f64,
    arrays: &[(&str, usize, &[f64])],
) -> Vec<u8> {
    let mut head = String::new();
    head.push_str("<?xml version=\"1.0\"?>\n");
    head.push_str("<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    let extent = format!("0 {} 0 {} 0 0", n[0] - 1, n[1] - 1);
    head.push_str(&format!(
        "  <ImageData WholeExtent=\"{extent}\" Origin=\"{} {} 0\" Spacing=\"{spacing} {spacing} {spacing}\">\n",
        origin[0], origin[1]
    ));
    head.push_str(&format!(
        "    <Piece Extent=\"{extent}\">\n      <PointData>\n"
    ));
    let mut offset = 0usize;
    for (name, comps, values) in arrays {
        head.push_str(&format!(
            "        <DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"appended\" offset=\"{offset}\"/>\n"
        ));
        offset += 8 + 8 * values.len();
    }
    head.push_str(
        "      </PointData>\n    </Piece>\n  </ImageData>\n  <AppendedData encoding=\"raw\">\n   _",
    );
    let mut bytes = head.into_bytes();
    bytes.reserve(offset + 64);
    for (_, _, values) in arrays {
        bytes.extend_from_slice(&((8 * values.len()) as u64).to_le_bytes());
        for v in values.iter() {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    bytes.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
    bytes
}
