//! The document writer shared by all file kinds: indentation, elements with escaped
//! attributes, data arrays in the three encodings, and the appended-data section.

use std::io::{self, Write};
use std::path::Path;

use base64::engine::general_purpose::STANDARD;
use base64::write::EncoderWriter;

use crate::array::{Attributes, DataArray, Encoding, Values};
use crate::atomic::write_atomic_with;
use crate::error::VtkError;

/// Bytes of values gathered before they are passed to the base64 encoder.
const CHUNK: usize = 3 << 13;

/// A VTK file being written to `w`.
pub(crate) struct Doc<'w> {
    w: &'w mut dyn Write,
    enc: Encoding,
    depth: usize,
    /// The appended blocks so far (`Encoding::Appended`).
    appended: Vec<u8>,
    /// Whether any array went to the appended section.
    any_appended: bool,
    buf: Vec<u8>,
}

/// Append `s` to `out` with XML's five special characters escaped.
pub(crate) fn escape(s: &str, out: &mut String) {
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
}

/// ` key="value"` for every attribute, values escaped.
fn attributes(attrs: &[(&str, &str)]) -> String {
    let mut s = String::new();
    for (k, v) in attrs {
        s.push(' ');
        s.push_str(k);
        s.push_str("=\"");
        escape(v, &mut s);
        s.push('"');
    }
    s
}

/// Value types: VTK name, and how one value is written.
trait Scalar: Copy {
    const VTK: &'static str;
    fn put_le(self, out: &mut Vec<u8>);
    fn put_text(self, out: &mut Vec<u8>);
}

macro_rules! scalar {
    ($t:ty, $name:literal, $fmt:literal) => {
        impl Scalar for $t {
            const VTK: &'static str = $name;
            fn put_le(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            fn put_text(self, out: &mut Vec<u8>) {
                let _ = write!(out, $fmt, self);
            }
        }
    };
}
scalar!(f64, "Float64", "{:?}");
scalar!(i32, "Int32", "{}");
scalar!(i64, "Int64", "{}");
scalar!(u8, "UInt8", "{}");

impl<'w> Doc<'w> {
    /// Write the XML declaration and open `<VTKFile type="kind">` and `<kind attrs>`.
    pub(crate) fn start(
        w: &'w mut dyn Write,
        enc: Encoding,
        kind: &str,
        attrs: &[(&str, &str)],
    ) -> io::Result<Self> {
        writeln!(
            w,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"{kind}\" version=\"1.0\" \
             byte_order=\"LittleEndian\" header_type=\"UInt64\">"
        )?;
        let mut doc = Self {
            w,
            enc,
            depth: 1,
            appended: Vec::new(),
            any_appended: false,
            buf: Vec::new(),
        };
        doc.open(kind, attrs)?;
        Ok(doc)
    }

    fn indent(&mut self) -> io::Result<()> {
        for _ in 0..self.depth {
            self.w.write_all(b"  ")?;
        }
        Ok(())
    }

    /// `<name attrs>` on its own line; the following lines are indented one level more.
    pub(crate) fn open(&mut self, name: &str, attrs: &[(&str, &str)]) -> io::Result<()> {
        self.indent()?;
        writeln!(self.w, "<{name}{}>", attributes(attrs))?;
        self.depth += 1;
        Ok(())
    }

    /// `</name>`.
    pub(crate) fn close(&mut self, name: &str) -> io::Result<()> {
        self.depth -= 1;
        self.indent()?;
        writeln!(self.w, "</{name}>")
    }

    /// `<name attrs>`, the arrays, `</name>`.
    pub(crate) fn section(
        &mut self,
        name: &str,
        attrs: &[(&str, &str)],
        arrays: &[DataArray<'_>],
    ) -> io::Result<()> {
        self.open(name, attrs)?;
        for a in arrays {
            self.array(a)?;
        }
        self.close(name)
    }

    /// `<PointData>` / `<CellData>` with the active scalars.
    pub(crate) fn attributes(&mut self, name: &str, a: &Attributes<'_>) -> io::Result<()> {
        match a.scalars {
            Some(s) => self.section(name, &[("Scalars", s)], a.arrays),
            None => self.section(name, &[], a.arrays),
        }
    }

    /// One `<DataArray>`.
    pub(crate) fn array(&mut self, a: &DataArray<'_>) -> io::Result<()> {
        match a.values {
            Values::F64(v) => self.typed(a, v),
            Values::I32(v) => self.typed(a, v),
            Values::I64(v) => self.typed(a, v),
            Values::U8(v) => self.typed(a, v),
        }
    }

    fn typed<T: Scalar>(&mut self, a: &DataArray<'_>, values: &[T]) -> io::Result<()> {
        let ncomp = a.components.max(1);
        let mut head = format!("<DataArray type=\"{}\" Name=\"", T::VTK);
        escape(a.name, &mut head);
        head.push('"');
        // One component is VTK's default; meshio reads an explicit 1 as an n × 1 array.
        if ncomp != 1 {
            head.push_str(&format!(" NumberOfComponents=\"{ncomp}\""));
        }
        for (k, n) in a.component_names.iter().enumerate() {
            head.push_str(&format!(" ComponentName{k}=\""));
            escape(n, &mut head);
            head.push('"');
        }
        if values.len().is_multiple_of(ncomp) {
            head.push_str(&format!(" NumberOfTuples=\"{}\"", values.len() / ncomp));
        }
        self.indent()?;
        self.w.write_all(head.as_bytes())?;
        let nbytes = size_of_val(values) as u64;
        match self.enc {
            Encoding::Ascii => {
                self.w.write_all(b" format=\"ascii\">\n")?;
                let per_line = (12 / ncomp).max(1) * ncomp;
                for chunk in values.chunks(per_line) {
                    self.buf.clear();
                    for _ in 0..=self.depth {
                        self.buf.extend_from_slice(b"  ");
                    }
                    for (i, &v) in chunk.iter().enumerate() {
                        if i > 0 {
                            self.buf.push(b' ');
                        }
                        v.put_text(&mut self.buf);
                    }
                    self.buf.push(b'\n');
                    self.w.write_all(&self.buf)?;
                }
            }
            Encoding::Base64 => {
                self.w.write_all(b" format=\"binary\">\n")?;
                for _ in 0..=self.depth {
                    self.w.write_all(b"  ")?;
                }
                {
                    // One base64 stream for the header and the values.
                    let mut enc = EncoderWriter::new(&mut *self.w, &STANDARD);
                    self.buf.clear();
                    self.buf.extend_from_slice(&nbytes.to_le_bytes());
                    for &v in values {
                        v.put_le(&mut self.buf);
                        if self.buf.len() >= CHUNK {
                            enc.write_all(&self.buf)?;
                            self.buf.clear();
                        }
                    }
                    enc.write_all(&self.buf)?;
                    enc.finish()?;
                }
                self.w.write_all(b"\n")?;
            }
            Encoding::Appended => {
                writeln!(
                    self.w,
                    " format=\"appended\" offset=\"{}\"/>",
                    self.appended.len()
                )?;
                self.any_appended = true;
                self.appended.extend_from_slice(&nbytes.to_le_bytes());
                for &v in values {
                    v.put_le(&mut self.appended);
                }
                return Ok(());
            }
        }
        self.indent()?;
        self.w.write_all(b"</DataArray>\n")
    }

    /// Close `<kind>`, write the appended data if any, and close `<VTKFile>`.
    pub(crate) fn finish(mut self, kind: &str) -> io::Result<()> {
        self.close(kind)?;
        if self.any_appended {
            self.w
                .write_all(b"  <AppendedData encoding=\"raw\">\n   _")?;
            self.w.write_all(&self.appended)?;
            self.w.write_all(b"\n  </AppendedData>\n")?;
        }
        self.w.write_all(b"</VTKFile>\n")
    }
}

/// The bytes that `body` writes.
pub(crate) fn to_bytes(body: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> Vec<u8> {
    let mut out = Vec::new();
    // Writing to a vector cannot fail.
    let _ = body(&mut out);
    out
}

/// Write `path` atomically with what `body` writes.
pub(crate) fn to_file(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), VtkError> {
    write_atomic_with(path, body)
}

/// `n` as text, for attributes.
pub(crate) fn num(n: usize) -> String {
    n.to_string()
}
