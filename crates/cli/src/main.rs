//! The `porofrac` command: runs a scene file and writes ParaView files, CSV and plots.
//! Everything but the arguments, the progress display and the exit status is in
//! `porofrac-scene`.
//!
//! Exit status: 0 on success, 1 for an error in the scene or the run (one line naming the
//! file, line and key), 2 for command-line misuse, 130 when interrupted by Ctrl-C (the
//! finished steps' files are complete and `summary.json` says
//! `"status": "interrupted at t = …"`).

mod heap;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Parser, Subcommand};
use porofrac_scene::{Observer, Scene, SetupReport, StepReport, Stop};

/// Simulate fracturing of porous rock: run scene files, write ParaView files, CSV and plots.
#[derive(Parser, Debug)]
#[command(
    name = "porofrac",
    version,
    about,
    after_help = "Examples:\n  porofrac run scenes/patch_test.toml\n  porofrac run scenes/patch_test.toml --out /tmp/patch\n  porofrac check scenes/patch_test.toml"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene; output goes to out/NAME/ (NAME from the scene) unless --out is given.
    Run {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Output directory.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Check a scene file without running it.
    Check {
        /// The scene file (TOML).
        scene: PathBuf,
    },
}

/// Exit status of an interrupted run (128 + SIGINT, as shells report it).
const INTERRUPTED: u8 = 130;

fn main() -> ExitCode {
    heap::retain_freed_memory();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Check { scene } => Scene::load(&scene)
            .map(|s| {
                let what = match s.file().scene.model.as_deref().unwrap_or("continuum") {
                    "continuum" => format!("grid {}", s.file().grid.kind.as_str()),
                    model => format!("model {model}"),
                };
                println!(
                    "{}: ok ({}D, {what})",
                    s.path().display(),
                    s.file().scene.dim
                );
                ExitCode::SUCCESS
            })
            .map_err(|e| e.to_string()),
        Command::Run { scene, out } => run(&scene, out),
    };
    result.unwrap_or_else(|msg| {
        eprintln!("error: {msg}");
        ExitCode::from(1)
    })
}

fn run(path: &Path, out: Option<PathBuf>) -> Result<ExitCode, String> {
    let scene = Scene::load(path).map_err(|e| e.to_string())?;
    let out = out.unwrap_or_else(|| scene.default_out());
    // Ctrl-C: finish the current step, keep what was written, exit with 130.
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let mut progress = Progress::new(stop);
    let summary = scene.run(&out, &mut progress).map_err(|e| e.to_string())?;
    progress.finish();
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
