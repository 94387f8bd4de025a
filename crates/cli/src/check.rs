//! Reading and checking a scene file: every problem is a [`SceneError`] with the file,
//! line and key.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::expr::Expr;
use crate::scene::{
    Bc, CellCount, Component, KeyPart, NumOrExpr, Permeability, Scene, Select, key_text,
    line_of_offset, locate,
};

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
    pub scene: Scene,
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

/// Read and parse a scene file (syntax, types, unknown keys).
pub fn load(path: &Path) -> Result<LoadedScene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        file: path.to_path_buf(),
        line: 0,
        message: format!("cannot read the scene file: {e}"),
    })?;
    let scene: Scene = toml::from_str(&text).map_err(|e| SceneError {
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

fn expr_ok(
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

/// Fields a probe or line may sample.
pub const FIELDS: [&str; 13] = [
    "pressure",
    "ux",
    "uy",
    "uz",
    "sxx",
    "syy",
    "szz",
    "sxy",
    "syz",
    "sxz",
    "smax",
    "smin",
    "fractured",
];

/// Check every value of a parsed scene. Returns the first problem found.
pub fn check(ls: &LoadedScene) -> Result<(), SceneError> {
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
    if let Some(p) = &s.scene.plane {
        if d == 3 {
            return Err(ls.error(&k(&["scene", "plane"]), "applies to 2D scenes only"));
        }
        if p != "strain" && p != "stress" {
            return Err(ls.error(
                &k(&["scene", "plane"]),
                format!("= \"{p}\" must be \"strain\" or \"stress\""),
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
        ] {
            if let Some(v) = v {
                positive(ls, &key(f), v)?;
            }
        }
        if let Some(c) = m.cohesion {
            if !(c.is_finite() && c >= 0.0) {
                return Err(ls.error(&key("cohesion"), format!("= {c} must be ≥ 0")));
            }
            if m.friction_angle.is_none() {
                return Err(ls.error(&key("cohesion"), "needs friction_angle (Mohr–Coulomb)"));
            }
        }
        if let Some(a) = m.friction_angle {
            if !(0.0..90.0).contains(&a) {
                return Err(ls.error(
                    &key("friction_angle"),
                    format!("= {a} must be in [0, 90) degrees"),
                ));
            }
        }
        if let Some(a) = m.biot_alpha {
            if !(0.0..=1.0).contains(&a) {
                return Err(ls.error(&key("biot_alpha"), format!("= {a} must be in [0, 1]")));
            }
        }
        if let Some(phi) = m.porosity {
            if !(phi > 0.0 && phi <= 1.0) {
                return Err(ls.error(&key("porosity"), format!("= {phi} must be in (0, 1]")));
            }
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
        if let Some(m) = &r.material {
            if !s.material.contains_key(m) {
                let known: Vec<_> = s.material.keys().cloned().collect();
                return Err(ls.error(
                    &ki("region", i, &["material"]),
                    format!(
                        "= \"{m}\" is not a defined material (known: {})",
                        known.join(", ")
                    ),
                ));
            }
        }
        if let Some(l) = &r.law {
            if !["vem", "mdem", "dem"].contains(&l.as_str()) {
                return Err(ls.error(
                    &ki("region", i, &["law"]),
                    format!("= \"{l}\" must be one of vem, mdem, dem"),
                ));
            }
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
    if let Some(init) = &s.initial {
        if let Some(m) = &init.mechanics {
            if m != "equilibrium" && m != "zero" {
                return Err(ls.error(
                    &k(&["initial", "mechanics"]),
                    format!("= \"{m}\" must be \"equilibrium\" or \"zero\""),
                ));
            }
        }
        if let Some(p) = &init.pressure {
            expr_ok(ls, &k(&["initial", "pressure"]), p, false)?;
        }
    }
    if let Some(c) = &s.physics.coupling {
        if !["monolithic", "fixed-stress", "explicit-pressure", "none"].contains(&c.as_str()) {
            return Err(ls.error(
                &k(&["physics", "coupling"]),
                format!("= \"{c}\" must be monolithic, fixed-stress, explicit-pressure or none"),
            ));
        }
    }
    if let Some(f) = &s.physics.failure_stress {
        if f != "cell" && f != "recovered" {
            return Err(ls.error(
                &k(&["physics", "failure_stress"]),
                format!("= \"{f}\" must be \"cell\" or \"recovered\""),
            ));
        }
    }
    if let Some(kf) = s.physics.fracture_permeability {
        positive(ls, &k(&["physics", "fracture_permeability"]), kf)?;
    }
    if let Some(a) = s.physics.crack_tracking
        && !(a.is_finite() && a > 0.0 && a <= 90.0)
    {
        return Err(ls.error(
            &k(&["physics", "crack_tracking"]),
            format!("= {a} must be an angle in (0, 90] degrees"),
        ));
    }
    if let Some(r) = s.physics.open_edge_stiffness
        && !(r.is_finite() && (0.0..1.0).contains(&r))
    {
        return Err(ls.error(
            &k(&["physics", "open_edge_stiffness"]),
            format!("= {r} must be in [0, 1)"),
        ));
    }
    if let Some(m) = &s.solver.mechanics {
        if m != "direct" && m != "explicit" {
            return Err(ls.error(
                &k(&["solver", "mechanics"]),
                format!("= \"{m}\" must be \"direct\" or \"explicit\""),
            ));
        }
    }
    if let Some(l) = &s.solver.linear {
        if !["auto", "cholesky", "cg-amg"].contains(&l.as_str()) {
            return Err(ls.error(
                &k(&["solver", "linear"]),
                format!("= \"{l}\" must be auto, cholesky or cg-amg"),
            ));
        }
    }
    if let Some(t) = s.solver.tolerance {
        positive(ls, &k(&["solver", "tolerance"]), t)?;
    }
    if let Some(t) = s.solver.threads {
        if t < 0 {
            return Err(ls.error(&k(&["solver", "threads"]), format!("= {t} must be ≥ 0")));
        }
    }
    if s.output.every < 1 {
        return Err(ls.error(
            &k(&["output", "every"]),
            format!("= {} must be ≥ 1", s.output.every),
        ));
    }
    let mut names = std::collections::BTreeSet::new();
    for (i, p) in s.output.probe.iter().enumerate() {
        if !FIELDS.contains(&p.field.as_str()) {
            return Err(ls.error(
                &ki("output.probe", i, &["field"]),
                format!(
                    "= \"{}\" is not a field (known: {})",
                    p.field,
                    FIELDS.join(", ")
                ),
            ));
        }
        len_is(ls, &ki("output.probe", i, &["at"]), p.at.len(), d)?;
        if !names.insert(p.name.clone()) || p.name == "time" || p.name.contains(',') {
            return Err(ls.error(
                &ki("output.probe", i, &["name"]),
                format!("= \"{}\" is repeated, reserved or contains a comma", p.name),
            ));
        }
    }
    for (i, l) in s.output.line.iter().enumerate() {
        if !FIELDS.contains(&l.field.as_str()) {
            return Err(ls.error(
                &ki("output.line", i, &["field"]),
                format!(
                    "= \"{}\" is not a field (known: {})",
                    l.field,
                    FIELDS.join(", ")
                ),
            ));
        }
        len_is(ls, &ki("output.line", i, &["from"]), l.from.len(), d)?;
        len_is(ls, &ki("output.line", i, &["to"]), l.to.len(), d)?;
        if l.points < 2 {
            return Err(ls.error(
                &ki("output.line", i, &["points"]),
                format!("= {} must be ≥ 2", l.points),
            ));
        }
        if l.name.is_empty() || l.name.contains(['/', '\\']) {
            return Err(ls.error(
                &ki("output.line", i, &["name"]),
                "must be a non-empty file name",
            ));
        }
    }
    Ok(())
}

fn check_grid(ls: &LoadedScene, d: usize) -> Result<(), SceneError> {
    let g = &ls.scene.grid;
    let key = |f: &str| k(&["grid", f]);
    let kinds = [
        "cartesian",
        "triangles",
        "tetrahedra",
        "voronoi",
        "file",
        "composite",
    ];
    if !kinds.contains(&g.kind.as_str()) {
        return Err(ls.error(
            &key("kind"),
            format!("= \"{}\" must be one of {}", g.kind, kinds.join(", ")),
        ));
    }
    if (g.kind == "triangles" || g.kind == "voronoi") && d != 2 {
        return Err(ls.error(
            &key("kind"),
            format!("= \"{}\" is a 2D grid, the scene is {d}D", g.kind),
        ));
    }
    if g.kind == "tetrahedra" && d != 3 {
        return Err(ls.error(
            &key("kind"),
            "= \"tetrahedra\" is a 3D grid, the scene is 2D",
        ));
    }
    if g.kind == "file" {
        if g.path.is_none() {
            return Err(ls.error(&key("path"), "is required for kind = \"file\""));
        }
        return Ok(());
    }
    let Some(ext) = &g.extent else {
        return Err(ls.error(
            &key("extent"),
            format!("is required for kind = \"{}\"", g.kind),
        ));
    };
    len_is(ls, &key("extent"), ext[0].len(), d)?;
    len_is(ls, &key("extent"), ext[1].len(), d)?;
    for a in 0..d {
        if !(ext[0][a].is_finite() && ext[1][a].is_finite() && ext[1][a] > ext[0][a]) {
            return Err(ls.error(&key("extent"), format!("needs min < max on axis {a}")));
        }
    }
    match (&g.cells, g.kind.as_str()) {
        (None, _) => return Err(ls.error(&key("cells"), "is required")),
        (Some(CellCount::One(n)), "voronoi") if *n >= 1 => {}
        (Some(CellCount::PerAxis(v)), kind) if kind != "voronoi" => {
            len_is(ls, &key("cells"), v.len(), d)?;
            if v.iter().any(|&n| n < 1) {
                return Err(ls.error(&key("cells"), format!("= {v:?} must all be ≥ 1")));
            }
        }
        (Some(c), kind) => {
            return Err(ls.error(&key("cells"), format!("= {c:?} does not fit kind = \"{kind}\" (one number for voronoi, one per axis otherwise)")));
        }
    }
    if let Some(p) = g.perturb {
        if !(0.0..0.5).contains(&p) {
            return Err(ls.error(&key("perturb"), format!("= {p} must be in [0, 0.5)")));
        }
    }
    if let Some(d) = &g.diagonals
        && (g.kind != "composite" || (d != "structured" && d != "alternating"))
    {
        return Err(ls.error(
            &key("diagonals"),
            format!("= \"{d}\" must be \"structured\" or \"alternating\" (composite grids)"),
        ));
    }
    if g.kind == "composite" {
        for f in ["center", "zone_half_width", "refine", "well_radius"] {
            let present = match f {
                "center" => g.center.is_some(),
                "zone_half_width" => g.zone_half_width.is_some(),
                "refine" => g.refine.is_some(),
                _ => g.well_radius.is_some(),
            };
            if !present {
                return Err(ls.error(&key(f), "is required for kind = \"composite\""));
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
            if let Component::Expr(s) = c {
                if s != "free" {
                    return Err(ls.error(
                        &ki("bc", i, &["platen", "force"]),
                        format!("= \"{s}\": platen forces are numbers or \"free\""),
                    ));
                }
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
    if let Some(pos) = sides.iter().position(|&s| s == bc.boundary) {
        if pos >= 2 * d {
            return Err(ls.error(
                &key("boundary"),
                format!("= \"{}\" does not exist in {d}D", bc.boundary),
            ));
        }
    }
    Ok(())
}
