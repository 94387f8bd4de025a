//! The oracle of the mutation harness: run the `porofrac` binary on one input under an
//! address-space limit and a wall-time bound, and judge what it did.
//!
//! Acceptable outcomes: exit status 1 with a message that names the input file, or exit
//! status 0 (`check` printing `ok`; `run` writing only finite numbers to `probes.csv`
//! and `summary.json`). Everything else — a panic, a signal, an abort, another exit
//! status, a bound exceeded — is a failure.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Address-space limit of every child, in kB (`ulimit -v`): 4 GB.
pub const ADDRESS_SPACE_KB: u64 = 4_000_000;

/// Wall-time bound of a `check`.
pub const CHECK_TIMEOUT: Duration = Duration::from_secs(10);

/// Wall-time bound of a `run` of a mutant of a fast scene (unmutated runs take well
/// under a second on this machine).
pub const RUN_TIMEOUT: Duration = Duration::from_secs(8);

/// How long an interrupted run may take to stop after Ctrl-C.
pub const STOP_GRACE: Duration = Duration::from_secs(4);

/// How a child ended.
#[derive(Debug)]
pub enum End {
    /// It exited with this status.
    Exit(i32),
    /// It was ended by this signal.
    Signal(i32),
    /// It ran past the bound; `Some(status)` when it then stopped on Ctrl-C (SIGINT)
    /// within [`STOP_GRACE`], `None` when it had to be killed.
    Timeout(Option<i32>),
}

/// What one invocation did.
pub struct Outcome {
    /// How it ended.
    pub end: End,
    /// Its standard output.
    pub stdout: String,
    /// Its standard error.
    pub stderr: String,
    /// Wall time.
    pub seconds: f64,
}

/// The shell command that runs `args` under the address-space limit (to reproduce).
pub fn command_line(args: &[&str]) -> String {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    format!(
        "sh -c 'ulimit -v {ADDRESS_SPACE_KB}; exec \"$0\" \"$@\"' '{}' {}",
        env!("CARGO_BIN_EXE_porofrac"),
        quoted.join(" ")
    )
}

#[cfg(unix)]
fn signal_of(status: &std::process::ExitStatus) -> Option<i32> {
    use std::os::unix::process::ExitStatusExt;
    status.signal()
}

#[cfg(not(unix))]
fn signal_of(_: &std::process::ExitStatus) -> Option<i32> {
    None
}

/// Run the binary with `args` in `dir` (stdout and stderr to files there), under the
/// address-space limit, for at most `timeout`; on timeout send SIGINT, and SIGKILL if it
/// has not stopped after [`STOP_GRACE`].
pub fn invoke(dir: &Path, tag: &str, args: &[&str], timeout: Duration) -> Outcome {
    let out_path = dir.join(format!("{tag}.stdout"));
    let err_path = dir.join(format!("{tag}.stderr"));
    let start = Instant::now();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {ADDRESS_SPACE_KB}; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_porofrac"))
        .args(args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).expect("stdout file"))
        .stderr(std::fs::File::create(&err_path).expect("stderr file"))
        .spawn()
        .expect("spawn sh");
    let wait_until = |child: &mut std::process::Child, bound: Duration| loop {
        if let Some(status) = child.try_wait().expect("wait") {
            return Some(status);
        }
        if start.elapsed() > bound {
            return None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let end = match wait_until(&mut child, timeout) {
        Some(status) => match (status.code(), signal_of(&status)) {
            (Some(c), _) => End::Exit(c),
            (None, Some(s)) => End::Signal(s),
            (None, None) => End::Signal(-1),
        },
        None => {
            // `exec` replaced the shell, so the child's pid is the binary's.
            let _ = Command::new("kill")
                .args(["-INT", &child.id().to_string()])
                .status();
            match wait_until(&mut child, timeout + STOP_GRACE) {
                Some(status) => End::Timeout(Some(status.code().unwrap_or(-1))),
                None => {
                    let _ = child.kill();
                    let _ = child.wait();
                    End::Timeout(None)
                }
            }
        }
    };
    let read = |p: &Path| {
        std::fs::read(p)
            .map(|b| String::from_utf8_lossy(&b).into_owned())
            .unwrap_or_default()
    };
    Outcome {
        end,
        stdout: read(&out_path),
        stderr: read(&err_path),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// The non-finite values written by a successful run to `out` (`probes.csv`,
/// `summary.json`), or what is wrong with those files; empty when all is finite.
pub fn non_finite_outputs(out: &Path) -> Vec<String> {
    let mut found = Vec::new();
    let probes = out.join("probes.csv");
    if let Ok(text) = std::fs::read_to_string(&probes) {
        for (n, line) in text.lines().enumerate().skip(1) {
            for (c, field) in line.split(',').enumerate() {
                let f = field.trim();
                let bad = match f.parse::<f64>() {
                    Ok(v) => !v.is_finite(),
                    Err(_) => !f.is_empty(),
                };
                if bad {
                    found.push(format!("probes.csv line {} column {}: {f:?}", n + 1, c + 1));
                }
            }
        }
    }
    match std::fs::read_to_string(out.join("summary.json")) {
        Err(e) => found.push(format!("summary.json not readable: {e}")),
        Ok(text) => match serde_json::from_str::<serde_json::Value>(&text) {
            Err(e) => found.push(format!("summary.json is not JSON ({e})")),
            Ok(v) => walk(&v, "", 0, &mut found),
        },
    }
    found.truncate(5);
    found
}

/// Measures that are `null` by definition when undefined (docs/models/nscd.md): the
/// fault-propagation measures when no disk of the window moved or no band holds points.
const UNDEFINED_BY_DEFINITION: [&str; 12] = [
    ".fault.limit_angle_deg",
    ".fault.limit_angle_points",
    ".fault.limits.left_deg",
    ".fault.limits.right_deg",
    ".fault.limits.opening_deg",
    ".fault.run_out",
    ".fault.trishear",
    ".fault.trishear.layer",
    ".fault.area.axis_deg",
    ".fault.area.left_deg",
    ".fault.area.right_deg",
    ".fault.area.opening_deg",
];

/// Non-finite values of a summary: strings that spell one and `null` below the top
/// level (serde writes NaN and ±inf as `null`; top-level `null` marks an absent section,
/// and the measures of [`UNDEFINED_BY_DEFINITION`] are `null` when undefined).
fn walk(v: &serde_json::Value, at: &str, depth: usize, found: &mut Vec<String>) {
    use serde_json::Value;
    match v {
        Value::Null if depth > 1 && !UNDEFINED_BY_DEFINITION.contains(&at) => {
            found.push(format!("summary.json {at} = null"))
        }
        Value::String(s) => {
            let l = s.trim().to_ascii_lowercase();
            let l = l.trim_start_matches(['+', '-']);
            if ["nan", "inf", "infinity"].contains(&l) {
                found.push(format!("summary.json {at} = {s:?}"));
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                walk(x, &format!("{at}[{i}]"), depth + 1, found);
            }
        }
        Value::Object(o) => {
            for (k, x) in o {
                walk(x, &format!("{at}.{k}"), depth + 1, found);
            }
        }
        _ => {}
    }
}
