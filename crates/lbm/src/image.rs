//! Solid maps from grey-level images: a digitised rock (a segmented micro-CT slice, a thin
//! section) read from a PGM (`P2` text or `P5` binary) or PNG file, thresholded into grain
//! and pore pixels, sampled at the lattice nodes and cut into axis-aligned rectangles of
//! nodes that the lattice takes as fixed obstacles.
//!
//! **Sampling.** Pixel `(c, r)` of a `w × h` image (row 0 at the top, as image files store
//! them) covers `[x₀ + c p, x₀ + (c+1) p] × [y₀ + (h−1−r) p, y₀ + (h−r) p]`, `p` the pixel
//! size and `(x₀, y₀)` the image's lower-left corner; a lattice node is solid when the pixel
//! under its centre is a grain pixel (nearest-pixel sampling; nodes off the image are
//! fluid). A pixel is a grain pixel when its grey level, as a fraction of the format's white
//! (`maxval` of a PGM, 255 or 65535 of a PNG), is at or above the threshold
//! ([`Polarity::Above`]: bright grains, the usual segmentation) or below it
//! ([`Polarity::Below`]).
//!
//! **Rectangles.** [`rectangles`] merges equal runs of solid nodes of consecutive rows
//! into rectangles whose sides lie on the halfway lines between nodes, so an obstacle box
//! from them covers exactly its nodes and every cut link has `δ = ½` (halfway
//! bounce-back, as a voxel image implies).
//!
//! Sizes are checked from the header before anything is allocated ([`MAX_SIDE`],
//! [`MAX_PIXELS`]); a bad file is an [`ImageError`] that says where (the 1-based line of a
//! PGM header or text value).

use std::path::Path;

/// Largest image side accepted (pixels).
pub const MAX_SIDE: usize = 1 << 15;
/// Largest image accepted (pixels).
pub const MAX_PIXELS: usize = 1 << 26;

/// A grey-level image, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct GreyImage {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// The grey level of white (`maxval`).
    pub white: u16,
    /// Grey levels, row after row from the top.
    pub pixels: Vec<u16>,
}

/// Which pixels are grains.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Polarity {
    /// Grey level at or above the threshold (bright grains).
    #[default]
    Above,
    /// Grey level below the threshold (dark grains).
    Below,
}

/// What went wrong reading an image.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ImageError {
    /// The file could not be read.
    #[error("cannot read the file: {0}")]
    Io(String),
    /// Neither a PGM nor a PNG file.
    #[error("not a PGM (P2, P5) or PNG file (it starts with {0:?})")]
    Kind(String),
    /// A PGM file that breaks the format.
    #[error("line {line}: {what}")]
    Pgm {
        /// 1-based line of the file.
        line: usize,
        /// What is wrong.
        what: String,
    },
    /// A PNG file the decoder refuses.
    #[error("PNG: {0}")]
    Png(String),
    /// An image too large.
    #[error(
        "{width} × {height} pixels: at most {MAX_SIDE} per side and {MAX_PIXELS} in all are accepted"
    )]
    TooLarge {
        /// Columns.
        width: usize,
        /// Rows.
        height: usize,
    },
}

impl GreyImage {
    /// Read a PGM or PNG file (told apart by its first bytes).
    pub fn read(path: &Path) -> Result<Self, ImageError> {
        let meta = std::fs::metadata(path).map_err(|e| ImageError::Io(e.to_string()))?;
        // a PGM of the largest accepted size in text, with room for comments
        let limit = (MAX_PIXELS as u64) * 8 + (1 << 20);
        if meta.len() > limit {
            return Err(ImageError::Io(format!(
                "{} bytes: larger than any accepted image ({limit} bytes)",
                meta.len()
            )));
        }
        let bytes = std::fs::read(path).map_err(|e| ImageError::Io(e.to_string()))?;
        Self::parse(&bytes)
    }

    /// Parse the bytes of a PGM or PNG file.
    pub fn parse(bytes: &[u8]) -> Result<Self, ImageError> {
        if bytes.starts_with(b"\x89PNG") {
            parse_png(bytes)
        } else if bytes.starts_with(b"P2") || bytes.starts_with(b"P5") {
            parse_pgm(bytes)
        } else {
            let head: String = bytes
                .iter()
                .take(4)
                .map(|&b| if b.is_ascii_graphic() { b as char } else { '.' })
                .collect();
            Err(ImageError::Kind(head))
        }
    }

    /// Grey level of pixel `(c, r)` (row 0 at the top) as a fraction of white.
    pub fn level(&self, c: usize, r: usize) -> f64 {
        f64::from(self.pixels[r * self.width + c]) / f64::from(self.white)
    }

    /// Whether pixel `(c, r)` is a grain pixel.
    pub fn is_grain(&self, c: usize, r: usize, threshold: f64, polarity: Polarity) -> bool {
        let v = self.level(c, r);
        match polarity {
            Polarity::Above => v >= threshold,
            Polarity::Below => v < threshold,
        }
    }

    /// The solid map of an `nx × ny` lattice (x fastest, row 0 at the bottom) whose node
    /// `(i, j)` sits at `(i + ½, j + ½)` spacings from the lattice's corner, with the
    /// image's lower-left corner at `corner` and its pixels `pixel` wide (both in lattice
    /// spacings).
    pub fn solid_map(
        &self,
        nx: usize,
        ny: usize,
        corner: [f64; 2],
        pixel: f64,
        threshold: f64,
        polarity: Polarity,
    ) -> Vec<bool> {
        let mut solid = vec![false; nx * ny];
        for j in 0..ny {
            let y = (j as f64 + 0.5 - corner[1]) / pixel;
            if !(y >= 0.0 && y < self.height as f64) {
                continue;
            }
            let r = self.height - 1 - (y.floor() as usize).min(self.height - 1);
            for i in 0..nx {
                let x = (i as f64 + 0.5 - corner[0]) / pixel;
                if !(x >= 0.0 && x < self.width as f64) {
                    continue;
                }
                let c = (x.floor() as usize).min(self.width - 1);
                solid[j * nx + i] = self.is_grain(c, r, threshold, polarity);
            }
        }
        solid
    }
}

/// Rectangles of solid nodes `[i0, j0, i1, j1]` (inclusive node ranges) covering every
/// solid node of `solid` (`nx × ny`, x fastest) exactly once: equal runs of consecutive
/// rows are merged.
pub fn rectangles(solid: &[bool], nx: usize, ny: usize) -> Vec<[usize; 4]> {
    let mut done = Vec::new();
    // open rectangles: runs of the previous row [i0, i1] and their first row
    let mut open: Vec<[usize; 3]> = Vec::new();
    for j in 0..ny {
        let row = &solid[j * nx..(j + 1) * nx];
        let mut runs = Vec::new();
        let mut i = 0;
        while i < nx {
            if row[i] {
                let i0 = i;
                while i < nx && row[i] {
                    i += 1;
                }
                runs.push([i0, i - 1]);
            } else {
                i += 1;
            }
        }
        let mut next = Vec::with_capacity(runs.len());
        for run in runs {
            match open.iter().position(|o| o[0] == run[0] && o[1] == run[1]) {
                Some(p) => next.push(open.swap_remove(p)),
                None => next.push([run[0], run[1], j]),
            }
        }
        for o in open {
            done.push([o[0], o[2], o[1], j - 1]);
        }
        open = next;
    }
    for o in open {
        done.push([o[0], o[2], o[1], ny - 1]);
    }
    done.sort_unstable_by_key(|r| (r[1], r[0]));
    done
}

/// A PGM header or text value: the next token and its 1-based line; comments (`#` to the
/// end of the line) and white space are skipped.
struct Tokens<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Tokens<'a> {
    fn next(&mut self) -> Option<(&'a [u8], usize)> {
        let b = self.bytes;
        loop {
            while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
                if b[self.pos] == b'\n' {
                    self.line += 1;
                }
                self.pos += 1;
            }
            if self.pos < b.len() && b[self.pos] == b'#' {
                while self.pos < b.len() && b[self.pos] != b'\n' {
                    self.pos += 1;
                }
                continue;
            }
            break;
        }
        if self.pos >= b.len() {
            return None;
        }
        let start = self.pos;
        while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() && b[self.pos] != b'#' {
            self.pos += 1;
        }
        Some((&b[start..self.pos], self.line))
    }

    fn number(&mut self, what: &str, max: usize) -> Result<usize, ImageError> {
        let line = self.line;
        let (tok, line) = self.next().ok_or_else(|| ImageError::Pgm {
            line,
            what: format!("the file ends before the {what}"),
        })?;
        let s = String::from_utf8_lossy(tok);
        match s.parse::<usize>() {
            Ok(v) if v <= max => Ok(v),
            Ok(v) => Err(ImageError::Pgm {
                line,
                what: format!("{what} {v} is above {max}"),
            }),
            Err(_) => Err(ImageError::Pgm {
                line,
                what: format!("{what} \"{s}\" is not a whole number"),
            }),
        }
    }
}

fn parse_pgm(bytes: &[u8]) -> Result<GreyImage, ImageError> {
    let binary = bytes[1] == b'5';
    let mut t = Tokens {
        bytes,
        pos: 2,
        line: 1,
    };
    let width = t.number("width", usize::MAX)?;
    let height = t.number("height", usize::MAX)?;
    if width == 0 || height == 0 {
        return Err(ImageError::Pgm {
            line: t.line,
            what: format!("{width} × {height} pixels: an empty image"),
        });
    }
    if width > MAX_SIDE || height > MAX_SIDE || width * height > MAX_PIXELS {
        return Err(ImageError::TooLarge { width, height });
    }
    let white = t.number("maxval", 65535)?;
    if white == 0 {
        return Err(ImageError::Pgm {
            line: t.line,
            what: "maxval 0 (must be 1 to 65535)".into(),
        });
    }
    let n = width * height;
    let mut pixels = Vec::with_capacity(n);
    if binary {
        // one white-space byte after maxval, then the raster
        let start = t.pos + 1;
        let size = if white < 256 { 1 } else { 2 };
        let need = n * size;
        let have = bytes.len().saturating_sub(start);
        if have < need {
            return Err(ImageError::Pgm {
                line: t.line,
                what: format!(
                    "{width} × {height} pixels need {need} bytes of raster after the header, \
                     the file has {have}"
                ),
            });
        }
        let raster = &bytes[start..start + need];
        if size == 1 {
            pixels.extend(raster.iter().map(|&b| u16::from(b)));
        } else {
            pixels.extend(
                raster
                    .chunks_exact(2)
                    .map(|c| u16::from_be_bytes([c[0], c[1]])),
            );
        }
    } else {
        for k in 0..n {
            let v = t.number(&format!("grey level of pixel {}", k + 1), usize::MAX)?;
            if v > white {
                return Err(ImageError::Pgm {
                    line: t.line,
                    what: format!("grey level {v} of pixel {} is above maxval {white}", k + 1),
                });
            }
            pixels.push(v as u16);
        }
    }
    if let Some(&p) = pixels.iter().find(|&&p| usize::from(p) > white) {
        return Err(ImageError::Pgm {
            line: t.line,
            what: format!("grey level {p} in the raster is above maxval {white}"),
        });
    }
    Ok(GreyImage {
        width,
        height,
        white: white as u16,
        pixels,
    })
}

fn parse_png(bytes: &[u8]) -> Result<GreyImage, ImageError> {
    let err = |e: png::DecodingError| ImageError::Png(e.to_string());
    let mut dec = png::Decoder::new_with_limits(
        std::io::Cursor::new(bytes),
        png::Limits {
            bytes: 4 * MAX_PIXELS,
        },
    );
    dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = dec.read_info().map_err(err)?;
    let (w, h) = reader.info().size();
    let (width, height) = (w as usize, h as usize);
    if width == 0 || height == 0 {
        return Err(ImageError::Png(format!(
            "{width} × {height} pixels: an empty image"
        )));
    }
    if width > MAX_SIDE || height > MAX_SIDE || width * height > MAX_PIXELS {
        return Err(ImageError::TooLarge { width, height });
    }
    let mut buf = vec![0u8; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).map_err(err)?;
    let channels = info.color_type.samples();
    let line = info.line_size;
    let mut pixels = Vec::with_capacity(width * height);
    for r in 0..height {
        let row = &buf[r * line..];
        for c in 0..width {
            let p = &row[c * channels..c * channels + channels];
            let grey = match channels {
                // grey, grey + alpha
                1 | 2 => f64::from(p[0]),
                // RGB, RGBA: luma (ITU-R BT.601)
                _ => 0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2]),
            };
            pixels.push(grey.round() as u16);
        }
    }
    Ok(GreyImage {
        width,
        height,
        white: 255,
        pixels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_and_binary_pgm_agree_and_sample_onto_the_lattice() {
        let text = b"P2\n# a grain in the top-left corner\n3 2\n255\n255 0 0\n0 0 128\n";
        let a = GreyImage::parse(text).unwrap();
        let mut bin = b"P5 3 2 255\n".to_vec();
        bin.extend([255u8, 0, 0, 0, 0, 128]);
        let b = GreyImage::parse(&bin).unwrap();
        assert_eq!(a, b);
        assert_eq!((a.width, a.height, a.white), (3, 2, 255));
        // two nodes per pixel: the image's top-left pixel covers nodes (0..2, 2..4)
        let s = a.solid_map(6, 4, [0.0, 0.0], 2.0, 0.5, Polarity::Above);
        let solid: Vec<(usize, usize)> =
            (0..24).filter(|&n| s[n]).map(|n| (n % 6, n / 6)).collect();
        assert_eq!(
            solid,
            vec![
                (4, 0),
                (5, 0),
                (4, 1),
                (5, 1),
                (0, 2),
                (1, 2),
                (0, 3),
                (1, 3)
            ]
        );
        // the other polarity is the complement
        let d = a.solid_map(6, 4, [0.0, 0.0], 2.0, 0.5, Polarity::Below);
        assert!(s.iter().zip(&d).all(|(x, y)| x != y));
        // off the image: fluid
        let off = a.solid_map(6, 4, [10.0, 0.0], 2.0, 0.0, Polarity::Above);
        assert!(off.iter().all(|x| !x));
    }

    #[test]
    fn png_reads_grey_and_colour() {
        for (colour, samples) in [(png::ColorType::Grayscale, 1), (png::ColorType::Rgb, 3)] {
            let mut bytes = Vec::new();
            {
                let mut enc = png::Encoder::new(&mut bytes, 2, 2);
                enc.set_color(colour);
                enc.set_depth(png::BitDepth::Eight);
                let mut w = enc.write_header().unwrap();
                let data: Vec<u8> = [0u8, 255, 200, 10]
                    .iter()
                    .flat_map(|&v| std::iter::repeat_n(v, samples))
                    .collect();
                w.write_image_data(&data).unwrap();
            }
            let img = GreyImage::parse(&bytes).unwrap();
            assert_eq!(img.pixels, vec![0, 255, 200, 10]);
            assert_eq!(img.white, 255);
        }
    }

    #[test]
    fn bad_files_say_where() {
        let e = GreyImage::parse(b"P2\n3 2\n255\n1 2 3\n4 x 6\n").unwrap_err();
        assert_eq!(
            e,
            ImageError::Pgm {
                line: 5,
                what: "grey level of pixel 5 \"x\" is not a whole number".into()
            }
        );
        let e = GreyImage::parse(b"P2\n3 2\n255\n1 2 3\n4 5\n").unwrap_err();
        assert!(matches!(e, ImageError::Pgm { line: 5, .. }), "{e}");
        let e = GreyImage::parse(b"P2\n3 2\n# white\n100\n1 2 3\n4 500 6\n").unwrap_err();
        assert!(e.to_string().contains("line 6") && e.to_string().contains("above maxval"));
        let e = GreyImage::parse(b"P5 3 2 255\n\x01\x02").unwrap_err();
        assert!(e.to_string().contains("need 6 bytes"), "{e}");
        let e = GreyImage::parse(b"GIF89a").unwrap_err();
        assert_eq!(e, ImageError::Kind("GIF8".into()));
        let e = GreyImage::parse(b"\x89PNG\r\n\x1a\nbroken").unwrap_err();
        assert!(matches!(e, ImageError::Png(_)));
    }

    #[test]
    fn hostile_sizes_are_refused_before_allocating() {
        // the header claims 4e10 pixels in a 20-byte file
        let e = GreyImage::parse(b"P5 200000 200000 255\n").unwrap_err();
        assert_eq!(
            e,
            ImageError::TooLarge {
                width: 200000,
                height: 200000
            }
        );
        let e = GreyImage::parse(b"P2 99999999999999999999999 2 255\n").unwrap_err();
        assert!(matches!(e, ImageError::Pgm { line: 1, .. }), "{e}");
        let e = GreyImage::parse(b"P2 30000 30000 255\n").unwrap_err();
        assert!(matches!(e, ImageError::TooLarge { .. }));
        // a PNG header of 2^31 × 2^31 pixels
        let mut bytes = Vec::new();
        {
            let enc = png::Encoder::new(&mut bytes, 1, 1);
            let mut w = enc.write_header().unwrap();
            w.write_image_data(&[0]).unwrap();
        }
        // IHDR width and height at bytes 16..24; fix the chunk's CRC
        bytes[16..20].copy_from_slice(&40000u32.to_be_bytes());
        bytes[20..24].copy_from_slice(&40000u32.to_be_bytes());
        let crc = crc32(&bytes[12..29]);
        bytes[29..33].copy_from_slice(&crc.to_be_bytes());
        let e = GreyImage::parse(&bytes).unwrap_err();
        assert!(
            matches!(e, ImageError::TooLarge { .. } | ImageError::Png(_)),
            "{e}"
        );
    }

    fn crc32(data: &[u8]) -> u32 {
        let mut c = 0xFFFF_FFFFu32;
        for &b in data {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    #[test]
    fn rectangles_cover_every_solid_node_once() {
        let (nx, ny) = (13, 9);
        let solid: Vec<bool> = (0..nx * ny)
            .map(|n| {
                let (i, j) = ((n % nx) as f64, (n / nx) as f64);
                (i - 5.0).powi(2) + (j - 4.0).powi(2) < 10.0 || (i > 10.0 && j < 3.0)
            })
            .collect();
        let rects = rectangles(&solid, nx, ny);
        let mut count = vec![0; nx * ny];
        for r in &rects {
            for j in r[1]..=r[3] {
                for i in r[0]..=r[2] {
                    count[j * nx + i] += 1;
                }
            }
        }
        for n in 0..nx * ny {
            assert_eq!(count[n], usize::from(solid[n]), "node {n}");
        }
        // the disk's symmetric rows merge: fewer rectangles than solid rows' runs
        let runs: usize = (0..ny)
            .map(|j| {
                (0..nx)
                    .filter(|&i| solid[j * nx + i] && (i == 0 || !solid[j * nx + i - 1]))
                    .count()
            })
            .sum();
        assert!(
            rects.len() < runs,
            "{} rectangles, {runs} runs",
            rects.len()
        );
    }
}
