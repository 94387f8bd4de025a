//! Standard base64 (RFC 4648, alphabet `A–Z a–z 0–9 + /`, `=` padding) for reading VTK's
//! binary data, on top of the `base64` crate.
//!
//! VTK writes some arrays as *several* base64 streams back to back: with compression, the
//! block header and the compressed blocks are encoded separately, so `=` padding may end a
//! 4-character group in the middle of the text. [`decode`] splits the text after every
//! padded group and decodes the pieces one after the other.

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;

/// Append the base64 encoding of `bytes` to `out` (test data).
#[cfg(test)]
pub(crate) fn encode_into(bytes: &[u8], out: &mut String) {
    STANDARD.encode_string(bytes, out);
}

/// Decode base64 text (ASCII whitespace ignored) made of one or more padded streams.
/// Returns what is wrong on error.
pub(crate) fn decode(text: &[u8]) -> Result<Vec<u8>, String> {
    let text = text.trim_ascii();
    let compact: Vec<u8>;
    let mut rest = if text.iter().any(u8::is_ascii_whitespace) {
        compact = text
            .iter()
            .copied()
            .filter(|b| !b.is_ascii_whitespace())
            .collect();
        &compact[..]
    } else {
        text
    };
    if rest.len() % 4 != 0 {
        return Err(format!(
            "base64 text of {} characters is not a multiple of 4",
            rest.len()
        ));
    }
    let mut out = Vec::with_capacity(rest.len() / 4 * 3);
    let mut done = 0;
    while !rest.is_empty() {
        // One stream: up to and including the first group that ends with `=`.
        let end = rest
            .chunks_exact(4)
            .position(|g| g[3] == b'=')
            .map_or(rest.len(), |k| 4 * k + 4);
        STANDARD
            .decode_vec(&rest[..end], &mut out)
            .map_err(|e| match e {
                base64::DecodeError::InvalidByte(at, b) => format!(
                    "invalid base64 character {:?} at character {}",
                    b as char,
                    done + at
                ),
                other => format!("invalid base64 near character {done}: {other}"),
            })?;
        done += end;
        rest = &rest[end..];
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rfc4648_vectors() {
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, enc) in cases {
            let mut s = String::new();
            encode_into(plain.as_bytes(), &mut s);
            assert_eq!(s, enc);
            assert_eq!(decode(enc.as_bytes()).unwrap(), plain.as_bytes());
        }
        // Two streams back to back (header encoded separately), with whitespace.
        assert_eq!(decode(b"Zg==\n Zm9v").unwrap(), b"ffoo");
        assert_eq!(decode(b"Zm8=Zg==Zm9vYmFy\n").unwrap(), b"foffoobar");
        assert!(decode(b"Zm9").is_err());
        assert!(decode(b"Zm*v").unwrap_err().contains("'*'"));
        assert!(decode(b"Z===").is_err());
        let all: Vec<u8> = (0..=255).collect();
        let mut s = String::new();
        encode_into(&all, &mut s);
        assert_eq!(decode(s.as_bytes()).unwrap(), all);
    }
}
