//! The `porofrac` command: runs a scene file and writes ParaView files, CSV and plots.
//! Everything but the arguments, the progress display and the exit status is in
//! `porofrac-scene`.
//!
//! Exit status: 0 on success, 1 for an error in the scene or the run (one line naming the
//! file, line and key), 2 for command-line misuse, 130 when interrupted by Ctrl-C (the
//! finished steps' files are complete and `summary.json` says
//! `"status": "interrupted at t = …"`).
//!
//! `mpirun -n P porofrac run scene.toml` runs the scene on P ranks when built with the
//! `mpi` feature ([`ranks`]).

mod ranks;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Parser, Subcommand};
use porofrac_scene::common::keys;
use porofrac_scene::common::overrides::Override;
use porofrac_scene::{LawRegistry, MODELS, Observer, Scene, SetupReport, StepReport, Stop};

/// Simulate fracturing of porous rock: run scene files, write ParaView files, CSV and plots.
#[derive(Parser, Debug)]
#[command(
    name = "porofrac",
    version,
    about,
    after_help = "Examples:\n  porofrac run scenes/patch_test.toml\n  porofrac run scenes/patch_test.toml --out /tmp/patch\n  porofrac run scenes/patch_test.toml --set material.rock.youngs_modulus=2e10\n  porofrac run --resume /tmp/patch\n  porofrac check scenes/patch_test.toml\n  porofrac keys continuum grid"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene; output goes to out/NAME/ (NAME from the scene) unless --out is given.
    Run {
        /// The scene file (TOML); with --resume it may be left out (the copy in the
        /// checkpoint is used) or must have the content the checkpoint was written from.
        #[arg(required_unless_present = "resume")]
        scene: Option<PathBuf>,
        /// Output directory.
        #[arg(long, conflicts_with = "resume")]
        out: Option<PathBuf>,
        /// Set a key of the scene (repeatable): a dotted key, 1-based numbers for arrays
        /// of tables (`bc.2.value=1e6`), a TOML value or a bare word.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Continue the run whose output directory (with its checkpoint/) is DIR.
        #[arg(long, value_name = "DIR")]
        resume: Option<PathBuf>,
    },
    /// Check a scene without running it: everything a run does before its first step
    /// (files read, grid built, conditions, probes, packings), nothing written; prints
    /// what a run would do, with estimates of its memory and time.
    Check {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Set a key of the scene (repeatable), as for `run`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// List the keys of scene files: type, unit, default, allowed values and meaning.
    Keys {
        /// A model (continuum, cosserat, nscd, lsm, lbm): its sections and the shared ones
        /// it reads; or a section when no model is given.
        model: Option<String>,
        /// A section (`grid`, `bc`, `output.probe`): that section only.
        section: Option<String>,
        /// Markdown tables (docs/SCENE.md is this output for all models).
        #[arg(long)]
        markdown: bool,
        /// Print the JSON Schema of summary.json instead (docs/summary.schema.json).
        #[arg(long, conflicts_with_all = ["model", "section", "markdown"])]
        summary_schema: bool,
    },
}

/// Exit status of an interrupted run (128 + SIGINT, as shells report it).
const INTERRUPTED: u8 = 130;

fn main() -> ExitCode {
    porofrac_scene::common::heap::retain_freed_memory();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Keys {
            summary_schema: true,
            ..
        } => {
            print!("{}", keys::summary_schema());
            return ExitCode::SUCCESS;
        }
        Command::Keys {
            model,
            section,
            markdown,
            ..
        } => return keys(model.as_deref(), section.as_deref(), markdown),
        Command::Check { scene, set } => check(&scene, &set),
        Command::Run {
            scene,
            out,
            set,
            resume,
        } => run(scene.as_deref(), out, resume, &set),
    };
    result.unwrap_or_else(|msg| {
        if !ranks::quiet() {
            eprintln!("error: {msg}");
        }
        ExitCode::from(1)
    })
}

/// `porofrac check`: the scene built as a run builds it (files read, grid, conditions,
/// probes, packings; Ctrl-C stops a long build), nothing written; on success the `ok`
/// line and what a run would do, with estimates of its memory and time.
fn check(path: &Path, set: &[String]) -> Result<ExitCode, String> {
    let set = overrides(set)?;
    let scene = Scene::load_with_overrides(path, LawRegistry::default(), &set)
        .map_err(|e| e.to_string())?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let mut progress = Progress::new(stop);
    let plan = match scene.check(&mut progress) {
        Ok(plan) => plan,
        Err(porofrac_scene::RunError::Interrupted) => {
            progress.finish();
            eprintln!("{}: check interrupted", path.display());
            return Ok(ExitCode::from(INTERRUPTED));
        }
        Err(e) => return Err(e.to_string()),
    };
    progress.finish();
    let what = match scene.file().scene.model.as_deref().unwrap_or("continuum") {
        "continuum" => format!("grid {}", scene.file().grid.kind.as_str()),
        model => format!("model {model}"),
    };
    let mut text = format!(
        "{}: ok ({}D, {what})\n",
        scene.path().display(),
        scene.file().scene.dim
    );
    for line in plan.lines_text() {
        text.push_str(&format!("  {line}\n"));
    }
    // A reader that went away (`| head`) is not an error of the scene.
    let _ = std::io::Write::write_all(&mut std::io::stdout().lock(), text.as_bytes());
    Ok(ExitCode::SUCCESS)
}

/// The `--set` arguments, each `KEY=VALUE`.
fn overrides(set: &[String]) -> Result<Vec<Override>, String> {
    set.iter().map(|s| Override::parse(s)).collect()
}

/// `porofrac keys [MODEL] [SECTION]`: the key reference, from the parser's types.
fn keys(model: Option<&str>, section: Option<&str>, markdown: bool) -> ExitCode {
    let names: Vec<&str> = MODELS.iter().map(|m| m.name()).collect();
    // One word that is not a model is a section.
    let (model, section) = match (model, section) {
        (Some(m), None) if !names.contains(&m) => (None, Some(m)),
        other => other,
    };
    if let Some(m) = model
        && !names.contains(&m)
    {
        eprintln!(
            "error: no model \"{m}\"; the models are {}",
            names.join(", ")
        );
        return ExitCode::from(2);
    }
    let mut sections = keys::sections(MODELS, model);
    if let Some(s) = section {
        let all: Vec<String> = sections.iter().map(|s| s.path.clone()).collect();
        sections = keys::select(sections, s);
        if sections.is_empty() {
            let near = keys::nearest(s, &all)
                .map(|n| format!("; did you mean `{n}`?"))
                .unwrap_or_default();
            eprintln!(
                "error: no section `{s}`{}{near} (sections: {})",
                model
                    .map(|m| format!(" in model \"{m}\""))
                    .unwrap_or_default(),
                all.join(", ")
            );
            return ExitCode::from(2);
        }
    }
    if markdown {
        print!("{}", keys::markdown(&sections));
    } else {
        print!("{}", keys::text(&sections));
    }
    ExitCode::SUCCESS
}

fn run(
    path: Option<&Path>,
    out: Option<PathBuf>,
    resume: Option<PathBuf>,
    set: &[String],
) -> Result<ExitCode, String> {
    let ranks = ranks::Ranks::start()?;
    let set = overrides(set)?;
    let scene = match (path, &resume) {
        (Some(p), _) => Scene::load_with_overrides(p, LawRegistry::default(), &set)
            .map_err(|e| e.to_string())?,
        (None, Some(_)) if !set.is_empty() => {
            return Err(
                "--set with --resume: a resumed run keeps the overrides its checkpoint holds \
                 (name the scene file to give them again)"
                    .into(),
            );
        }
        (None, Some(dir)) => Scene::from_checkpoint(dir).map_err(|e| e.to_string())?,
        (None, None) => return Err("no scene file given".into()),
    };
    let out = resume
        .clone()
        .or(out)
        .unwrap_or_else(|| scene.default_out());
    // Ctrl-C: finish the current step, keep what was written, exit with 130.
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let mut progress = Progress::new(stop);
    let summary = if resume.is_some() && ranks.size() > 1 {
        return Err("--resume continues a run on one rank: run it without mpirun".into());
    } else if resume.is_some() {
        scene.resume(&out, &mut progress)
    } else if ranks.size() > 1 {
        ranks.run(&scene, &out, &mut progress)
    } else {
        scene.run(&out, &mut progress)
    }
    .map_err(|e| e.to_string())?;
    progress.finish();
    if ranks::quiet() {
        return Ok(ExitCode::from(if summary.interrupted() {
            INTERRUPTED
        } else {
            0
        }));
    }
    eprintln!(
        "{}: {}, {} steps in {:.2} s; output in {}{}",
        summary.scene,
        summary.sizes_text,
        summary.steps,
        summary.wall_seconds.total,
        out.display(),
        if summary.interrupted() {
            format!(" ({})", summary.status)
        } else {
            String::new()
        }
    );
    Ok(if summary.interrupted() {
        ExitCode::from(INTERRUPTED)
    } else {
        ExitCode::SUCCESS
    })
}

/// Progress of a run: an indicatif bar when stderr is a terminal, plain lines otherwise;
/// the Ctrl-C flag.
struct Progress {
    bar: Option<indicatif::ProgressBar>,
    stop: Arc<AtomicBool>,
}

impl Progress {
    fn new(stop: Arc<AtomicBool>) -> Self {
        Self { bar: None, stop }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

impl Observer for Progress {
    fn step(&mut self, r: &StepReport) {
        use std::io::IsTerminal;
        if r.total <= 1 {
            return;
        }
        // Steps are the output times after the initial state (step 0): `step 40/40`
        // ends a run of 40 steps, as `summary.json` counts them.
        let steps = r.total - 1;
        let mut msg = format!(
            "t = {:.4e} s, solver iterations {} (total {})",
            r.time, r.iterations, r.total_iterations
        );
        if let Some(what) = r.failed_name {
            msg.push_str(&format!(", {} {what}", r.failed));
        }
        if self.bar.is_none() && std::io::stderr().is_terminal() {
            let bar = indicatif::ProgressBar::new(steps as u64);
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{bar:30} step {pos}/{len}  {msg}  ETA {eta}",
            ) {
                bar.set_style(style);
            }
            self.bar = Some(bar);
        }
        match &self.bar {
            Some(bar) => {
                bar.set_position(r.step as u64);
                bar.set_message(msg);
            }
            None if r.step == 0 => eprintln!("step 0/{steps} (initial state): {msg}"),
            None => eprintln!("step {}/{steps}: {msg}", r.step),
        }
    }

    fn setup(&mut self, r: &SetupReport<'_>) {
        match &self.bar {
            Some(bar) => bar.set_message(r.to_string()),
            None => eprintln!("{r}"),
        }
    }

    fn stop_requested(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    fn stop_handle(&self) -> Stop {
        Stop::from_flag(Arc::clone(&self.stop))
    }
}
