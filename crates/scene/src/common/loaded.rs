//! Reading and checking a scene file: every problem is a [`SceneError`] with the file,
//! line and key.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::common::expr::Expr;
use crate::common::laws::LawRegistry;
use crate::common::sections::{
    Bc, CellCount, Component, GridKind, KeyPart, LinearChoice, NumOrExpr, Permeability, SceneFile,
    Select, key_text, line_of_offset, locate,
};
use porofrac_grid::Point;
use porofrac_grid::generate::RoundWellSpec;

/// A problem in a scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// The scene file.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// What is wrong, starting with the key (`material.rock.poisson_ratio = 0.5 must be < 0.5`).
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = self.file.file_name().map_or_else(
            || self.file.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        write!(f, "{name}:{}: {}", self.line, self.message)
    }
}

impl std::error::Error for SceneError {}

/// A parsed scene with its source text (for locating keys in later errors).
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The typed scene.
    pub scene: SceneFile,
    /// The file it came from.
    pub path: PathBuf,
    /// Its text.
    pub text: String,
}

impl LoadedScene {
    /// An error at a key path.
    pub fn error(&self, path: &[KeyPart], message: impl fmt::Display) -> SceneError {
        SceneError {
            file: self.path.clone(),
            line: locate(&self.text, path),
            message: format!("{} {}", key_text(path), message),
        }
    }
    /// The model of the scene (`[scene] model`, default `"continuum"`).
    pub fn model(&self) -> &str {
        self.scene.scene.model.as_deref().unwrap_or("continuum")
    }
    /// Resolve a path written in the scene (relative to the scene file's directory).
    pub fn resolve(&self, p: &str) -> PathBuf {
        let p = Path::new(p);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.path.parent().unwrap_or(Path::new(".")).join(p)
        }
    }
}

/// Key path helper: `k(&["material", "rock", "poisson_ratio"])`.
pub fn k(parts: &[&str]) -> Vec<KeyPart> {
    parts.iter().map(|p| KeyPart::Key(p.to_string())).collect()
}

/// Key path with an index: `ki("bc", 2, &["traction"])`.
pub fn ki(table: &str, index: usize, rest: &[&str]) -> Vec<KeyPart> {
    let mut v = k(&table.split('.').collect::<Vec<_>>());
    v.push(KeyPart::Index(index));
    v.extend(rest.iter().map(|p| KeyPart::Key(p.to_string())));
    v
}

/// Largest scene file read (bytes): a scene is a page of text, not data.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

/// Read and parse a scene file (syntax, types, unknown keys).
pub fn load(path: &Path) -> Result<LoadedScene, SceneError> {
    let cannot = |e: String| SceneError {
        file: path.to_path_buf(),
        line: 0,
        message: format!("cannot read the scene file: {e}"),
    };
    let size = std::fs::metadata(path)
        .map_err(|e| cannot(e.to_string()))?
        .len();
    if size > MAX_SCENE_BYTES {
        return Err(cannot(format!(
            "it has {size} bytes, more than the {MAX_SCENE_BYTES} a scene file may have"
        )));
    }
    let text = std::fs::read_to_string(path).map_err(|e| cannot(e.to_string()))?;
    parse(&text, path)
}

/// Deepest nesting of TOML arrays and tables in a scene file. The TOML parser recurses
/// per level, so deeper text is refused before it is parsed.
pub const MAX_TOML_NESTING: usize = 32;

/// Parse scene text (syntax, types, unknown keys); `path` names it in errors.
pub fn parse(text: &str, path: &Path) -> Result<LoadedScene, SceneError> {
    if let Some((offset, depth)) = too_deep(text) {
        return Err(SceneError {
            file: path.to_path_buf(),
            line: line_of_offset(text, offset),
            message: format!(
                "arrays and tables nest {depth} levels deep here, more than the \
                 {MAX_TOML_NESTING} a scene may use"
            ),
        });
    }
    let text = text.to_string();
    let scene: SceneFile = toml::from_str(&text).map_err(|e| SceneError {
        file: path.to_path_buf(),
        line: e.span().map_or(1, |s| line_of_offset(&text, s.start)),
        message: e.message().trim().replace('\n', " "),
    })?;
    Ok(LoadedScene {
        scene,
        path: path.to_path_buf(),
        text,
    })
}

/// The offset and depth where `[`/`{` nesting (outside strings and comments) first
/// exceeds [`MAX_TOML_NESTING`].
fn too_deep(text: &str) -> Option<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    let mut at_line_start = true;
    while i < bytes.len() {
        let b = bytes[i];
        match b {
            b'#' => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'"' | b'\'' => {
                // Skip a string (basic strings honour backslash escapes; triple quotes
                // are three empty-or-not strings in a row, which skips the same way).
                let quote = b;
                i += 1;
                while i < bytes.len() && bytes[i] != quote {
                    if quote == b'"' && bytes[i] == b'\\' {
                        i += 1;
                    }
                    i += 1;
                }
            }
            b'[' | b'{' if depth > 0 || !(at_line_start && b == b'[') => {
                depth += 1;
                if depth > MAX_TOML_NESTING {
                    return Some((i, depth));
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            b'\n' => {
                at_line_start = true;
                i += 1;
                continue;
            }
            _ => {}
        }
        if !b.is_ascii_whitespace() {
            at_line_start = false;
        }
        i += 1;
    }
    None
}

fn positive(ls: &LoadedScene, path: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if !(v.is_finite() && v > 0.0) {
        return Err(ls.error(path, format!("= {v} must be > 0")));
    }
    Ok(())
}

fn len_is(ls: &LoadedScene, path: &[KeyPart], got: usize, want: usize) -> Result<(), SceneError> {
    if got != want {
        return Err(ls.error(path, format!("has {got} components, the scene is {want}D")));
    }
    Ok(())
}

/// The part of `[[output.line]]` number `i` every model checks alike: `points` in
/// `2..=MAX_LINE_POINTS` and a name that is a file name.
pub(crate) fn line_points_and_name(
    ls: &LoadedScene,
    i: usize,
    l: &crate::common::sections::Line,
) -> Result<(), SceneError> {
    if !(2..=crate::common::limits::MAX_LINE_POINTS as i64).contains(&l.points) {
        return Err(ls.error(
            &ki("output.line", i, &["points"]),
            format!(
                "= {} must be in 2..={}",
                l.points,
                crate::common::limits::MAX_LINE_POINTS
            ),
        ));
    }
    if l.name.is_empty() || l.name.contains(['/', '\\']) {
        return Err(ls.error(
            &ki("output.line", i, &["name"]),
            "must be a non-empty file name",
        ));
    }
    Ok(())
}

/// A number (finite) or an expression that parses (or `"free"` where allowed).
pub(crate) fn expr_ok(
    ls: &LoadedScene,
    path: &[KeyPart],
    v: &NumOrExpr,
    allow_free: bool,
) -> Result<(), SceneError> {
    match v {
        NumOrExpr::Num(x) if !x.is_finite() => {
            Err(ls.error(path, format!("= {x} is not a finite number")))
        }
        NumOrExpr::Num(_) => Ok(()),
        NumOrExpr::Expr(s) if allow_free && s == "free" => Ok(()),
        NumOrExpr::Expr(s) => Expr::parse(s)
            .map(|_| ())
            .map_err(|e| ls.error(path, format!("= \"{s}\": bad expression at {e}"))),
    }
}

/// Number of steps of a schedule (before the [`crate::common::limits::MAX_STEPS`] bound; as
/// a float so absurd requests do not overflow).
pub fn step_count_f64(sch: &crate::common::sections::Schedule) -> f64 {
    match (sch.dt, sch.steps) {
        (Some(dt), _) => (sch.end_time / dt - 1e-9).ceil().max(1.0),
        (None, Some(n)) => n.max(1) as f64,
        _ => 1.0,
    }
}

/// Number of steps of a checked schedule.
pub fn step_count(sch: &crate::common::sections::Schedule) -> u64 {
    step_count_f64(sch) as u64
}

/// Check every value of a parsed scene. Returns the first problem found.
pub fn check(ls: &LoadedScene, laws: &LawRegistry) -> Result<(), SceneError> {
    let s = &ls.scene;
    let dim = s.scene.dim;
    if dim != 2 && dim != 3 {
        return Err(ls.error(&k(&["scene", "dim"]), format!("= {dim} must be 2 or 3")));
    }
    let d = dim as usize;
    if s.scene.name.is_empty() || s.scene.name.contains(['/', '\\']) {
        return Err(ls.error(
            &k(&["scene", "name"]),
            "must be a non-empty name without slashes",
        ));
    }
    if s.scene.plane.is_some() && d == 3 {
        return Err(ls.error(&k(&["scene", "plane"]), "applies to 2D scenes only"));
    }
    match ls.model() {
        "nscd" => {
            crate::lbm::check::refuse_sections(ls, "nscd")?;
            crate::lsm::check::refuse_sections(ls, "nscd")?;
            return crate::nscd::check::check(ls);
        }
        "lbm" => {
            crate::nscd::check::refuse_sections(ls, "lbm")?;
            crate::lsm::check::refuse_sections(ls, "lbm")?;
            return crate::lbm::check(ls);
        }
        "continuum" => {
            crate::nscd::check::refuse_sections(ls, "continuum")?;
            crate::lbm::check::refuse_sections(ls, "continuum")?;
            crate::lsm::check::refuse_sections(ls, "continuum")?;
            crate::cosserat::check::refuse_in_continuum(ls)?;
            if !crate::nscd::check::has_section(ls, "grid") {
                return Err(ls.error(
                    &k(&["grid"]),
                    "is missing: a continuum scene needs a [grid]",
                ));
            }
        }
        "lsm" => {
            // [lbm] and [thermal] are the fluid of a lattice solid scene
            return crate::lsm::check::check(ls);
        }
        "cosserat" => {
            crate::nscd::check::refuse_sections(ls, "cosserat")?;
            crate::lbm::check::refuse_sections(ls, "cosserat")?;
            crate::lsm::check::refuse_sections(ls, "cosserat")?;
            return crate::cosserat::check::check(ls);
        }
        other => {
            return Err(ls.error(
                &k(&["scene", "model"]),
                format!(
                    "= \"{other}\" is not available in this version of porofrac (available: \
                     continuum, nscd, lbm, cosserat, lsm)"
                ),
            ));
        }
    }
    check_grid(ls, d)?;
    // Materials.
    for (name, m) in &s.material {
        let key = |f: &str| k(&["material", name, f]);
        positive(ls, &key("youngs_modulus"), m.youngs_modulus)?;
        let nu = m.poisson_ratio;
        if !nu.is_finite() || nu >= 0.5 {
            return Err(ls.error(&key("poisson_ratio"), format!("= {nu} must be < 0.5")));
        }
        if nu <= -1.0 {
            return Err(ls.error(&key("poisson_ratio"), format!("= {nu} must be > -1")));
        }
        for (f, v) in [
            ("density", m.density),
            ("solid_bulk_modulus", m.solid_bulk_modulus),
            ("tensile_strength", m.tensile_strength),
            ("fracture_toughness", m.fracture_toughness),
        ] {
            if let Some(v) = v {
                positive(ls, &key(f), v)?;
            }
        }
        if m.fracture_toughness.is_some() && m.tensile_strength.is_none() {
            return Err(ls.error(
                &key("fracture_toughness"),
                "needs tensile_strength (the toughness only holds crack tips that the strength \
                 would fail)",
            ));
        }
        if let Some(c) = m.cohesion {
            if !(c.is_finite() && c >= 0.0) {
                return Err(ls.error(&key("cohesion"), format!("= {c} must be ≥ 0")));
            }
            if m.friction_angle.is_none() {
                return Err(ls.error(&key("cohesion"), "needs friction_angle (Mohr–Coulomb)"));
            }
        }
        if let Some(a) = m.friction_angle
            && !(0.0..90.0).contains(&a)
        {
            return Err(ls.error(
                &key("friction_angle"),
                format!("= {a} must be in [0, 90) degrees"),
            ));
        }
        if let Some(a) = m.biot_alpha
            && !(0.0..=1.0).contains(&a)
        {
            return Err(ls.error(&key("biot_alpha"), format!("= {a} must be in [0, 1]")));
        }
        if let Some(phi) = m.porosity
            && !(phi > 0.0 && phi <= 1.0)
        {
            return Err(ls.error(&key("porosity"), format!("= {phi} must be in (0, 1]")));
        }
        match &m.permeability {
            Some(Permeability::Scalar(v)) => positive(ls, &key("permeability"), *v)?,
            Some(Permeability::Diagonal(v)) => {
                len_is(ls, &key("permeability"), v.len(), d)?;
                for &x in v {
                    positive(ls, &key("permeability"), x)?;
                }
            }
            None => {}
        }
    }
    // Regions.
    if s.region.is_empty() {
        return Err(ls.error(&k(&["region"]), "is missing: at least one [[region]] must select cells and give them a law and a material"));
    }
    for (i, r) in s.region.iter().enumerate() {
        if let Some(m) = &r.material
            && !s.material.contains_key(m)
        {
            let known: Vec<_> = s.material.keys().cloned().collect();
            return Err(ls.error(
                &ki("region", i, &["material"]),
                format!(
                    "= \"{m}\" is not a defined material (known: {})",
                    known.join(", ")
                ),
            ));
        }
        if let Some(l) = &r.law
            && !laws.contains(l)
        {
            return Err(ls.error(
                &ki("region", i, &["law"]),
                format!(
                    "= \"{l}\" is not a known law (known: {})",
                    laws.names().join(", ")
                ),
            ));
        }
        match &r.select {
            Select::All(false) => {
                return Err(ls.error(
                    &ki("region", i, &["select"]),
                    "= { all = false } selects nothing",
                ));
            }
            Select::Box(b) => {
                len_is(ls, &ki("region", i, &["select"]), b[0].len(), d)?;
                len_is(ls, &ki("region", i, &["select"]), b[1].len(), d)?;
            }
            Select::Around(pb)
                if pb.path.is_empty()
                    || pb.path.iter().any(|p| p.len() != d)
                    || pb.radius.is_nan()
                    || pb.radius <= 0.0 =>
            {
                return Err(ls.error(
                    &ki("region", i, &["select"]),
                    format!(
                        "= {{ around = {{ path, radius }} }} needs points of {d} coordinates and \
                         a radius > 0"
                    ),
                ));
            }
            Select::Ijk(r) if d != 3 || r.iter().any(|a| a[0] < 1 || a[0] > a[1]) => {
                return Err(ls.error(
                    &ki("region", i, &["select"]),
                    "= { ijk = [[i0, i1], [j0, j1], [k0, k1]] } needs 1 ≤ lower ≤ upper on \
                     each axis (1-based, inclusive) in a 3D scene",
                ));
            }
            Select::Circle(b) | Select::Sphere(b) => {
                let want = if matches!(r.select, Select::Circle(_)) {
                    2
                } else {
                    3
                };
                if want != d {
                    return Err(ls.error(
                        &ki("region", i, &["select"]),
                        format!("uses a {}D shape in a {d}D scene", want),
                    ));
                }
                len_is(ls, &ki("region", i, &["select"]), b.center.len(), d)?;
                positive(ls, &ki("region", i, &["select"]), b.radius)?;
            }
            _ => {}
        }
    }
    if s.region
        .first()
        .is_some_and(|r| r.material.is_none() || r.law.is_none())
    {
        return Err(ls.error(
            &ki("region", 0, &[]),
            "the first region must give both a law and a material",
        ));
    }
    // Boundary conditions.
    for (i, bc) in s.bc.iter().enumerate() {
        check_bc(ls, i, bc, d)?;
    }
    if let Some(l) = &s.loads {
        if let Some(g) = &l.gravity {
            len_is(ls, &k(&["loads", "gravity"]), g.len(), d)?;
        }
        if let Some(b) = &l.body_force {
            len_is(ls, &k(&["loads", "body_force"]), b.len(), d)?;
            for v in b {
                expr_ok(ls, &k(&["loads", "body_force"]), v, false)?;
            }
        }
    }
    for (i, src) in s.source.iter().enumerate() {
        if !s.region.iter().any(|r| r.name == src.region) {
            return Err(ls.error(
                &ki("source", i, &["region"]),
                format!("= \"{}\" is not a defined region", src.region),
            ));
        }
        match (src.rate, src.pore_volumes_per_hour) {
            (Some(_), Some(_)) | (None, None) => {
                return Err(ls.error(
                    &ki("source", i, &[]),
                    "needs exactly one of rate and pore_volumes_per_hour",
                ));
            }
            (Some(r), None) if !r.is_finite() => {
                return Err(ls.error(&ki("source", i, &["rate"]), "must be finite"));
            }
            _ => {}
        }
    }
    if let Some(sch) = &s.schedule {
        positive(ls, &k(&["schedule", "end_time"]), sch.end_time)?;
        match (sch.dt, sch.steps) {
            (Some(dt), None) => positive(ls, &k(&["schedule", "dt"]), dt)?,
            (None, Some(n)) if n >= 1 => {}
            (None, Some(n)) => {
                return Err(ls.error(&k(&["schedule", "steps"]), format!("= {n} must be ≥ 1")));
            }
            _ => return Err(ls.error(&k(&["schedule"]), "needs exactly one of dt and steps")),
        }
    }
    if let Some(init) = &s.initial
        && let Some(p) = &init.pressure
    {
        expr_ok(ls, &k(&["initial", "pressure"]), p, false)?;
    }
    if let Some(kf) = s.physics.fracture_permeability {
        positive(ls, &k(&["physics", "fracture_permeability"]), kf)?;
    }
    if s.physics.fluid_lag.is_some()
        && (s.physics.fracture != Some(true) || s.physics.flow != Some(true))
    {
        return Err(ls.error(
            &k(&["physics", "fluid_lag"]),
            "needs fracture = true and flow = true",
        ));
    }
    if let Some(t) = s.physics.fracture_transmissivity {
        positive(ls, &k(&["physics", "fracture_transmissivity"]), t)?;
        if s.physics.fracture_permeability.is_some() {
            return Err(ls.error(
                &k(&["physics", "fracture_transmissivity"]),
                "and fracture_permeability both set: give one of them",
            ));
        }
    }
    if let Some(a) = s.physics.crack_tracking
        && !(a.is_finite() && a > 0.0 && a <= 90.0)
    {
        return Err(ls.error(
            &k(&["physics", "crack_tracking"]),
            format!("= {a} must be an angle in (0, 90] degrees"),
        ));
    }
    if let Some(r) = s.physics.crack_exclusion {
        if !(r.is_finite() && r >= 0.0) {
            return Err(ls.error(
                &k(&["physics", "crack_exclusion"]),
                format!("= {r} must be a distance ≥ 0 (m)"),
            ));
        }
        if s.physics.crack_tracking.is_none() {
            return Err(ls.error(&k(&["physics", "crack_exclusion"]), "needs crack_tracking"));
        }
    }
    if let Some(r) = s.physics.open_edge_stiffness
        && !(r.is_finite() && (0.0..1.0).contains(&r))
    {
        return Err(ls.error(
            &k(&["physics", "open_edge_stiffness"]),
            format!("= {r} must be in [0, 1)"),
        ));
    }
    if let Some(t) = s.solver.tolerance {
        positive(ls, &k(&["solver", "tolerance"]), t)?;
    }
    if let Some(l @ (LinearChoice::Lu | LinearChoice::GmresAmg)) = s.solver.linear {
        return Err(ls.error(
            &k(&["solver", "linear"]),
            format!(
                "= \"{}\" is a solver of model \"cosserat\"; this model takes \"auto\", \
                 \"cholesky\" or \"cg-amg\"",
                if l == LinearChoice::Lu {
                    "lu"
                } else {
                    "gmres-amg"
                }
            ),
        ));
    }
    if let Some(t) = s.solver.threads
        && !(0..=1024).contains(&t)
    {
        return Err(ls.error(
            &k(&["solver", "threads"]),
            format!("= {t} must be in 0..=1024 (0: one thread per core)"),
        ));
    }
    if s.output.every < 1 {
        return Err(ls.error(
            &k(&["output", "every"]),
            format!("= {} must be ≥ 1", s.output.every),
        ));
    }
    if let Some(u) = &s.output.exact_displacement {
        let key = k(&["output", "exact_displacement"]);
        len_is(ls, &key, u.len(), d)?;
        for c in u {
            expr_ok(ls, &key, c, false)?;
        }
    }
    let flow = s.physics.flow == Some(true);
    let field_ok = |name: &str, key: Vec<KeyPart>| {
        crate::continuum::fields::Field::parse(name, d, flow)
            .map(|_| ())
            .map_err(|e| ls.error(&key, e))
    };
    let mut names = std::collections::BTreeSet::new();
    for (i, p) in s.output.probe.iter().enumerate() {
        field_ok(&p.field, ki("output.probe", i, &["field"]))?;
        len_is(ls, &ki("output.probe", i, &["at"]), p.at.len(), d)?;
        if !names.insert(p.name.clone()) || p.name == "time" || p.name.contains(',') {
            return Err(ls.error(
                &ki("output.probe", i, &["name"]),
                format!("= \"{}\" is repeated, reserved or contains a comma", p.name),
            ));
        }
    }
    for (i, l) in s.output.line.iter().enumerate() {
        field_ok(&l.field, ki("output.line", i, &["field"]))?;
        len_is(ls, &ki("output.line", i, &["from"]), l.from.len(), d)?;
        len_is(ls, &ki("output.line", i, &["to"]), l.to.len(), d)?;
        line_points_and_name(ls, i, l)?;
    }
    check_wells(ls, d)?;
    check_sizes(ls, d)?;
    Ok(())
}

fn check_grid(ls: &LoadedScene, d: usize) -> Result<(), SceneError> {
    let g = &ls.scene.grid;
    let key = |f: &str| k(&["grid", f]);
    if matches!(g.kind, GridKind::Triangles | GridKind::Voronoi) && d != 2 {
        return Err(ls.error(
            &key("kind"),
            format!("= \"{}\" is a 2D grid, the scene is {d}D", g.kind.as_str()),
        ));
    }
    if g.kind == GridKind::Tetrahedra && d != 3 {
        return Err(ls.error(
            &key("kind"),
            "= \"tetrahedra\" is a 3D grid, the scene is 2D",
        ));
    }
    if g.kind == GridKind::File {
        if g.path.is_none() {
            return Err(ls.error(&key("path"), "is required for kind = \"file\""));
        }
        return Ok(());
    }
    let Some(ext) = &g.extent else {
        return Err(ls.error(
            &key("extent"),
            format!("is required for kind = \"{}\"", g.kind.as_str()),
        ));
    };
    len_is(ls, &key("extent"), ext[0].len(), d)?;
    len_is(ls, &key("extent"), ext[1].len(), d)?;
    for a in 0..d {
        if !(ext[0][a].is_finite() && ext[1][a].is_finite() && ext[1][a] > ext[0][a]) {
            return Err(ls.error(&key("extent"), format!("needs min < max on axis {a}")));
        }
    }
    match (&g.cells, g.kind) {
        (None, _) => return Err(ls.error(&key("cells"), "is required")),
        (Some(CellCount::One(n)), GridKind::Voronoi) if *n >= 1 => {}
        (Some(CellCount::PerAxis(v)), kind) if kind != GridKind::Voronoi => {
            len_is(ls, &key("cells"), v.len(), d)?;
            if v.iter().any(|&n| n < 1) {
                return Err(ls.error(&key("cells"), format!("= {v:?} must all be ≥ 1")));
            }
        }
        (Some(c), kind) => {
            return Err(ls.error(&key("cells"), format!("= {c:?} does not fit kind = \"{}\" (one number for voronoi, one per axis otherwise)", kind.as_str())));
        }
    }
    if let Some(p) = g.perturb
        && !(0.0..0.5).contains(&p)
    {
        return Err(ls.error(&key("perturb"), format!("= {p} must be in [0, 0.5)")));
    }
    if g.diagonals.is_some() && g.kind != GridKind::Composite {
        return Err(ls.error(&key("diagonals"), "applies to composite grids only"));
    }
    if let Some(zone) = &g.mdem_zone {
        if g.kind != GridKind::File || d != 3 {
            return Err(ls.error(
                &key("mdem_zone"),
                "applies to 3D grids read from a file or a corner-point deck",
            ));
        }
        if let Select::Around(pb) = zone
            && (pb.path.is_empty()
                || pb.path.iter().any(|p| p.len() != 3)
                || pb.radius.is_nan()
                || pb.radius <= 0.0)
        {
            return Err(ls.error(
                &key("mdem_zone"),
                "= { around = { path = [[x, y, z], …], radius = r } } needs points of 3 \
                 coordinates and r > 0",
            ));
        }
        if let Some(r) = g.refine
            && !(0..=3).contains(&r)
        {
            return Err(ls.error(
                &key("refine"),
                format!("= {r}: the MDEM zone is refined 0 to 3 times (each ×8 tetrahedra)"),
            ));
        }
    } else if g.well_path.is_some() {
        return Err(ls.error(&key("well_path"), "needs mdem_zone"));
    }
    if let Some(p) = &g.well_path
        && p.iter().any(|p| p.len() != 3)
    {
        return Err(ls.error(&key("well_path"), "needs points of 3 coordinates"));
    }
    if g.well_size.is_some() && g.kind != GridKind::RoundWell {
        return Err(ls.error(&key("well_size"), "applies to round-well grids only"));
    }
    if matches!(g.kind, GridKind::Composite | GridKind::RoundWell) {
        for f in ["center", "zone_half_width", "refine", "well_radius"] {
            let present = match f {
                "center" => g.center.is_some(),
                "zone_half_width" => g.zone_half_width.is_some(),
                "refine" => g.refine.is_some(),
                _ => g.well_radius.is_some(),
            };
            if !present {
                return Err(ls.error(
                    &key(f),
                    format!("is required for kind = \"{}\"", g.kind.as_str()),
                ));
            }
        }
        if let Some(c) = &g.center
            && c.len() != 2
        {
            return Err(ls.error(
                &key("center"),
                format!(
                    "must have 2 components (in 3D: the x, y of the vertical well axis), got {}",
                    c.len()
                ),
            ));
        }
    }
    if g.kind == GridKind::RoundWell {
        check_round_well(ls, ext)?;
    }
    Ok(())
}

/// The round well's sizes, each error naming its key: positive sizes, a well inside the
/// zone with room for one interface spacing of triangles around it.
fn check_round_well(ls: &LoadedScene, ext: &[Vec<f64>; 2]) -> Result<(), SceneError> {
    let g = &ls.scene.grid;
    let key = |f: &str| k(&["grid", f]);
    let positive = |f: &str, v: Option<f64>| match v {
        Some(x) if !(x.is_finite() && x > 0.0) => {
            Err(ls.error(&key(f), format!("= {x} must be a size > 0")))
        }
        _ => Ok(()),
    };
    positive("zone_half_width", g.zone_half_width)?;
    positive("well_radius", g.well_radius)?;
    positive("well_size", g.well_size)?;
    let refine = g.refine.unwrap_or(0);
    if refine < 1 {
        return Err(ls.error(&key("refine"), format!("= {refine} must be ≥ 1")));
    }
    let Some(CellCount::PerAxis(n)) = &g.cells else {
        return Ok(());
    };
    let c = g.center.clone().unwrap_or_default();
    let p = |v: &[f64]| Point::<2>::new(v[0], v[1]);
    let mut spec = RoundWellSpec::new(
        p(&ext[0]),
        p(&ext[1]),
        [n[0].max(1) as usize, n[1].max(1) as usize],
        p(&c),
        g.zone_half_width.unwrap_or(0.0),
        refine as usize,
        g.well_radius.unwrap_or(0.0),
    );
    spec.well_size = g.well_size;
    if let Err(e) = spec.layout() {
        let m = e.to_string();
        let f = if m.contains("bigger than the refined zone") {
            "well_radius"
        } else if m.contains("well_size") {
            "well_size"
        } else {
            "zone_half_width"
        };
        return Err(ls.error(&key(f), m));
    }
    Ok(())
}

fn check_bc(ls: &LoadedScene, i: usize, bc: &Bc, d: usize) -> Result<(), SceneError> {
    let key = |f: &str| ki("bc", i, &[f]);
    if let Some(u) = &bc.displacement {
        len_is(ls, &key("displacement"), u.len(), d)?;
        for c in u {
            expr_ok(ls, &key("displacement"), c, true)?;
        }
    }
    if let Some(t) = &bc.traction {
        len_is(ls, &key("traction"), t.len(), d)?;
        for c in t {
            expr_ok(ls, &key("traction"), c, false)?;
        }
    }
    if let Some(p) = &bc.platen {
        len_is(ls, &ki("bc", i, &["platen", "force"]), p.force.len(), d)?;
        for c in &p.force {
            if let Component::Expr(s) = c
                && s != "free"
            {
                return Err(ls.error(
                    &ki("bc", i, &["platen", "force"]),
                    format!("= \"{s}\": platen forces are numbers or \"free\""),
                ));
            }
        }
        if bc.displacement.is_some() || bc.traction.is_some() {
            return Err(ls.error(
                &key("platen"),
                "cannot be combined with displacement or traction on the same boundary",
            ));
        }
    }
    if let Some(p) = &bc.pressure {
        expr_ok(ls, &key("pressure"), p, false)?;
    }
    if let Some(q) = &bc.flux {
        expr_ok(ls, &key("flux"), q, false)?;
        if bc.pressure.is_some() {
            return Err(ls.error(
                &key("flux"),
                "cannot be combined with pressure on the same boundary",
            ));
        }
    }
    let sides = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"];
    if let Some(pos) = sides.iter().position(|&s| s == bc.boundary)
        && pos >= 2 * d
    {
        return Err(ls.error(
            &key("boundary"),
            format!("= \"{}\" does not exist in {d}D", bc.boundary),
        ));
    }
    Ok(())
}

fn check_wells(ls: &LoadedScene, d: usize) -> Result<(), SceneError> {
    let mut names = std::collections::BTreeSet::new();
    for (i, w) in ls.scene.well.iter().enumerate() {
        let key = |f: &str| ki("well", i, &[f]);
        if w.name.is_empty() || !names.insert(w.name.as_str()) {
            return Err(ls.error(&key("name"), "must be a non-empty name used once"));
        }
        match (&w.at, w.cell) {
            (Some(at), None) => len_is(ls, &key("at"), at.len(), d)?,
            (None, Some(_)) => {}
            _ => {
                return Err(ls.error(
                    &ki("well", i, &[]),
                    "needs exactly one of at (a point) and cell (a cell index)",
                ));
            }
        }
        positive(ls, &key("radius"), w.radius)?;
        if let Some(sk) = w.skin
            && !sk.is_finite()
        {
            return Err(ls.error(&key("skin"), format!("= {sk} must be finite")));
        }
        match (w.rate, w.bottom_hole_pressure) {
            (Some(q), None) if q.is_finite() => {}
            (None, Some(p)) if p.is_finite() => {}
            (Some(_), None) => return Err(ls.error(&key("rate"), "must be finite")),
            (None, Some(_)) => {
                return Err(ls.error(&key("bottom_hole_pressure"), "must be finite"));
            }
            _ => {
                return Err(ls.error(
                    &ki("well", i, &[]),
                    "needs exactly one of rate and bottom_hole_pressure",
                ));
            }
        }
    }
    Ok(())
}

/// Bound steps, output series and generated grids before anything is allocated
/// ([`crate::common::limits`]).
fn check_sizes(ls: &LoadedScene, d: usize) -> Result<(), SceneError> {
    use crate::common::limits::{MAX_CELLS, MAX_STEPS, fits_in_memory, run_bytes};
    let s = &ls.scene;
    if let Some(sch) = &s.schedule {
        let n = step_count_f64(sch);
        let key = if sch.dt.is_some() {
            k(&["schedule", "dt"])
        } else {
            k(&["schedule", "steps"])
        };
        if n > MAX_STEPS as f64 {
            return Err(ls.error(
                &key,
                format!(
                    "gives {n:.3e} steps up to end_time = {}, more than the {MAX_STEPS} a run \
                     may take",
                    sch.end_time
                ),
            ));
        }
        // Output series kept in memory: the written times, probe columns and line rows
        // (8 bytes per number, about 24 in the CSV text).
        let written = n / s.output.every.max(1) as f64 + 2.0;
        let numbers: f64 = 1.0
            + s.output.probe.len() as f64
            + s.output
                .line
                .iter()
                .map(|l| l.points as f64 * (d as f64 + 2.0))
                .sum::<f64>();
        fits_in_memory(
            written * numbers * 32.0,
            &format!("{n:.3e} steps with these probes and lines"),
        )
        .map_err(|e| ls.error(&key, e))?;
    }
    let g = &s.grid;
    let per_axis: Vec<f64> = match &g.cells {
        Some(CellCount::PerAxis(v)) => v.iter().map(|&n| n as f64).collect(),
        Some(CellCount::One(n)) => vec![*n as f64],
        None => return Ok(()),
    };
    let boxes: f64 = per_axis.iter().product();
    let corners: f64 = per_axis.iter().map(|n| n + 1.0).product();
    let (cells, nodes) = match g.kind {
        GridKind::Cartesian => (boxes, corners),
        GridKind::Triangles => (2.0 * boxes, corners),
        GridKind::Tetrahedra => (6.0 * boxes, corners),
        GridKind::Voronoi => (boxes, 2.0 * boxes),
        GridKind::Composite | GridKind::RoundWell => {
            // The far field plus the refined zone (about (2 w / h · refine)² squares of
            // two triangles), extruded over cells[2] layers in 3D.
            let (nx, ny) = (per_axis[0], per_axis.get(1).copied().unwrap_or(1.0));
            let refine = g.refine.unwrap_or(1).max(1) as f64;
            let ext = g.extent.as_ref();
            let hx = ext.map_or(1.0, |e| (e[1][0] - e[0][0]) / nx);
            let zone = (2.0 * g.zone_half_width.unwrap_or(0.0) / hx).ceil() + 1.0;
            let fine = (zone * refine) * (zone * refine);
            let (layers, per_layer) = if d == 3 {
                (per_axis.get(2).copied().unwrap_or(1.0), 3.0)
            } else {
                (1.0, 1.0)
            };
            (
                (nx * ny + 2.0 * fine) * layers * per_layer,
                (nx * ny + fine) * (layers + 1.0),
            )
        }
        GridKind::File => return Ok(()),
    };
    let key = k(&["grid", "cells"]);
    if cells > MAX_CELLS as f64 {
        return Err(ls.error(
            &key,
            format!("asks for {cells:.3e} cells, more than the {MAX_CELLS} a grid may have"),
        ));
    }
    let flow = s.physics.flow == Some(true);
    let unknowns = d as f64 * nodes + if flow { cells } else { 0.0 };
    fits_in_memory(
        run_bytes(cells, unknowns),
        &format!("asks for {cells:.3e} cells and {unknowns:.3e} unknowns"),
    )
    .map_err(|e| ls.error(&key, e))
}
