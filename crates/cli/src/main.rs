//! The `porofrac` command: runs a scene file and writes ParaView files, CSV and plots.
//!
//! Exit status: 0 on success, 1 for an error in the scene or the run (one line naming the
//! file, line and key), 2 for command-line misuse.

use porofrac_cli::check;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

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

fn main() -> ExitCode {
    porofrac_sim::heap::retain_freed_memory();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Check { scene } => check::load(&scene)
            .and_then(|ls| {
                check::check(&ls)?;
                Ok(ls)
            })
            .map(|ls| {
                println!(
                    "{}: ok ({}D, grid {})",
                    ls.path.display(),
                    ls.scene.scene.dim,
                    ls.scene.grid.kind
                );
            })
            .map_err(|e| e.to_string()),
        Command::Run { scene, out } => run(&scene, out),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("error: {msg}");
            ExitCode::from(1)
        }
    }
}

fn run(scene: &std::path::Path, out: Option<PathBuf>) -> Result<(), String> {
    let ls = check::load(scene).map_err(|e| e.to_string())?;
    check::check(&ls).map_err(|e| e.to_string())?;
    let out = out.unwrap_or_else(|| porofrac_cli::run::default_out(&ls));
    // Ctrl-C: finish the current step, keep what was written.
    let _ = ctrlc::set_handler(|| {
        porofrac_cli::run::STOP.store(true, std::sync::atomic::Ordering::Relaxed)
    });
    let start = std::time::Instant::now();
    match porofrac_cli::run::run(&ls, &out) {
        Ok(summary) => {
            eprintln!(
                "{}: {} cells, {} dofs, {} steps in {:.2} s; output in {}",
                summary.scene,
                summary.cells,
                summary.dofs,
                summary.steps,
                summary.wall_seconds.total,
                out.display()
            );
            Ok(())
        }
        Err(e) => {
            let msg = e.to_string();
            porofrac_cli::run::write_failed_summary(&ls, &out, &msg, start);
            Err(msg)
        }
    }
}
