//! The mutator of the mutation harness: a seeded generator and the text mutations of
//! scene files (TOML), corner-point decks (GRDECL) and meshes (VTK XML).
//!
//! Every mutation is a pure function of the input text and the generator, so a seed, a
//! file and a round name one mutant exactly.

/// A small deterministic generator (SplitMix64): the same seed gives the same mutants on
/// every machine.
pub struct Rng(u64);

impl Rng {
    /// A generator for one mutant: mixes the run's seed, the file's name and the round.
    pub fn for_mutant(seed: u64, file: &str, round: u64) -> Self {
        // FNV-1a of the file name: stable across platforms and runs.
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in file.bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        let mut r = Rng(seed ^ h.rotate_left(17) ^ round.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        r.next();
        r
    }

    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A uniform index in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    /// One element of a non-empty slice.
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Hostile replacements of a number.
pub const HOSTILE_NUMBERS: [&str; 10] = [
    "0",
    "-1",
    "1e300",
    "-1e300",
    "1e-300",
    "nan",
    "inf",
    "18446744073709551615",
    "2147483648",
    "1e20",
];

/// Hostile repeat counts of a deck's `n*v`.
const HOSTILE_REPEATS: [&str; 5] = [
    "0",
    "18446744073709551615",
    "2147483648",
    "1000000000000",
    "-1",
];

/// What kind of input a file is; each kind has its own mutations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A scene file (TOML).
    Scene,
    /// A corner-point deck (GRDECL).
    Deck,
    /// A mesh file (VTK XML).
    Mesh,
}

/// One mutant: the mutated bytes, what was done, and the 1-based line it was done on
/// (0 when the mutation is not on one line).
pub struct Mutant {
    /// The mutated file.
    pub bytes: Vec<u8>,
    /// What the mutation did, in one line.
    pub what: String,
}

/// Mutate `text` of the given kind once.
pub fn mutate(kind: Kind, text: &str, rng: &mut Rng) -> Mutant {
    // Each kind tries its operations in a random order until one applies (a file
    // without strings cannot have a string replaced).
    let ops: &[Op] = match kind {
        Kind::Scene => &[
            Op::Number,
            Op::Number,
            Op::Number,
            Op::Number,
            Op::String,
            Op::String,
            Op::DeleteLine,
            Op::DuplicateLine,
            Op::DropHeader,
            Op::Truncate,
            Op::SwapValues,
        ],
        Kind::Deck => &[
            Op::Number,
            Op::Number,
            Op::Repeat,
            Op::Repeat,
            Op::DropSlash,
            Op::KeywordNumbers,
            Op::KeywordNumbers,
            Op::DeleteLine,
            Op::DuplicateLine,
            Op::Truncate,
        ],
        Kind::Mesh => &[
            Op::Number,
            Op::Number,
            Op::String,
            Op::Base64,
            Op::Base64,
            Op::DeleteLine,
            Op::DuplicateLine,
            Op::Truncate,
        ],
    };
    for _ in 0..32 {
        if let Some(m) = apply(*rng.pick(ops), kind, text, rng) {
            return m;
        }
    }
    apply(Op::Truncate, kind, text, rng).expect("truncation always applies")
}

#[derive(Clone, Copy, Debug)]
enum Op {
    Number,
    String,
    DeleteLine,
    DuplicateLine,
    DropHeader,
    Truncate,
    SwapValues,
    Repeat,
    DropSlash,
    KeywordNumbers,
    Base64,
}

/// The part of a line that is not a comment (`#` outside a string for TOML, `--` for
/// decks); mesh lines have no comments.
fn code_len(kind: Kind, line: &str) -> usize {
    match kind {
        Kind::Scene => {
            let mut in_str = false;
            let mut prev = ' ';
            for (i, c) in line.char_indices() {
                match c {
                    '"' if prev != '\\' => in_str = !in_str,
                    '#' if !in_str => return i,
                    _ => {}
                }
                prev = c;
            }
            line.len()
        }
        Kind::Deck => line.find("--").unwrap_or(line.len()),
        Kind::Mesh => line.len(),
    }
}

/// Byte spans of the numbers in the code part of a line.
fn numbers(kind: Kind, line: &str) -> Vec<(usize, usize)> {
    let code = &line.as_bytes()[..code_len(kind, line)];
    let mut spans = Vec::new();
    let mut i = 0;
    while i < code.len() {
        let prev_ok = i == 0 || !(code[i - 1].is_ascii_alphanumeric() || code[i - 1] == b'_');
        let starts = code[i].is_ascii_digit()
            || ((code[i] == b'-' || code[i] == b'+' || code[i] == b'.')
                && code.get(i + 1).is_some_and(u8::is_ascii_digit));
        if !(prev_ok && starts) {
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        while i < code.len() && (code[i].is_ascii_digit() || code[i] == b'.') {
            i += 1;
        }
        if i < code.len() && (code[i] == b'e' || code[i] == b'E') {
            let mut j = i + 1;
            if j < code.len() && (code[j] == b'-' || code[j] == b'+') {
                j += 1;
            }
            if j < code.len() && code[j].is_ascii_digit() {
                i = j;
                while i < code.len() && code[i].is_ascii_digit() {
                    i += 1;
                }
            }
        }
        // `3*0.25` in a deck: the repeat count and the value are separate numbers.
        spans.push((start, i));
    }
    spans
}

/// Byte spans of the contents of the double-quoted strings in the code part of a line.
fn strings(kind: Kind, line: &str) -> Vec<(usize, usize)> {
    let code = &line.as_bytes()[..code_len(kind, line)];
    let mut spans = Vec::new();
    let mut open = None;
    for (i, &b) in code.iter().enumerate() {
        if b == b'"' && (i == 0 || code[i - 1] != b'\\') {
            match open.take() {
                None => open = Some(i + 1),
                Some(s) => spans.push((s, i)),
            }
        }
    }
    spans
}

/// Lines with something other than blanks and comments: 0-based indices.
fn code_lines(kind: Kind, lines: &[&str]) -> Vec<usize> {
    (0..lines.len())
        .filter(|&i| !lines[i][..code_len(kind, lines[i])].trim().is_empty())
        .collect()
}

/// The key of a TOML `key = value` line.
fn key_of(line: &str) -> Option<String> {
    let eq = line.find('=')?;
    let key = line[..eq].trim();
    (!key.is_empty() && !key.starts_with('[') && !key.contains('"')).then(|| key.to_string())
}

fn join(lines: &[String], trailing_newline: bool) -> Vec<u8> {
    let mut s = lines.join("\n");
    if trailing_newline {
        s.push('\n');
    }
    s.into_bytes()
}

fn shorten(s: &str) -> String {
    let s = s.trim();
    if s.chars().count() > 60 {
        format!("{}…", s.chars().take(60).collect::<String>())
    } else {
        s.to_string()
    }
}

fn apply(op: Op, kind: Kind, text: &str, rng: &mut Rng) -> Option<Mutant> {
    let lines: Vec<&str> = text.lines().collect();
    let nl = text.ends_with('\n');
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    let code = code_lines(kind, &lines);
    // Base64 lines of a mesh are data, not attributes: only tag lines carry numbers
    // and strings worth replacing.
    let tag_line = |i: &&usize| kind != Kind::Mesh || lines[**i].trim_start().starts_with('<');
    let replace_span = |out: &mut Vec<String>, i: usize, (s, e): (usize, usize), by: &str| {
        let old = out[i][s..e].to_string();
        out[i].replace_range(s..e, by);
        old
    };
    match op {
        Op::Number => {
            let cands: Vec<(usize, (usize, usize))> = code
                .iter()
                .filter(tag_line)
                .flat_map(|&i| numbers(kind, lines[i]).into_iter().map(move |s| (i, s)))
                .collect();
            if cands.is_empty() {
                return None;
            }
            let &(i, span) = rng.pick(&cands);
            let by = *rng.pick(&HOSTILE_NUMBERS);
            if lines[i][span.0..span.1] == *by {
                return None;
            }
            let old = replace_span(&mut out, i, span, by);
            Some(Mutant {
                what: format!(
                    "line {}: number {old} -> {by} in `{}`",
                    i + 1,
                    shorten(&out[i])
                ),
                bytes: join(&out, nl),
            })
        }
        Op::String => {
            let cands: Vec<(usize, (usize, usize))> = code
                .iter()
                .filter(tag_line)
                .flat_map(|&i| strings(kind, lines[i]).into_iter().map(move |s| (i, s)))
                .collect();
            if cands.is_empty() {
                return None;
            }
            let &(i, span) = rng.pick(&cands);
            let long = "a".repeat(10_000);
            let choices = ["", long.as_str(), "1/0", "x"];
            let by = *rng.pick(&choices);
            if lines[i][span.0..span.1] == *by {
                return None;
            }
            let old = replace_span(&mut out, i, span, by);
            let shown = if by.len() > 100 { "a 10 kB string" } else { by };
            Some(Mutant {
                what: format!(
                    "line {}: string \"{}\" -> \"{shown}\"",
                    i + 1,
                    shorten(&old)
                ),
                bytes: join(&out, nl),
            })
        }
        Op::DeleteLine | Op::DuplicateLine => {
            if code.is_empty() {
                return None;
            }
            let i = *rng.pick(&code);
            let line = out[i].clone();
            let verb = if matches!(op, Op::DeleteLine) {
                out.remove(i);
                "deleted"
            } else {
                out.insert(i, line.clone());
                "duplicated"
            };
            Some(Mutant {
                what: format!("line {} {verb}: `{}`", i + 1, shorten(&line)),
                bytes: join(&out, nl),
            })
        }
        Op::DropHeader => {
            let heads: Vec<usize> = code
                .iter()
                .copied()
                .filter(|&i| lines[i].trim_start().starts_with('['))
                .collect();
            if heads.is_empty() {
                return None;
            }
            let i = *rng.pick(&heads);
            let line = out.remove(i);
            Some(Mutant {
                what: format!("line {}: header `{}` dropped", i + 1, line.trim()),
                bytes: join(&out, nl),
            })
        }
        Op::Truncate => {
            let at = rng.below(text.len().max(1));
            Some(Mutant {
                what: format!("truncated at byte {at} of {}", text.len()),
                bytes: text.as_bytes()[..at].to_vec(),
            })
        }
        Op::SwapValues => {
            let kv: Vec<usize> = code
                .iter()
                .copied()
                .filter(|&i| key_of(lines[i]).is_some())
                .collect();
            if kv.len() < 2 {
                return None;
            }
            let a = *rng.pick(&kv);
            let b = *rng.pick(&kv);
            let value = |i: usize| {
                let l = lines[i];
                let eq = l.find('=').expect("a key = value line");
                (eq + 1, code_len(kind, l))
            };
            let (va, vb) = (value(a), value(b));
            let (ta, tb) = (
                lines[a][va.0..va.1].to_string(),
                lines[b][vb.0..vb.1].to_string(),
            );
            if a == b || ta.trim() == tb.trim() {
                return None;
            }
            out[a].replace_range(va.0..va.1, &tb);
            out[b].replace_range(vb.0..vb.1, &ta);
            Some(Mutant {
                what: format!(
                    "values of lines {} and {} swapped: `{}` / `{}`",
                    a + 1,
                    b + 1,
                    shorten(&out[a]),
                    shorten(&out[b])
                ),
                bytes: join(&out, nl),
            })
        }
        Op::Repeat => {
            // Turn a value `v` into `n*v` (or change an existing count).
            let cands: Vec<(usize, (usize, usize))> = code
                .iter()
                .flat_map(|&i| numbers(kind, lines[i]).into_iter().map(move |s| (i, s)))
                .filter(|&(i, (s, _))| s == 0 || lines[i].as_bytes()[s - 1] != b'*')
                .collect();
            if cands.is_empty() {
                return None;
            }
            let &(i, (s, e)) = rng.pick(&cands);
            let n = *rng.pick(&HOSTILE_REPEATS);
            let old = out[i][s..e].to_string();
            let has_count = out[i].as_bytes().get(e) == Some(&b'*');
            let by = if has_count {
                n.to_string()
            } else {
                format!("{n}*{old}")
            };
            out[i].replace_range(s..e, &by);
            Some(Mutant {
                what: format!("line {}: {old} -> {by} (repeat count)", i + 1),
                bytes: join(&out, nl),
            })
        }
        Op::DropSlash => {
            let slashes: Vec<usize> = code
                .iter()
                .copied()
                .filter(|&i| lines[i][..code_len(kind, lines[i])].contains('/'))
                .collect();
            if slashes.is_empty() {
                return None;
            }
            let i = *rng.pick(&slashes);
            let at = out[i].rfind('/').expect("a line with a slash");
            out[i].remove(at);
            Some(Mutant {
                what: format!("line {}: record terminator `/` dropped", i + 1),
                bytes: join(&out, nl),
            })
        }
        Op::KeywordNumbers => {
            // A keyword line and the first data line after it: every number on that line
            // becomes one hostile value.
            let kws: Vec<usize> = code
                .iter()
                .copied()
                .filter(|&i| {
                    let t = lines[i].trim();
                    t.chars().next().is_some_and(|c| c.is_ascii_uppercase())
                        && i + 1 < lines.len()
                        && !numbers(kind, lines[i + 1]).is_empty()
                })
                .collect();
            if kws.is_empty() {
                return None;
            }
            let k = *rng.pick(&kws);
            let by = *rng.pick(&HOSTILE_NUMBERS);
            let i = k + 1;
            let spans = numbers(kind, lines[i]);
            for &(s, e) in spans.iter().rev() {
                out[i].replace_range(s..e, by);
            }
            Some(Mutant {
                what: format!(
                    "line {}: every number of {}'s first data line -> {by}",
                    i + 1,
                    lines[k].trim()
                ),
                bytes: join(&out, nl),
            })
        }
        Op::Base64 => {
            let data: Vec<usize> = code
                .iter()
                .copied()
                .filter(|&i| !lines[i].trim_start().starts_with('<') && lines[i].trim().len() > 16)
                .collect();
            if data.is_empty() {
                return None;
            }
            let i = *rng.pick(&data);
            const ALPHABET: &[u8] =
                b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/=!";
            let mut bytes = out[i].clone().into_bytes();
            let first = bytes
                .iter()
                .position(|b| !b.is_ascii_whitespace())
                .unwrap_or(0);
            let changes = 1 + rng.below(8);
            for _ in 0..changes {
                let at = first + rng.below(bytes.len() - first);
                bytes[at] = *rng.pick(ALPHABET);
            }
            out[i] = String::from_utf8(bytes).expect("ASCII");
            Some(Mutant {
                what: format!(
                    "line {}: {changes} characters of binary data changed",
                    i + 1
                ),
                bytes: join(&out, nl),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_strings_are_found_outside_comments() {
        let l = r#"dt = 1.5e-3  # 2 steps"#;
        let n: Vec<&str> = numbers(Kind::Scene, l)
            .iter()
            .map(|&(s, e)| &l[s..e])
            .collect();
        assert_eq!(n, ["1.5e-3"]);
        let l = r#"at = [-0.5, 2] # "x""#;
        let n: Vec<&str> = numbers(Kind::Scene, l)
            .iter()
            .map(|&(s, e)| &l[s..e])
            .collect();
        assert_eq!(n, ["-0.5", "2"]);
        let l = r#"name = "gamma1e5" # "q""#;
        assert!(numbers(Kind::Scene, l).is_empty());
        let s: Vec<&str> = strings(Kind::Scene, l)
            .iter()
            .map(|&(s, e)| &l[s..e])
            .collect();
        assert_eq!(s, ["gamma1e5"]);
        let l = " 3*0.25 1 / -- 7";
        let n: Vec<&str> = numbers(Kind::Deck, l)
            .iter()
            .map(|&(s, e)| &l[s..e])
            .collect();
        assert_eq!(n, ["3", "0.25", "1"]);
    }

    #[test]
    fn the_same_seed_gives_the_same_mutant() {
        let text = "[a]\nx = 1\ny = \"s\"\n[b]\nz = [1, 2]\n";
        for round in 0..50 {
            let a = mutate(Kind::Scene, text, &mut Rng::for_mutant(7, "f", round));
            let b = mutate(Kind::Scene, text, &mut Rng::for_mutant(7, "f", round));
            assert_eq!(a.bytes, b.bytes);
            assert_eq!(a.what, b.what);
            assert_ne!(a.bytes, text.as_bytes(), "{}", a.what);
        }
    }
}
