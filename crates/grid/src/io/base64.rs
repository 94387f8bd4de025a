//! Standard base64 (RFC 4648, alphabet `A–Z a–z 0–9 + /`, `=` padding), as used by VTK's
//! inline binary data.

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Append the base64 encoding of `bytes` to `out`.
pub(crate) fn encode_into(bytes: &[u8], out: &mut String) {
    out.reserve(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        let sym = |k: u32| ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char;
        out.push(sym(0));
        out.push(sym(1));
        out.push(if chunk.len() > 1 { sym(2) } else { '=' });
        out.push(if chunk.len() > 2 { sym(3) } else { '=' });
    }
}

fn value(c: u8) -> Option<u32> {
    Some(match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => return None,
    } as u32)
}

/// Decode base64 text (ASCII whitespace ignored). Padding may appear at the end of any
/// 4-character group (VTK may encode a header and the data as two separate streams).
/// Returns the offending character on error.
pub(crate) fn decode(text: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let mut group = [0u32; 4];
    let mut len = 0;
    let mut pad = 0;
    for &c in text.as_bytes() {
        if c.is_ascii_whitespace() {
            continue;
        }
        if c == b'=' {
            if len < 2 {
                return Err("misplaced `=` padding".into());
            }
            pad += 1;
            group[len] = 0;
            len += 1;
        } else {
            if pad > 0 {
                return Err("data after `=` padding inside a group".into());
            }
            group[len] =
                value(c).ok_or_else(|| format!("invalid base64 character `{}`", c as char))?;
            len += 1;
        }
        if len == 4 {
            let n = (group[0] << 18) | (group[1] << 12) | (group[2] << 6) | group[3];
            let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
            out.extend_from_slice(&bytes[..3 - pad]);
            len = 0;
            pad = 0;
        }
    }
    if len != 0 {
        return Err("base64 text length is not a multiple of 4".into());
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
            assert_eq!(decode(enc).unwrap(), plain.as_bytes());
        }
        // Two streams back to back (header encoded separately), with whitespace.
        assert_eq!(decode("Zg==\n Zm9v").unwrap(), b"ffoo");
        assert!(decode("Zm9").is_err());
        assert!(decode("Zm*v").is_err());
        let all: Vec<u8> = (0..=255).collect();
        let mut s = String::new();
        encode_into(&all, &mut s);
        assert_eq!(decode(&s).unwrap(), all);
    }
}
