//! Reading the keywords of an Eclipse grid deck (see the [module docs](super)).

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use crate::error::{GridError, Result};

/// Unit system of a deck. Lengths are converted to metres and permeabilities to m²
/// when read, whatever the deck's units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Units {
    /// Metres (the default).
    #[default]
    Metric,
    /// Feet (× 0.3048).
    Field,
    /// Centimetres (× 0.01).
    Lab,
}

impl Units {
    /// Metres per length unit of the deck.
    pub fn metres(self) -> f64 {
        match self {
            Units::Metric => 1.0,
            Units::Field => 0.3048,
            Units::Lab => 0.01,
        }
    }
}

/// One millidarcy in m² (the permeability unit of all three unit systems).
pub const MILLIDARCY: f64 = 9.869_233e-16;

/// The cell properties read from a deck, one value per cell of the deck (inactive cells
/// included), `i` fastest, then `j`, then `k`. Permeabilities are in m².
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellProperties {
    /// `PORO`.
    pub poro: Option<Vec<f64>>,
    /// `PERMX`, `PERMY`, `PERMZ` (m²).
    pub perm: [Option<Vec<f64>>; 3],
    /// `NTG`, net-to-gross.
    pub ntg: Option<Vec<f64>>,
    /// `MULTPV`, pore-volume multipliers.
    pub multpv: Option<Vec<f64>>,
}

/// The cell face a `FAULTS` segment names: `X` is the face towards `i + 1`, `X-` towards
/// `i − 1` (`I`, `I-` are the same), and so on for `Y` (`j`) and `Z` (`k`, depth).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultFace {
    /// Towards `i + 1`.
    XPlus,
    /// Towards `i − 1`.
    XMinus,
    /// Towards `j + 1`.
    YPlus,
    /// Towards `j − 1`.
    YMinus,
    /// Towards `k + 1` (down).
    ZPlus,
    /// Towards `k − 1` (up).
    ZMinus,
}

impl FaultFace {
    fn parse(word: &str) -> Option<Self> {
        Some(match word.to_ascii_uppercase().as_str() {
            "X" | "I" | "X+" | "I+" => Self::XPlus,
            "X-" | "I-" => Self::XMinus,
            "Y" | "J" | "Y+" | "J+" => Self::YPlus,
            "Y-" | "J-" => Self::YMinus,
            "Z" | "K" | "Z+" | "K+" => Self::ZPlus,
            "Z-" | "K-" => Self::ZMinus,
            _ => return None,
        })
    }
}

/// One record of `FAULTS`: the faces of the cells `i, j, k` (1-based ranges, inclusive)
/// on the side `face` belong to the fault `name`.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultSegment {
    /// The fault's name (upper case).
    pub name: String,
    /// `[i1, i2]`, `[j1, j2]`, `[k1, k2]`, 1-based, inclusive.
    pub ijk: [[usize; 2]; 3],
    /// The side of those cells.
    pub face: FaultFace,
}

/// The grid keywords of a deck, in SI units.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Deck {
    /// `[nx, ny, nz]` from `SPECGRID` or `DIMENS`.
    pub dims: [usize; 3],
    /// `COORD`: per pillar (`i` fastest over `nx + 1`, then `j` over `ny + 1`) the top and
    /// bottom points `x y z x y z` (m).
    pub coord: Vec<f64>,
    /// `ZCORN`: the eight corner depths of every cell in Eclipse's order (m).
    pub zcorn: Vec<f64>,
    /// `ACTNUM` (all active without it).
    pub actnum: Option<Vec<bool>>,
    /// `MAPAXES` (three points `x1 y1 x0 y0 x2 y2` of the map axes, in the deck's map
    /// units): reported, not applied; the grid stays in the deck's coordinates.
    pub mapaxes: Option<[f64; 6]>,
    /// The unit system (`METRIC`, `FIELD`, `LAB`).
    pub units: Units,
    /// Cell properties.
    pub properties: CellProperties,
    /// `FAULTS`: the segments of every named fault.
    pub faults: Vec<FaultSegment>,
    /// `MULTFLT`: transmissibility multipliers by fault name (upper case), in order.
    pub fault_multipliers: Vec<(String, f64)>,
    /// Keywords read but not used (their data skipped), in order of appearance.
    pub skipped: Vec<String>,
    /// Where each array keyword (`COORD`, `ZCORN`, `ACTNUM`, `PORO`, …) was read: the
    /// keyword, its file and its 1-based line, in order (for messages about its values).
    pub keyword_lines: Vec<(String, PathBuf, usize)>,
}

impl Deck {
    /// Number of cells of the deck, `nx · ny · nz`.
    pub fn num_cells(&self) -> usize {
        self.dims.iter().product()
    }

    /// A deck on vertical pillars at `x = i dx`, `y = j dy`: the top of cell `(i, j, k)` at
    /// its corner `(x, y)` lies at depth `depth([i, j], x, y, k)`, its bottom at
    /// `depth([i, j], x, y, k + 1)` (the column is passed so that a fault can move
    /// columns apart). All cells active, metres.
    pub fn on_vertical_pillars(
        dims: [usize; 3],
        spacing: [f64; 2],
        depth: impl Fn([usize; 2], f64, f64, usize) -> f64,
    ) -> Self {
        let [nx, ny, nz] = dims;
        let mut coord = Vec::with_capacity(6 * (nx + 1) * (ny + 1));
        for j in 0..=ny {
            for i in 0..=nx {
                let (x, y) = (i as f64 * spacing[0], j as f64 * spacing[1]);
                coord.extend([x, y, 0.0, x, y, 1.0]);
            }
        }
        let mut zcorn = Vec::with_capacity(8 * nx * ny * nz);
        for k in 0..nz {
            for dk in 0..2 {
                for j in 0..ny {
                    for dj in 0..2 {
                        for i in 0..nx {
                            for di in 0..2 {
                                let x = (i + di) as f64 * spacing[0];
                                let y = (j + dj) as f64 * spacing[1];
                                zcorn.push(depth([i, j], x, y, k + dk));
                            }
                        }
                    }
                }
            }
        }
        Self {
            dims,
            coord,
            zcorn,
            ..Self::default()
        }
    }

    /// Write the deck as GRDECL text (`SPECGRID`, `COORD`, `ZCORN`, `ACTNUM` and the
    /// properties it has; metres, permeabilities in millidarcy), every number written so
    /// that it reads back to the same bits.
    pub fn write_text(&self, out: &mut impl std::io::Write) -> std::io::Result<()> {
        let [nx, ny, nz] = self.dims;
        writeln!(out, "SPECGRID\n {nx} {ny} {nz} 1 F /")?;
        let array = |out: &mut dyn std::io::Write, name: &str, v: &[f64], per_line: usize| {
            writeln!(out, "{name}")?;
            for row in v.chunks(per_line) {
                let line: Vec<String> = row.iter().map(|x| format!("{x:?}")).collect();
                writeln!(out, " {}", line.join(" "))?;
            }
            writeln!(out, "/")
        };
        array(out, "COORD", &self.coord, 6)?;
        array(out, "ZCORN", &self.zcorn, 8)?;
        if let Some(a) = &self.actnum {
            let v: Vec<f64> = a.iter().map(|&b| if b { 1.0 } else { 0.0 }).collect();
            array(out, "ACTNUM", &v, 20)?;
        }
        let p = &self.properties;
        if let Some(v) = &p.poro {
            array(out, "PORO", v, 8)?;
        }
        for (name, perm) in ["PERMX", "PERMY", "PERMZ"].iter().zip(&p.perm) {
            if let Some(v) = perm {
                let md: Vec<f64> = v.iter().map(|k| k / MILLIDARCY).collect();
                array(out, name, &md, 8)?;
            }
        }
        if let Some(v) = &p.ntg {
            array(out, "NTG", v, 8)?;
        }
        if let Some(v) = &p.multpv {
            array(out, "MULTPV", v, 8)?;
        }
        Ok(())
    }
}

/// Largest number of cells a deck may declare (2³¹: Eclipse's own limit on indices).
pub const MAX_DECK_CELLS: usize = 1 << 31;
/// Deepest chain of `INCLUDE`s.
const MAX_INCLUDE_DEPTH: usize = 16;
/// Longest line of a deck (1 MiB, newline included); a token lies on one line, so this
/// bounds tokens too.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Read a GRDECL deck (following `INCLUDE`s relative to the including file).
pub fn read_deck(path: impl AsRef<Path>) -> Result<Deck> {
    read_deck_with(path, &DeckLimit::default())
}

/// The largest deck a reader accepts, and why (the caller's memory, say): a larger
/// `SPECGRID` is an error before anything is allocated for it.
#[derive(Clone, Debug)]
pub struct DeckLimit {
    /// Largest number of cells (at most [`MAX_DECK_CELLS`]).
    pub cells: usize,
    /// Why, for the error message.
    pub why: String,
}

impl Default for DeckLimit {
    fn default() -> Self {
        Self {
            cells: MAX_DECK_CELLS,
            why: "the most a deck may have".into(),
        }
    }
}

/// [`read_deck`] with a bound on the deck's size.
pub fn read_deck_with(path: impl AsRef<Path>, limit: &DeckLimit) -> Result<Deck> {
    let mut reader = DeckReader {
        limit: limit.clone(),
        ..DeckReader::default()
    };
    let path = path.as_ref();
    if let Some(what) = not_regular(path) {
        return Err(GridError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidInput, what),
        });
    }
    reader.top = path.to_path_buf();
    reader.read_file(path, 0)?;
    reader.finish()
}

/// Keywords that take no data record (section headers, switches).
const NO_DATA: &[&str] = &[
    "RUNSPEC", "GRID", "EDIT", "PROPS", "REGIONS", "SOLUTION", "SUMMARY", "SCHEDULE", "ECHO",
    "NOECHO", "METRIC", "FIELD", "LAB", "PVT-M", "NONNC", "OIL", "WATER", "GAS", "DISGAS",
    "VAPOIL", "END", "ENDBOX", "NEWTRAN", "OLDTRAN",
];

#[derive(Default)]
struct DeckReader {
    deck: Deck,
    /// Where `SPECGRID`/`DIMENS` was given (file, line), to name in count errors.
    dims_at: Option<(PathBuf, usize)>,
    /// Where each array keyword was read, for count errors found at the end.
    arrays_at: Vec<(String, PathBuf, usize, usize)>,
    /// Raw length arrays in deck units, scaled once the units are known.
    gridunit_scale: Option<f64>,
    /// Files being read (to refuse an `INCLUDE` cycle).
    open: Vec<PathBuf>,
    /// The largest deck accepted.
    limit: DeckLimit,
    /// The file the deck starts with, and its number of lines.
    top: PathBuf,
    last_line: usize,
    /// A section after the grid's was met (`PROPS`, …): reading stops.
    done: bool,
    /// Where each `MULTFLT` record was read (file, line), in the order of
    /// [`Deck::fault_multipliers`].
    multflt_at: Vec<(PathBuf, usize)>,
}

/// A token of the deck: a word or number, a quoted string, or the record end `/`.
#[derive(Clone, Debug, PartialEq)]
enum Token {
    Word(String),
    Quoted(String),
    Slash,
}

/// Splits a deck into tokens, streaming from a reader, keeping the line number.
struct Lexer<R: BufRead> {
    input: R,
    line: usize,
    buf: Vec<u8>,
    pos: usize,
    path: PathBuf,
    /// A token read ahead and given back.
    pushback: Option<Token>,
}

impl<R: BufRead> Lexer<R> {
    fn new(input: R, path: &Path) -> Self {
        Self {
            input,
            line: 0,
            buf: Vec::new(),
            pos: 0,
            path: path.to_path_buf(),
            pushback: None,
        }
    }

    fn error(&self, what: impl Into<String>) -> GridError {
        GridError::Parse {
            path: self.path.clone(),
            line: self.line,
            what: what.into(),
        }
    }

    /// The next token, or `None` at the end of the input.
    fn next(&mut self) -> Result<Option<Token>> {
        if let Some(t) = self.pushback.take() {
            return Ok(Some(t));
        }
        loop {
            while self.pos < self.buf.len() && self.buf[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
            let rest = &self.buf[self.pos..];
            if rest.is_empty() || rest.starts_with(b"--") {
                self.buf.clear();
                self.pos = 0;
                // At most one byte more than a line may have, so that a file without
                // newlines (or a device) is refused after 1 MiB, not read whole.
                let n = (&mut self.input)
                    .take(MAX_LINE_BYTES as u64 + 1)
                    .read_until(b'\n', &mut self.buf)
                    .map_err(|e| GridError::Parse {
                        path: self.path.clone(),
                        line: self.line + 1,
                        what: format!("cannot read: {e}"),
                    })?;
                if n == 0 {
                    return Ok(None);
                }
                self.line += 1;
                if self.buf.len() > MAX_LINE_BYTES && self.buf.last() != Some(&b'\n') {
                    self.buf.clear();
                    return Err(self.error(format!(
                        "the line is longer than {MAX_LINE_BYTES} bytes (1 MiB, the most a deck \
                         line may have; is this a deck?)"
                    )));
                }
                continue;
            }
            if rest[0] == b'/' {
                self.pos += 1;
                return Ok(Some(Token::Slash));
            }
            if rest[0] == b'\'' || rest[0] == b'"' {
                let quote = rest[0];
                let Some(end) = rest[1..].iter().position(|&b| b == quote) else {
                    return Err(self.error("a quoted string is not closed on its line"));
                };
                let text = String::from_utf8_lossy(&rest[1..1 + end]).into_owned();
                self.pos += end + 2;
                return Ok(Some(Token::Quoted(text)));
            }
            let len = rest
                .iter()
                .position(|&b| b.is_ascii_whitespace() || b == b'/' || b == b'\'')
                .unwrap_or(rest.len());
            let word = String::from_utf8_lossy(&rest[..len]).into_owned();
            self.pos += len;
            return Ok(Some(Token::Word(word)));
        }
    }
}

/// Parse one number of a data record, `n*value` repeats expanded into `out`.
fn push_values(word: &str, out: &mut Vec<f64>, limit: usize) -> std::result::Result<(), String> {
    let (count, value) = match word.split_once('*') {
        Some((n, v)) => {
            let n: usize = n
                .parse()
                .map_err(|_| format!("`{}` is not a repeat count `n*value`", shown(word)))?;
            if v.is_empty() {
                return Err(format!(
                    "`{}`: a default (`n*` without a value) has no meaning in a grid array",
                    shown(word)
                ));
            }
            (n, v)
        }
        None => (1, word),
    };
    let v: f64 = value
        .parse()
        .map_err(|_| format!("`{}` is not a number", shown(word)))?;
    if !v.is_finite() {
        return Err(format!("`{}` is not a finite number", shown(word)));
    }
    // Checked before anything is pushed: a repeat count may be any number the deck
    // writes (`18446744073709551615*1`), the values read so far never pass `limit`.
    if count > limit.saturating_sub(out.len()) {
        return Err(format!(
            "`{}` makes more than the {limit} values this keyword can have ({} read before it)",
            shown(word),
            out.len()
        ));
    }
    out.extend(std::iter::repeat_n(v, count));
    Ok(())
}

impl DeckReader {
    /// Read one file of the deck; `depth` is the number of `INCLUDE`s that led here (the
    /// caller has checked the depth, cycles and that the file is a regular file).
    fn read_file(&mut self, path: &Path, depth: usize) -> Result<()> {
        let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        let file = File::open(path).map_err(|source| GridError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        self.open.push(canonical);
        let mut lexer = Lexer::new(BufReader::with_capacity(1 << 16, file), path);
        let result = self.read_tokens(&mut lexer, path, depth);
        self.open.pop();
        if depth == 0 {
            self.last_line = lexer.line;
        }
        result
    }

    fn read_tokens<R: Read>(
        &mut self,
        lx: &mut Lexer<BufReader<R>>,
        path: &Path,
        depth: usize,
    ) -> Result<()> {
        while let Some(tok) = lx.next()? {
            if self.done {
                break;
            }
            let word = match tok {
                Token::Word(w) => w.to_ascii_uppercase(),
                Token::Slash => continue,
                Token::Quoted(q) => {
                    return Err(lx.error(format!(
                        "'{}': a quoted string where a keyword is expected",
                        shown(&q)
                    )));
                }
            };
            let line = lx.line;
            match word.as_str() {
                "SPECGRID" | "DIMENS" => {
                    // `nx ny nz` (then, for SPECGRID, the number of reservoirs and the
                    // coordinate type: F for Cartesian, T for radial, refused).
                    let mut words = Vec::new();
                    while let Some(t) = lx.next()? {
                        match t {
                            Token::Slash => break,
                            Token::Word(w) | Token::Quoted(w) if words.len() < 8 => words.push(w),
                            _ => return Err(lx.error(format!("{word}: too many values"))),
                        }
                    }
                    if words.get(4).is_some_and(|w| w.eq_ignore_ascii_case("T")) {
                        return Err(lx.error(format!(
                            "{word}: radial coordinates (T) are not supported; Cartesian (F) only"
                        )));
                    }
                    let mut vals = Vec::new();
                    for w in words.iter().take(3) {
                        push_values(w, &mut vals, 3)
                            .map_err(|e| lx.error(format!("{word}: {e}")))?;
                    }
                    let count = vals.len();
                    if count < 3 {
                        return Err(
                            lx.error(format!("{word}: needs nx ny nz, found {count} values"))
                        );
                    }
                    let mut dims = [0usize; 3];
                    for (d, v) in dims.iter_mut().zip(&vals) {
                        if *v < 1.0 || v.fract() != 0.0 || *v > MAX_DECK_CELLS as f64 {
                            return Err(lx.error(format!(
                                "{word}: `{v}` is not a positive whole number of cells"
                            )));
                        }
                        *d = *v as usize;
                    }
                    let n = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
                    let most = self.limit.cells.min(MAX_DECK_CELLS);
                    if n.is_none_or(|n| n > most) {
                        return Err(lx.error(format!(
                            "{word}: {} × {} × {} cells is more than the {most} allowed ({})",
                            dims[0], dims[1], dims[2], self.limit.why
                        )));
                    }
                    self.deck.dims = dims;
                    self.dims_at = Some((path.to_path_buf(), line));
                }
                "COORD" | "ZCORN" | "ACTNUM" | "PORO" | "PERMX" | "PERMY" | "PERMZ" | "NTG"
                | "MULTPV" => {
                    let Some(limit) = self.expected(&word) else {
                        return Err(lx.error(format!(
                            "{word} before SPECGRID or DIMENS: the grid size must come first"
                        )));
                    };
                    let mut vals = Vec::with_capacity(limit.min(1 << 24));
                    let (count, _) = self.record(lx, &word, &mut vals, limit)?;
                    self.arrays_at
                        .push((word.clone(), path.to_path_buf(), line, count));
                    self.store(&word, vals);
                }
                "MAPAXES" => {
                    let mut vals = Vec::new();
                    let (count, _) = self.record(lx, &word, &mut vals, 6)?;
                    if count != 6 {
                        return Err(lx.error(format!("MAPAXES: needs 6 values, found {count}")));
                    }
                    self.deck.mapaxes = Some(std::array::from_fn(|k| vals[k]));
                }
                "GRIDUNIT" => {
                    let unit = match lx.next()? {
                        Some(Token::Word(w) | Token::Quoted(w)) => w.trim().to_ascii_uppercase(),
                        _ => return Err(lx.error("GRIDUNIT: needs a unit (METRES, FEET or CM)")),
                    };
                    self.gridunit_scale = Some(match unit.as_str() {
                        "METRES" | "METERS" | "M" => 1.0,
                        "FEET" | "FT" => 0.3048,
                        "CM" => 0.01,
                        other => {
                            return Err(lx.error(format!(
                                "GRIDUNIT: unit `{}` is not METRES, FEET or CM",
                                shown(other)
                            )));
                        }
                    });
                    self.skip_record(lx)?;
                }
                "FAULTS" | "MULTFLT" => self.fault_records(lx, &word)?,
                "METRIC" => self.deck.units = Units::Metric,
                "FIELD" => self.deck.units = Units::Field,
                "LAB" => self.deck.units = Units::Lab,
                "INCLUDE" => {
                    let name = match lx.next()? {
                        Some(Token::Word(w) | Token::Quoted(w)) => w,
                        _ => return Err(lx.error("INCLUDE: needs a file name")),
                    };
                    let target = resolve_include(path, &name)
                        .map_err(|why| lx.error(format!("INCLUDE '{}': {why}", shown(&name))))?;
                    let canonical = target.canonicalize().unwrap_or_else(|_| target.clone());
                    if let Some(at) = self.open.iter().position(|p| *p == canonical) {
                        let chain: Vec<String> = self.open[at..]
                            .iter()
                            .chain([&canonical])
                            .map(|p| {
                                p.file_name()
                                    .unwrap_or_default()
                                    .to_string_lossy()
                                    .into_owned()
                            })
                            .collect();
                        return Err(lx.error(format!(
                            "INCLUDE '{}': a cycle of includes ({})",
                            shown(&name),
                            chain.join(" → ")
                        )));
                    }
                    if depth + 1 > MAX_INCLUDE_DEPTH {
                        return Err(lx.error(format!(
                            "INCLUDE '{}': includes nested deeper than {MAX_INCLUDE_DEPTH} files",
                            shown(&name)
                        )));
                    }
                    self.skip_record(lx)?;
                    self.read_file(&target, depth + 1)?;
                }
                // The sections after GRID and EDIT hold no grid data (and records this
                // reader does not parse): the deck's grid is read.
                "PROPS" | "REGIONS" | "SOLUTION" | "SUMMARY" | "SCHEDULE" => {
                    self.done = true;
                    break;
                }
                w if NO_DATA.contains(&w) => {}
                w if is_keyword(w) => {
                    // An unknown keyword: skip its record, unless the next keyword comes
                    // first (a keyword without data).
                    self.deck.skipped.push(w.to_string());
                    self.skip_unknown(lx)?;
                }
                other => {
                    return Err(lx.error(format!(
                        "`{}` where a keyword is expected (is a record missing its `/`?)",
                        shown(other)
                    )));
                }
            }
        }
        Ok(())
    }

    /// `FAULTS` (`'name' i1 i2 j1 j2 k1 k2 'face' /` …) or `MULTFLT` (`'name' m /` …), up to
    /// the empty record `/`.
    fn fault_records<R: BufRead>(&mut self, lx: &mut Lexer<R>, word: &str) -> Result<()> {
        loop {
            let mut items: Vec<String> = Vec::new();
            loop {
                match lx.next()? {
                    Some(Token::Slash) => break,
                    Some(Token::Word(w) | Token::Quoted(w)) if items.len() < 16 => items.push(w),
                    Some(_) => return Err(lx.error(format!("{word}: a record has too many items"))),
                    None => {
                        return Err(lx.error(format!(
                            "{word}: the file ends before the `/` ending the keyword"
                        )));
                    }
                }
            }
            if items.is_empty() {
                return Ok(());
            }
            let name = items[0].to_ascii_uppercase();
            if word == "MULTFLT" {
                let m = items
                    .get(1)
                    .and_then(|v| v.parse::<f64>().ok())
                    .filter(|m| m.is_finite() && *m >= 0.0);
                let Some(m) = m else {
                    return Err(lx.error(format!(
                        "MULTFLT: fault '{}' needs a multiplier ≥ 0 (record: {})",
                        shown(&name),
                        shown(&items.join(" "))
                    )));
                };
                self.deck.fault_multipliers.push((name, m));
                self.multflt_at.push((lx.path.clone(), lx.line));
                continue;
            }
            let bad = || {
                lx.error(format!(
                    "FAULTS: record `{}` is not 'name' i1 i2 j1 j2 k1 k2 'face' with 1 ≤ i1 ≤ i2 ≤ nx \
                     (and so for j, k) and face X, X-, Y, Y-, Z or Z-",
                    shown(&items.join(" "))
                ))
            };
            if items.len() < 8 {
                return Err(bad());
            }
            let mut ijk = [[0usize; 2]; 3];
            for a in 0..3 {
                for b in 0..2 {
                    let v: usize = items[1 + 2 * a + b].parse().map_err(|_| bad())?;
                    ijk[a][b] = v;
                }
                if ijk[a][0] < 1 || ijk[a][0] > ijk[a][1] || ijk[a][1] > self.deck.dims[a] {
                    return Err(bad());
                }
            }
            let face = FaultFace::parse(&items[7]).ok_or_else(bad)?;
            self.deck.faults.push(FaultSegment { name, ijk, face });
        }
    }

    /// The number of values an array keyword must have, once the size is known.
    fn expected(&self, word: &str) -> Option<usize> {
        let [nx, ny, nz] = self.deck.dims;
        if nx == 0 {
            return None;
        }
        Some(match word {
            "COORD" => 6 * (nx + 1) * (ny + 1),
            "ZCORN" => 8 * nx * ny * nz,
            _ => nx * ny * nz,
        })
    }

    fn store(&mut self, word: &str, vals: Vec<f64>) {
        let p = &mut self.deck.properties;
        match word {
            "COORD" => self.deck.coord = vals,
            "ZCORN" => self.deck.zcorn = vals,
            "ACTNUM" => self.deck.actnum = Some(vals.iter().map(|&v| v != 0.0).collect()),
            "PORO" => p.poro = Some(vals),
            "PERMX" => p.perm[0] = Some(vals),
            "PERMY" => p.perm[1] = Some(vals),
            "PERMZ" => p.perm[2] = Some(vals),
            "NTG" => p.ntg = Some(vals),
            _ => p.multpv = Some(vals),
        }
    }

    /// Read a data record up to its `/` into `out` (at most `limit` values); returns the
    /// number of values and the line of the `/`.
    fn record<R: BufRead>(
        &self,
        lx: &mut Lexer<R>,
        word: &str,
        out: &mut Vec<f64>,
        limit: usize,
    ) -> Result<(usize, usize)> {
        loop {
            match lx.next()? {
                Some(Token::Slash) => return Ok((out.len(), lx.line)),
                Some(Token::Word(w)) => {
                    if let Err(e) = push_values(&w, out, limit) {
                        let hint =
                            if is_keyword(&w.to_ascii_uppercase()) && w.parse::<f64>().is_err() {
                                " (is the `/` ending the record missing?)"
                            } else {
                                ""
                            };
                        return Err(lx.error(format!("{word}: {e}{hint}")));
                    }
                }
                Some(Token::Quoted(q)) => {
                    return Err(lx.error(format!("{word}: '{}' is not a number", shown(&q))));
                }
                None => {
                    return Err(lx.error(format!(
                        "{word}: the file ends before the `/` ending its data ({} values read)",
                        out.len()
                    )));
                }
            }
        }
    }

    fn skip_record<R: BufRead>(&self, lx: &mut Lexer<R>) -> Result<()> {
        while let Some(t) = lx.next()? {
            if t == Token::Slash {
                return Ok(());
            }
        }
        Ok(())
    }

    /// Skip an unknown keyword's data: tokens up to `/`. A keyword this reader knows met
    /// first means the unknown keyword had no data; reading goes on from that keyword.
    fn skip_unknown<R: BufRead>(&self, lx: &mut Lexer<R>) -> Result<()> {
        loop {
            match lx.next()? {
                None | Some(Token::Slash) => return Ok(()),
                Some(Token::Word(w)) => {
                    let up = w.to_ascii_uppercase();
                    if NO_DATA.contains(&up.as_str()) || known(&up) {
                        lx.pushback = Some(Token::Word(w));
                        return Ok(());
                    }
                }
                Some(Token::Quoted(_)) => {}
            }
        }
    }

    fn finish(self) -> Result<Deck> {
        let mut deck = self.deck;
        deck.keyword_lines = self
            .arrays_at
            .iter()
            .map(|(word, file, line, _)| (word.clone(), file.clone(), *line))
            .collect();
        let Some((dims_file, dims_line)) = self.dims_at else {
            return Err(GridError::Parse {
                path: self.top,
                line: self.last_line.max(1),
                what: "no SPECGRID or DIMENS in the deck (read to its end): the grid size is \
                       missing"
                    .into(),
            });
        };
        let [nx, ny, nz] = deck.dims;
        for (word, file, line, count) in &self.arrays_at {
            let need = match word.as_str() {
                "COORD" => 6 * (nx + 1) * (ny + 1),
                "ZCORN" => 8 * nx * ny * nz,
                _ => nx * ny * nz,
            };
            if *count != need {
                let how = match word.as_str() {
                    "COORD" => format!("6 × (nx + 1) × (ny + 1) = 6 × {} × {}", nx + 1, ny + 1),
                    "ZCORN" => format!("8 × nx × ny × nz = 8 × {nx} × {ny} × {nz}"),
                    _ => format!("nx × ny × nz = {nx} × {ny} × {nz}"),
                };
                return Err(GridError::Parse {
                    path: file.clone(),
                    line: *line,
                    what: format!(
                        "{word} has {count} values, needs {need} ({how}, the size given at {}:{dims_line})",
                        dims_file.display()
                    ),
                });
            }
        }
        for (word, present) in [
            ("COORD", !deck.coord.is_empty()),
            ("ZCORN", !deck.zcorn.is_empty()),
        ] {
            if !present {
                return Err(GridError::Parse {
                    path: dims_file.clone(),
                    line: dims_line,
                    what: format!(
                        "no {word} in the deck of this grid size: a corner-point grid needs \
                         COORD and ZCORN{}",
                        if deck.skipped.iter().any(|w| w == "DX" || w == "TOPS") {
                            " (block-centred grids, DX DY DZ TOPS, are not read)"
                        } else {
                            ""
                        }
                    ),
                });
            }
        }
        if let Some(((name, _), (file, line))) = deck
            .fault_multipliers
            .iter()
            .zip(&self.multflt_at)
            .find(|((n, _), _)| !deck.faults.iter().any(|s| &s.name == n))
        {
            return Err(GridError::Parse {
                path: file.clone(),
                line: *line,
                what: format!("MULTFLT: no fault named '{}' in FAULTS", shown(name)),
            });
        }
        // GRIDUNIT, when given, is the unit of COORD and ZCORN; without it the unit
        // system (METRIC, FIELD, LAB) is. The two are never multiplied together.
        let scale = self.gridunit_scale.unwrap_or(deck.units.metres());
        if scale != 1.0 {
            deck.coord.iter_mut().for_each(|v| *v *= scale);
            deck.zcorn.iter_mut().for_each(|v| *v *= scale);
        }
        for perm in deck.properties.perm.iter_mut().flatten() {
            perm.iter_mut().for_each(|v| *v *= MILLIDARCY);
        }
        Ok(deck)
    }
}

/// Keywords this reader knows (their records are parsed, not skipped).
fn known(w: &str) -> bool {
    matches!(
        w,
        "SPECGRID"
            | "DIMENS"
            | "COORD"
            | "ZCORN"
            | "ACTNUM"
            | "PORO"
            | "PERMX"
            | "PERMY"
            | "PERMZ"
            | "NTG"
            | "MULTPV"
            | "MAPAXES"
            | "GRIDUNIT"
            | "INCLUDE"
            | "FAULTS"
            | "MULTFLT"
    )
}

/// Whether a word has the shape of a keyword: up to 8 characters, a letter first, then
/// letters, digits, `_` or `-`.
fn is_keyword(w: &str) -> bool {
    let b = w.as_bytes();
    !b.is_empty()
        && b.len() <= 8
        && b[0].is_ascii_uppercase()
        && b.iter()
            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || *c == b'_' || *c == b'-')
}

/// The file an `INCLUDE` names, relative to the including file's folder: as written,
/// then upper-case, then lower-case (decks written on Windows name files in any case).
/// The first that exists must be a regular file; the error says why not.
fn resolve_include(from: &Path, name: &str) -> std::result::Result<PathBuf, String> {
    let dir = from.parent().unwrap_or(Path::new("."));
    let given = Path::new(name);
    let base = if given.is_absolute() {
        given.to_path_buf()
    } else {
        dir.join(given)
    };
    let mut candidates = vec![base.clone()];
    if let (Some(file), Some(parent)) = (base.file_name(), base.parent()) {
        let file = file.to_string_lossy();
        candidates.push(parent.join(file.to_ascii_uppercase()));
        candidates.push(parent.join(file.to_ascii_lowercase()));
    }
    match candidates.into_iter().find(|p| p.exists()) {
        None => Err(format!(
            "no such file next to {} (tried the name as given, upper- and lower-case)",
            from.display()
        )),
        Some(p) => match not_regular(&p) {
            None => Ok(p),
            Some(what) => Err(format!("{}: {what}", p.display())),
        },
    }
}

/// Why a path that exists cannot be a deck file (`None` if it is a regular file):
/// directories, devices (`/dev/zero`), FIFOs and sockets are refused before they are
/// opened (opening a FIFO would wait for a writer).
fn not_regular(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => None,
        Ok(m) if m.is_dir() => Some("is a directory, not a deck file".into()),
        Ok(_) => Some("is not a regular file (a device, FIFO or socket), not a deck file".into()),
        Err(e) => Some(format!("cannot be read: {e}")),
    }
}

/// Longest piece of user text a message repeats (in characters).
const SHOWN_CHARS: usize = 60;

/// User text as a message shows it: whole up to [`SHOWN_CHARS`] characters, else its
/// start and its length (`COORDXXXX… (5242880 characters)`), so that a huge token does
/// not flood the terminal.
pub(crate) fn shown(text: &str) -> String {
    let mut chars = text.char_indices();
    match chars.nth(SHOWN_CHARS) {
        None => text.to_string(),
        Some((end, _)) => format!("{}… ({} characters)", &text[..end], text.chars().count()),
    }
}
