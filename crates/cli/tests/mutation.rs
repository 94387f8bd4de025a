//! Mutation harness: every bundled input — the scenes (`scenes/**/*.toml`), the meshes
//! (`scenes/meshes/*`) and the corner-point decks (`scenes/**/*.grdecl`) — is mutated
//! with a fixed seed, and the built `porofrac` binary is run on each mutant under a 4 GB
//! address-space limit and a wall-time bound: `check` on every scene mutant, `run` on the
//! mutants of the scenes whose unmutated run is short (some of them with the schedule
//! cut to two output times) and on every mesh and deck mutant (through the fast scene
//! that reads it).
//!
//! Mutations (see `mutation/mutator.rs`): a number replaced by a hostile value (0, −1,
//! ±1e300, 1e-300, nan, inf, 2⁶⁴−1, 2³¹, 1e20), a string replaced by "", 10 kB, "1/0"
//! or "x", a line deleted or duplicated, a `[section]` header dropped, the file
//! truncated at a random byte, the values of two lines swapped; for decks also a repeat
//! count `n*v` made huge or zero, a record's `/` dropped, every number of a keyword's
//! first data line replaced; for meshes also attributes and binary data changed.
//!
//! Each mutant must give (see `mutation/oracle.rs`) exit status 1 with a message naming
//! the input file, or exit status 0 with `ok` (check) or only finite numbers in
//! `probes.csv` and `summary.json` (run). A panic, a signal, another status or a bound
//! exceeded is a failure. A run past the bound that stops on Ctrl-C with status 130
//! within the grace period is listed as a long run, not a failure: the mutated scene
//! asks for more work (a later end time, a stiffer rock and so a smaller stable step, a
//! load that takes many failure rounds), and stopping it is what a user would do. A run
//! that ignores Ctrl-C is a failure. `check` builds the model as `run` does (packings,
//! settling) and has the same grace.
//!
//! Environment: `POROFRAC_MUTATION_SEED` (default 20250611), `POROFRAC_MUTATION_BUDGET_S`
//! (wall-time budget in seconds, default 100; mutants are drawn round after round over
//! all files, meshes and decks four times a round, until it is spent), `POROFRAC_MUTATION_JOBS` (parallel children, default
//! 2), `POROFRAC_MUTATION_FILE` (only files whose path under `scenes/` contains this).
//! Failing mutants stay in `target/mutants/<seed>/` with their stdout and stderr; the
//! full list of failures is printed and written to `target/mutants/<seed>/failures.txt`
//! with the command that reproduces each.

#[path = "mutation/mutator.rs"]
mod mutator;
#[path = "mutation/oracle.rs"]
mod oracle;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use mutator::{Kind, Mutant, Rng, mutate};
use oracle::{CHECK_TIMEOUT, End, Outcome, RUN_TIMEOUT, command_line, invoke, non_finite_outputs};

/// Scenes (paths under `scenes/`) whose unmutated run takes well under a second here
/// (measured: 0.04 s to 0.42 s each in release); their mutants are also run.
const FAST: [&str; 13] = [
    "cantilever.toml",
    "corner_point/injection.toml",
    "cosserat_plate_hole.toml",
    "cosserat_shear_layer.toml",
    "flow_column.toml",
    "hybrid_uniaxial.toml",
    "lbm/taylor_green.toml",
    "mandel.toml",
    "manufactured_e2.toml",
    "nscd/column.toml",
    "patch_test.toml",
    "tension_band.toml",
    "terzaghi.toml",
];

/// Scenes (paths under `scenes/`) that are run with their schedule cut to two output
/// times (`end_time` = 2 `dt`, or `steps` = 2), which takes well under a second each
/// (measured 0.24 s to 0.95 s); these capped texts are what is mutated.
const CAPPED: [&str; 12] = [
    "cosserat_lamb.toml",
    "hydrofrac_composite.toml",
    "hydrofrac_seed.toml",
    "hydrofrac_seed_fluid_lag.toml",
    "lbm/schaefer_turek_2d1.toml",
    "lsm/borehole_dry.toml",
    "lsm/borehole_flooded.toml",
    "lsm/brazilian.toml",
    "lsm_heat.toml",
    "nscd/fault.toml",
    "nscd/fault_gamma0.toml",
    "nscd/forced_fold.toml",
];

/// `text` with its `[schedule]` cut to two output times: `end_time = 2 dt`, or with
/// `steps`, `end_time` scaled by `2 / steps` and `steps = 2`.
fn capped(text: &str) -> String {
    let value = |l: &str| -> Option<(String, f64)> {
        let (k, v) = l.split_once('=')?;
        let v = v.split('#').next()?.trim().parse().ok()?;
        Some((k.trim().to_string(), v))
    };
    let mut section = String::new();
    let mut sch: BTreeMap<String, f64> = BTreeMap::new();
    for l in text.lines() {
        let t = l.trim();
        if t.starts_with('[') {
            section = t.to_string();
        } else if section == "[schedule]"
            && let Some((k, v)) = value(t)
        {
            sch.insert(k, v);
        }
    }
    let end = match (sch.get("dt"), sch.get("steps"), sch.get("end_time")) {
        (Some(dt), _, _) => 2.0 * dt,
        (None, Some(n), Some(t)) => t * 2.0 / n,
        _ => return text.to_string(),
    };
    let mut out = String::with_capacity(text.len());
    section.clear();
    for l in text.lines() {
        let t = l.trim();
        if t.starts_with('[') {
            section = t.to_string();
        }
        let key = value(t).map(|(k, _)| k);
        match key.as_deref() {
            Some("end_time") if section == "[schedule]" => {
                out.push_str(&format!("end_time = {end:e}"))
            }
            Some("steps") if section == "[schedule]" => out.push_str("steps = 2"),
            _ => out.push_str(l),
        }
        out.push('\n');
    }
    out
}

/// Mutants of each mesh and deck per round (of each scene: 1).
const DATA_WEIGHT: u64 = 4;

/// The outcome of an error that names no input file (noted, not a failure).
const NO_FILE: &str = "refused, naming no file";

/// The outcome of a run past the bound that stopped on Ctrl-C with status 130 within
/// the grace period (noted, not a failure: the mutated scene asks for a long run — a
/// later end time, a stiffer rock and so a smaller stable step, a load that takes many
/// failure rounds — and the run answers Ctrl-C as a user would use it).
const LONG: &str = "long run, stopped by Ctrl-C";

/// Separates a failure's class from its detail.
const DETAIL: &str = " | ";

/// One input file of the corpus.
struct Input {
    /// Path under `scenes/` with `/` separators.
    rel: String,
    kind: Kind,
    text: String,
    /// For a mesh or deck: the scene (path under `scenes/`) that reads it, and the path
    /// the scene gives for it.
    reader: Option<(String, String)>,
}

/// One failure: where, what, and how to reproduce it.
struct Failure {
    class: String,
    mutant: String,
    what: String,
    command: String,
    detail: String,
}

#[derive(Default)]
struct Tally {
    mutants: usize,
    checks: usize,
    runs: usize,
    outcomes: BTreeMap<String, usize>,
    failures: Vec<Failure>,
    /// Refusals that name no file: the mutation and the message.
    unlocated: Vec<String>,
    /// Long runs stopped by Ctrl-C: the mutation.
    long: Vec<String>,
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .canonicalize()
        .expect("scenes/")
}

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("read scenes/")
        .map(|e| e.expect("entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files_under(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// The `path = "…"` values of a scene.
fn referenced_paths(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| {
            let (k, v) = l.split_once('=')?;
            (k.trim() == "path").then(|| v.trim().trim_matches('"').to_string())
        })
        .collect()
}

fn corpus(filter: &str) -> Vec<Input> {
    let root = scenes_dir();
    let mut paths = Vec::new();
    files_under(&root, &mut paths);
    let rel = |p: &Path| {
        p.strip_prefix(&root)
            .expect("under scenes/")
            .to_string_lossy()
            .replace('\\', "/")
    };
    let scenes: Vec<(String, String)> = paths
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| (rel(p), std::fs::read_to_string(p).expect("scene")))
        .collect();
    let mut inputs = Vec::new();
    for p in &paths {
        let r = rel(p);
        let ext = p
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let kind = if ext == "toml" {
            Kind::Scene
        } else if r.starts_with("meshes/") {
            Kind::Mesh
        } else if ["grdecl", "inc", "incl"].contains(&ext.as_str()) {
            Kind::Deck
        } else {
            continue;
        };
        if !r.contains(filter) {
            continue;
        }
        let Ok(mut text) = std::fs::read_to_string(p) else {
            continue; // binary meshes are not mutated as text
        };
        if CAPPED.contains(&r.as_str()) {
            text = capped(&text);
        }
        // A mesh or deck is run through a scene that reads it, the fastest one.
        let reader = (kind != Kind::Scene).then(|| {
            let r = &r;
            let mut readers: Vec<(String, String)> = scenes
                .iter()
                .flat_map(|(s, t)| {
                    let dir = Path::new(s)
                        .parent()
                        .map(Path::to_path_buf)
                        .unwrap_or_default();
                    referenced_paths(t)
                        .into_iter()
                        .filter(move |x| dir.join(x).to_string_lossy().replace('\\', "/") == *r)
                        .map(move |x| (s.clone(), x))
                })
                .collect();
            readers.sort_by_key(|(s, _)| !FAST.contains(&s.as_str()));
            readers.into_iter().next()
        });
        let reader = match reader {
            Some(None) => continue, // no bundled scene reads it
            Some(r) => r,
            None => None,
        };
        inputs.push(Input {
            rel: r,
            kind,
            text,
            reader,
        });
    }
    inputs
}

fn env_or<T: std::str::FromStr>(key: &str, default: T) -> T {
    match std::env::var(key) {
        Ok(v) => v
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("{key} = {v:?} is not a number")),
        Err(_) => default,
    }
}

fn last_lines(s: &str, n: usize) -> String {
    let lines: Vec<&str> = s.lines().collect();
    let tail = lines[lines.len().saturating_sub(n)..].join("\n");
    if tail.len() > 600 {
        let mut cut = 600;
        while !tail.is_char_boundary(cut) {
            cut -= 1;
        }
        format!("{}…", &tail[..cut])
    } else {
        tail
    }
}

/// What to show of a child's stderr: the panic message if there is one, else the end.
fn excerpt(stderr: &str) -> String {
    let lines: Vec<&str> = stderr.lines().collect();
    match lines.iter().position(|l| l.contains("panicked at")) {
        Some(i) => lines[i..(i + 2).min(lines.len())].join(" "),
        None => last_lines(stderr, 3),
    }
}

/// Judge one invocation; `None` when acceptable, else the failure class. `names` are
/// the file names an error message may name; `out` is the output directory of a run.
fn judge(o: &Outcome, names: &[&str], out: Option<&Path>) -> Result<String, String> {
    match o.end {
        _ if o.stderr.contains("panicked") => Err("panic".into()),
        End::Exit(101) => Err("exit 101 (panic)".into()),
        End::Signal(s) => Err(format!("killed by signal {s}")),
        End::Timeout(None) => Err("timeout, ignores Ctrl-C (killed)".into()),
        End::Timeout(Some(130)) => Ok(LONG.into()),
        End::Timeout(Some(c)) => Err(format!("timeout (stopped by Ctrl-C with status {c})")),
        End::Exit(1) => {
            let msg = o.stderr.trim();
            if msg.is_empty() {
                Err("exit 1 without a message".into())
            } else if !o.stderr.lines().any(|l| {
                l.strip_prefix("error: ")
                    .is_some_and(|m| m.chars().any(char::is_alphabetic))
            }) {
                Err("exit 1 without an `error:` line".into())
            } else if names.iter().any(|n| msg.contains(n)) {
                Ok("refused, naming the file".into())
            } else {
                // Errors found while running (conflicting conditions at a node, a
                // singular system) name the key or the item but not the file and line.
                Ok(NO_FILE.into())
            }
        }
        End::Exit(0) => match out {
            None if o.stdout.contains(": ok") => Ok("accepted".into()),
            None => Err("check exit 0 without `ok`".into()),
            Some(out) => {
                let bad = non_finite_outputs(out);
                if bad.is_empty() {
                    Ok("ran".into())
                } else {
                    Err(format!(
                        "exit 0 with non-finite output{DETAIL}{}",
                        bad.join("; ")
                    ))
                }
            }
        },
        End::Exit(c) => Err(format!("exit status {c}")),
    }
}

/// Set up, check and run one mutant (`round` = None: the unmutated input).
fn one(input: &Input, round: Option<u64>, seed: u64, root: &Path, tally: &Mutex<Tally>) {
    let scenes = scenes_dir();
    let label = match round {
        Some(r) => format!("r{r:04}"),
        None => "unmutated".to_string(),
    };
    let dir = root.join(&label).join(input.rel.replace('/', "__"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("mutant directory");
    let mut rng = Rng::for_mutant(seed, &input.rel, round.unwrap_or(u64::MAX));
    let m = match round {
        Some(_) => mutate(input.kind, &input.text, &mut rng),
        None => Mutant {
            bytes: input.text.clone().into_bytes(),
            what: "unmutated".into(),
        },
    };
    // The scene to check and run, with the files it reads beside it.
    let (scene_rel, data_name) = match &input.reader {
        None => (input.rel.clone(), None),
        Some((s, _)) => (
            s.clone(),
            Some(input.rel.rsplit('/').next().unwrap_or("").to_string()),
        ),
    };
    let scene_name = scene_rel.rsplit('/').next().expect("file name").to_string();
    let scene_src_dir = scenes.join(&scene_rel).parent().expect("dir").to_path_buf();
    let scene_path = dir.join(&scene_name);
    let scene_text = std::fs::read_to_string(scenes.join(&scene_rel)).expect("scene");
    match &input.reader {
        None => std::fs::write(&scene_path, &m.bytes).expect("write mutant"),
        Some(_) => std::fs::write(&scene_path, &scene_text).expect("write scene"),
    }
    for r in referenced_paths(&scene_text) {
        let target = dir.join(&r);
        if let Some(p) = target.parent() {
            let _ = std::fs::create_dir_all(p);
        }
        let is_mutated = input.reader.as_ref().is_some_and(|(_, x)| *x == r);
        if is_mutated {
            std::fs::write(&target, &m.bytes).expect("write mutant");
        } else {
            let _ = std::fs::copy(scene_src_dir.join(&r), &target);
        }
    }
    let _ = std::fs::write(
        dir.join("mutation.txt"),
        format!("{}: {}\n", input.rel, m.what),
    );
    let scene_arg = scene_path.to_string_lossy().into_owned();
    let mut names = vec![scene_name.as_str()];
    if let Some(d) = &data_name {
        names.push(d.as_str());
    }
    let id = format!("seed {seed}, {label}, {}", input.rel);
    let mut failed = false;
    let mut record = |kind: &str, o: &Outcome, verdict: Result<String, String>, args: &[&str]| {
        let mut t = tally.lock().expect("tally");
        match verdict {
            Ok(v) => {
                if v == NO_FILE {
                    let first = o.stderr.lines().find(|l| l.starts_with("error: "));
                    let note = format!("{id}: {} => {}", m.what, first.unwrap_or(""));
                    t.unlocated.push(note);
                } else if v == LONG {
                    t.long.push(format!("{id}: {}", m.what));
                }
                *t.outcomes.entry(format!("{kind}: {v}")).or_default() += 1
            }
            Err(class) => {
                *t.outcomes.entry(format!("{kind}: FAILED")).or_default() += 1;
                failed = true;
                let (class, extra) = class.split_once(DETAIL).unwrap_or((&class, ""));
                t.failures.push(Failure {
                    class: format!("{kind}: {class}"),
                    mutant: id.clone(),
                    what: m.what.clone(),
                    command: command_line(args),
                    detail: format!(
                        "after {:.1} s; {extra}{}stderr: {}",
                        o.seconds,
                        if extra.is_empty() { "" } else { "; " },
                        excerpt(&o.stderr)
                    ),
                });
            }
        }
    };
    let check_args = ["check", scene_arg.as_str()];
    let c = invoke(&dir, "check", &check_args, CHECK_TIMEOUT);
    let verdict = judge(&c, &names, None);
    record("check", &c, verdict, &check_args);
    let fast = FAST.contains(&scene_rel.as_str()) || CAPPED.contains(&scene_rel.as_str());
    let run = fast
        && (input.reader.is_some()
            || round.is_none()
            || matches!(c.end, End::Exit(0))
            || rng.below(4) == 0);
    if run {
        let out = dir.join("out");
        let out_arg = out.to_string_lossy().into_owned();
        let run_args = ["run", scene_arg.as_str(), "--out", out_arg.as_str()];
        let o = invoke(&dir, "run", &run_args, RUN_TIMEOUT);
        let verdict = judge(&o, &names, Some(&out));
        record("run", &o, verdict, &run_args);
    }
    {
        let mut t = tally.lock().expect("tally");
        t.mutants += 1;
        t.checks += 1;
        t.runs += usize::from(run);
    }
    if !failed {
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn every_mutant_of_every_bundled_input_is_refused_cleanly_or_runs() {
    let seed: u64 = env_or("POROFRAC_MUTATION_SEED", 20_250_611);
    let budget = Duration::from_secs_f64(env_or("POROFRAC_MUTATION_BUDGET_S", 100.0));
    let jobs: usize = env_or("POROFRAC_MUTATION_JOBS", 2usize).max(1);
    let filter = std::env::var("POROFRAC_MUTATION_FILE").unwrap_or_default();
    let inputs = corpus(&filter);
    assert!(!inputs.is_empty(), "no bundled input matches {filter:?}");
    if filter.is_empty() {
        // The corpus is what the bundled files are: scenes, a mesh, a deck.
        for k in [Kind::Scene, Kind::Mesh, Kind::Deck] {
            assert!(inputs.iter().any(|i| i.kind == k), "no {k:?} in scenes/");
        }
    }
    let root = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("../mutants")
        .join(seed.to_string());
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&root).expect("target/mutants");
    let root = root.canonicalize().expect("target/mutants");

    // First the unmutated fast scenes and the meshes and decks through their readers
    // (the oracle must accept them), then rounds of mutants over all inputs.
    let base: Vec<usize> = (0..inputs.len())
        .filter(|&i| {
            let r = inputs[i].rel.as_str();
            inputs[i].reader.is_some() || FAST.contains(&r) || CAPPED.contains(&r)
        })
        .collect();
    // A round mutates every scene once and every mesh and deck DATA_WEIGHT times (each
    // is a single file of its kind, and its runs are short).
    let slots: Vec<(usize, u64)> = (0..inputs.len())
        .flat_map(|i| {
            let w = if inputs[i].kind == Kind::Scene {
                1
            } else {
                DATA_WEIGHT
            };
            (0..w).map(move |sub| (i, sub))
        })
        .collect();
    let tally = Mutex::new(Tally::default());
    let next = AtomicUsize::new(0);
    let start = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| {
                loop {
                    let n = next.fetch_add(1, Ordering::Relaxed);
                    if n < base.len() {
                        one(&inputs[base[n]], None, seed, &root, &tally);
                        continue;
                    }
                    if start.elapsed() > budget {
                        break;
                    }
                    let k = n - base.len();
                    let (i, sub) = slots[k % slots.len()];
                    let round = (k / slots.len()) as u64 * DATA_WEIGHT + sub;
                    one(&inputs[i], Some(round), seed, &root, &tally);
                }
            });
        }
    });
    let wall = start.elapsed().as_secs_f64();
    let t = tally.into_inner().expect("tally");

    let mut report = format!(
        "mutation harness: seed {seed}, budget {:.0} s, {} inputs, {} mutants (incl. {} unmutated), \
         {} checks, {} runs in {wall:.1} s\n",
        budget.as_secs_f64(),
        inputs.len(),
        t.mutants,
        base.len(),
        t.checks,
        t.runs
    );
    for (k, v) in &t.outcomes {
        report.push_str(&format!("  {k}: {v}\n"));
    }
    let mut classes: BTreeMap<&str, usize> = BTreeMap::new();
    for f in &t.failures {
        *classes.entry(f.class.as_str()).or_default() += 1;
    }
    if !classes.is_empty() {
        report.push_str(&format!("{} failures by class:\n", t.failures.len()));
        for (k, v) in &classes {
            report.push_str(&format!("  {v:5}  {k}\n"));
        }
        report.push_str("failures:\n");
    }
    let mut failures = t.failures;
    failures.sort_by(|a, b| (&a.class, &a.mutant).cmp(&(&b.class, &b.mutant)));
    for f in &failures {
        report.push_str(&format!(
            "- [{}] {}: {}\n  reproduce: {}\n  {}\n",
            f.class, f.mutant, f.what, f.command, f.detail
        ));
    }
    let mut unlocated = t.unlocated;
    unlocated.sort();
    if !unlocated.is_empty() {
        report.push_str(&format!(
            "refusals that name no input file (not failures; {}):\n",
            unlocated.len()
        ));
        for u in &unlocated {
            report.push_str(&format!("  {u}\n"));
        }
    }
    if !t.long.is_empty() {
        report.push_str(&format!(
            "long runs stopped by Ctrl-C (not failures; {}):\n",
            t.long.len()
        ));
        for l in &t.long {
            report.push_str(&format!("  {l}\n"));
        }
    }
    let list = root.join("failures.txt");
    std::fs::write(&list, &report).expect("failures.txt");
    println!("{report}");
    assert!(
        failures.is_empty(),
        "{} mutants failed (listed above and in {})",
        failures.len(),
        list.display()
    );
}
