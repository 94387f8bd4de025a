//! Parallel `ImageData`: one lattice written as pieces (`.vti`, each a block of the
//! points of the whole lattice, as each process of a distributed run holds it) and the
//! `.pvti` file that ParaView opens as one data set.
//!
//! A piece covers points `offset .. offset + size` of the whole lattice; neighbouring
//! pieces share the layer of points on their border (so the cells between them are
//! drawn). Its file says the whole lattice's `WholeExtent` and origin and its own
//! `Extent`, as VTK's parallel writers do; the `.pvti` lists every piece's extent and
//! file name, and the name, type and components of every point array (the pieces must
//! have the same arrays).

use std::io;
use std::path::Path;

use crate::array::{DataArray, Encoding, Values};
use crate::doc::{escape, to_bytes, to_file};
use crate::error::VtkError;
use crate::image::ImageData;

fn extent(offset: [usize; 3], size: [usize; 3]) -> String {
    format!(
        "{} {} {} {} {} {}",
        offset[0],
        offset[0] + size[0] - 1,
        offset[1],
        offset[1] + size[1] - 1,
        offset[2],
        offset[2] + size[2] - 1
    )
}

/// One piece of a lattice of `whole` points: `image` holds its points (its `origin` is
/// that of the whole lattice's point `(0, 0, 0)`), which are points `offset ..
/// offset + image.size` of the whole.
#[derive(Clone, Copy, Debug)]
pub struct ImagePiece<'a> {
    /// The piece's points and data.
    pub image: ImageData<'a>,
    /// Index of the piece's first point in the whole lattice.
    pub offset: [usize; 3],
    /// Points per axis of the whole lattice.
    pub whole: [usize; 3],
}

impl ImagePiece<'_> {
    /// Check the piece's data and that it lies inside the whole lattice.
    pub fn check(&self) -> Result<(), VtkError> {
        self.image.check()?;
        for a in 0..3 {
            if self.offset[a] + self.image.size[a] > self.whole[a] {
                return Err(VtkError::Input(format!(
                    "image piece: points {:?} from {:?} are not inside the lattice of {:?}",
                    self.image.size, self.offset, self.whole
                )));
            }
        }
        Ok(())
    }

    fn emit(&self, w: &mut dyn io::Write, enc: Encoding) -> io::Result<()> {
        let whole = extent([0; 3], self.whole);
        let piece = extent(self.offset, self.image.size);
        self.image.emit_extents(w, enc, &whole, &piece)
    }

    /// The piece file's bytes.
    pub fn to_bytes(&self, enc: Encoding) -> Result<Vec<u8>, VtkError> {
        self.check()?;
        Ok(to_bytes(|w| self.emit(w, enc)))
    }

    /// Write the piece file atomically.
    pub fn write(&self, path: impl AsRef<Path>, enc: Encoding) -> Result<(), VtkError> {
        self.check()?;
        to_file(path.as_ref(), |w| self.emit(w, enc))
    }
}

/// The `.pvti` of a lattice written in pieces.
#[derive(Clone, Debug)]
pub struct PImageData<'a> {
    /// Points per axis of the whole lattice.
    pub whole: [usize; 3],
    /// Position of point `(0, 0, 0)`.
    pub origin: [f64; 3],
    /// Distance between neighbouring points along each axis.
    pub spacing: [f64; 3],
    /// The point arrays every piece has (their values are not read: name, type and
    /// components).
    pub point_data: &'a [DataArray<'a>],
    /// Each piece: its first point, its points per axis, and its file (relative to the
    /// `.pvti`).
    pub pieces: Vec<([usize; 3], [usize; 3], String)>,
}

impl PImageData<'_> {
    /// Check that every piece lies inside the whole lattice and that the pieces cover
    /// every point.
    pub fn check(&self) -> Result<(), VtkError> {
        let mut covered = vec![false; self.whole.iter().product()];
        for (offset, size, source) in &self.pieces {
            if (0..3).any(|a| size[a] == 0 || offset[a] + size[a] > self.whole[a]) {
                return Err(VtkError::Input(format!(
                    "parallel image data: piece {source} ({size:?} points from {offset:?}) \
                     is not inside the lattice of {:?}",
                    self.whole
                )));
            }
            for k in offset[2]..offset[2] + size[2] {
                for j in offset[1]..offset[1] + size[1] {
                    for i in offset[0]..offset[0] + size[0] {
                        covered[i + self.whole[0] * (j + self.whole[1] * k)] = true;
                    }
                }
            }
        }
        if let Some(p) = covered.iter().position(|c| !c) {
            return Err(VtkError::Input(format!(
                "parallel image data: no piece holds point {p} of the lattice of {:?}",
                self.whole
            )));
        }
        Ok(())
    }

    /// The `.pvti` text.
    pub fn to_string_checked(&self) -> Result<String, VtkError> {
        self.check()?;
        let [ox, oy, oz] = self.origin;
        let [sx, sy, sz] = self.spacing;
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"PImageData\" version=\"1.0\" \
             byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
        );
        s.push_str(&format!(
            "  <PImageData WholeExtent=\"{}\" GhostLevel=\"0\" Origin=\"{ox:?} {oy:?} {oz:?}\" \
             Spacing=\"{sx:?} {sy:?} {sz:?}\">\n    <PPointData>\n",
            extent([0; 3], self.whole)
        ));
        for a in self.point_data {
            let ty = match a.values {
                Values::F64(_) => "Float64",
                Values::I32(_) => "Int32",
                Values::I64(_) => "Int64",
                Values::U8(_) => "UInt8",
            };
            s.push_str(&format!("      <PDataArray type=\"{ty}\" Name=\""));
            escape(a.name, &mut s);
            s.push('"');
            if a.components != 1 {
                s.push_str(&format!(" NumberOfComponents=\"{}\"", a.components));
            }
            s.push_str("/>\n");
        }
        s.push_str("    </PPointData>\n");
        for (offset, size, source) in &self.pieces {
            s.push_str(&format!(
                "    <Piece Extent=\"{}\" Source=\"",
                extent(*offset, *size)
            ));
            escape(source, &mut s);
            s.push_str("\"/>\n");
        }
        s.push_str("  </PImageData>\n</VTKFile>\n");
        Ok(s)
    }

    /// Write the `.pvti` atomically.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<(), VtkError> {
        let text = self.to_string_checked()?;
        crate::atomic::write_atomic(path.as_ref(), text.as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::array::Attributes;

    #[test]
    fn pieces_name_the_whole_extent_and_their_own() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let arrays = [DataArray::new("p", 1, &v[..])];
        let piece = ImagePiece {
            image: ImageData {
                size: [3, 2, 1],
                origin: [0.5, 0.5, 0.0],
                spacing: [1.0; 3],
                field_data: &[],
                point_data: Attributes::new(&arrays),
                cell_data: Attributes::default(),
            },
            offset: [4, 0, 0],
            whole: [7, 2, 1],
        };
        let text = String::from_utf8(piece.to_bytes(Encoding::Ascii).unwrap()).unwrap();
        assert!(text.contains("WholeExtent=\"0 6 0 1 0 0\""), "{text}");
        assert!(text.contains("<Piece Extent=\"4 6 0 1 0 0\""), "{text}");
        // a piece reaching past the lattice is refused
        let out = ImagePiece {
            offset: [5, 0, 0],
            ..piece
        };
        assert!(out.check().is_err());

        let vel = [0.0; 3];
        let arrays = [
            DataArray::new("velocity", 3, &vel[..]),
            DataArray::new("p", 1, &v[..]),
        ];
        let mut p = PImageData {
            whole: [7, 2, 1],
            origin: [0.5, 0.5, 0.0],
            spacing: [1.0; 3],
            point_data: &arrays,
            pieces: vec![
                ([0, 0, 0], [5, 2, 1], "a_p0.vti".into()),
                ([4, 0, 0], [3, 2, 1], "a_p1.vti".into()),
            ],
        };
        let text = p.to_string_checked().unwrap();
        assert!(text.contains("<PImageData WholeExtent=\"0 6 0 1 0 0\" GhostLevel=\"0\""));
        assert!(
            text.contains(
                "<PDataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\"/>"
            )
        );
        assert!(text.contains("<Piece Extent=\"0 4 0 1 0 0\" Source=\"a_p0.vti\"/>"));
        assert!(text.contains("<Piece Extent=\"4 6 0 1 0 0\" Source=\"a_p1.vti\"/>"));
        // a gap between pieces is refused, naming the first point no piece holds
        p.pieces[1].0 = [6, 0, 0];
        p.pieces[1].1 = [1, 2, 1];
        let e = p.to_string_checked().unwrap_err().to_string();
        assert!(e.contains("no piece holds point 5"), "{e}");
    }
}
