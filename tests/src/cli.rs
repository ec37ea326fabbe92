//! Running programs (`cnc`, `plc`, `hli-peer`, tools) from a test: [`Cli`] is a
//! `Command` whose `output`, `status` and `spawn` come with a watchdog (a hung program is
//! killed and the test fails with what it printed, it never hangs the test run), and
//! [`Scratch`] a folder of the test's own that is removed afterwards.
//!
//! ```no_run
//! // A test of the `cnc-app` package names the binary with `env!("CARGO_BIN_EXE_cnc")`.
//! let cnc = "target/debug/cnc";
//! let out = tests::Cli::new(cnc)
//!     .args(["hli", "symbols"])
//!     .output()
//!     .unwrap();
//! assert!(out.status.success());
//! ```

use crate::child::ChildGuard;
use std::ffi::OsStr;
use std::io::{self, BufRead, BufReader};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Output, Stdio};
use std::time::Duration;

/// How long a program may run before its watchdog kills it: long enough for a debug build on
/// a loaded 2-core machine; `TEST_WATCHDOG_S` overrides it.
pub fn default_watchdog() -> Duration {
    let secs = std::env::var("TEST_WATCHDOG_S")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(600);
    Duration::from_secs(secs)
}

/// A program to run, with a watchdog.
#[derive(Debug)]
pub struct Cli {
    command: Command,
    watchdog: Duration,
}

impl Cli {
    /// `program` (a test's `env!("CARGO_BIN_EXE_cnc")`, say) with no arguments yet.
    pub fn new(program: impl AsRef<OsStr>) -> Self {
        let mut command = Command::new(program);
        // A group of its own: the watchdog kills the program with everything it started.
        command.process_group(0);
        Cli {
            command,
            watchdog: default_watchdog(),
        }
    }

    /// One more argument.
    pub fn arg(mut self, arg: impl AsRef<OsStr>) -> Self {
        self.command.arg(arg);
        self
    }

    /// More arguments.
    pub fn args<I: IntoIterator<Item = S>, S: AsRef<OsStr>>(mut self, args: I) -> Self {
        self.command.args(args);
        self
    }

    /// An environment variable of the program.
    pub fn env(mut self, key: impl AsRef<OsStr>, value: impl AsRef<OsStr>) -> Self {
        self.command.env(key, value);
        self
    }

    /// The program's working folder.
    pub fn current_dir(mut self, dir: impl AsRef<Path>) -> Self {
        self.command.current_dir(dir);
        self
    }

    /// The program's stdin ([`Cli::spawn`]; `output` and `status` give it none).
    pub fn stdin(mut self, cfg: Stdio) -> Self {
        self.command.stdin(cfg);
        self
    }

    /// The program's stdout ([`Cli::spawn`]).
    pub fn stdout(mut self, cfg: Stdio) -> Self {
        self.command.stdout(cfg);
        self
    }

    /// The program's stderr ([`Cli::spawn`]).
    pub fn stderr(mut self, cfg: Stdio) -> Self {
        self.command.stderr(cfg);
        self
    }

    /// Another watchdog than [`default_watchdog`].
    pub fn watchdog(mut self, limit: Duration) -> Self {
        self.watchdog = limit;
        self
    }

    /// Runs the program to its end with stdout and stderr captured. `Err` if it could not
    /// start, or if the watchdog killed it (the error carries what it printed).
    pub fn output(mut self) -> io::Result<Output> {
        let child = self
            .command
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()?;
        ChildGuard(child)
            .wait_with_output(self.watchdog)
            .map_err(|e| io::Error::new(e.kind(), format!("{:?}: {e}", self.command)))
    }

    /// Runs the program to its end with its output inherited; `Err` as [`Cli::output`].
    pub fn status(mut self) -> io::Result<ExitStatus> {
        let mut guard = ChildGuard(self.command.stdin(Stdio::null()).spawn()?);
        guard.wait_with_watchdog(self.watchdog).ok_or_else(|| {
            let text = format!(
                "watchdog: {:?} killed after {:?}",
                self.command, self.watchdog
            );
            io::Error::new(io::ErrorKind::TimedOut, text)
        })
    }

    /// Runs the program as `| head -1` would: its stdout is closed after the first line.
    /// Returns that line and the end of the run (status, stderr) as [`Cli::output`] does.
    pub fn first_line(self) -> io::Result<(String, Output)> {
        let watchdog = self.watchdog;
        let mut child = self.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn()?;
        let stdout = child.0.stdout.take().expect("piped stdout");
        let (tx, rx) = std::sync::mpsc::channel();
        // The line is read on a thread, so that the watchdog also covers a silent program.
        std::thread::spawn(move || {
            let mut line = String::new();
            let read = BufReader::new(stdout).read_line(&mut line).map(|_| line);
            let _ = tx.send(read);
        });
        let line = match rx.recv_timeout(watchdog) {
            Ok(read) => read?,
            Err(_) => {
                child.kill_group();
                let text = format!("watchdog: no first line within {watchdog:?}");
                return Err(io::Error::new(io::ErrorKind::TimedOut, text));
            }
        };
        Ok((line, child.wait_with_output(watchdog)?))
    }

    /// Starts the program; the guard kills it when dropped unless it has ended (wait for it
    /// with [`ChildGuard::wait_with_watchdog`] or [`ChildGuard::wait_with_output`]).
    pub fn spawn(mut self) -> io::Result<ChildGuard> {
        Ok(ChildGuard(self.command.spawn()?))
    }
}

/// A folder of the test's own under the temporary folder, removed when dropped.
#[derive(Debug)]
pub struct Scratch(PathBuf);

impl Scratch {
    /// A fresh, empty folder named after `test` and unique in this test run.
    pub fn new(test: &str) -> Self {
        let dir = std::env::temp_dir().join(crate::unique_instance(test));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create the scratch folder");
        Scratch(dir)
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// A path in the folder.
    pub fn join(&self, name: impl AsRef<Path>) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The repository's root folder (where `scenarios/` and `docs/` are).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the tests package sits in the repository root")
        .to_path_buf()
}

/// `scenarios/NAME/scenario.toml` of the repository.
pub fn scenario(name: &str) -> PathBuf {
    repo_root()
        .join("scenarios")
        .join(name)
        .join("scenario.toml")
}

/// Runs `program` with `args` to its end (watchdog, captured output): its exit code (-1 when
/// a signal ended it), stdout and stderr as text. Panics if it could not start or hung.
pub fn code_and_text(program: impl AsRef<OsStr>, args: &[&str]) -> (i32, String, String) {
    let out = Cli::new(program)
        .args(args)
        .output()
        .expect("run the program");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// What a run printed: its stdout, then its stderr.
pub fn report(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr)
}

/// `cnc run ARGS --instance INSTANCE --trace TRACE` to its end, `cnc` being the calling test's
/// `env!("CARGO_BIN_EXE_cnc")`; asserts that it succeeded, with its [`report`] if not.
pub fn cnc_run(cnc: &str, args: &[&str], instance: &str, trace: &Path) -> Output {
    let out = Cli::new(cnc)
        .arg("run")
        .args(args)
        .args(["--instance", instance, "--trace"])
        .arg(trace)
        .output()
        .expect("run cnc");
    assert!(out.status.success(), "cnc run {args:?}: {}", report(&out));
    out
}

/// `cnc run SCENARIO --lockstep` ([`cnc_run`]) under an instance of its own, its trace written
/// to a scratch folder (removed again): the [`report`] and the trace's bytes.
pub fn cnc_run_lockstep(cnc: &str, scenario: &Path, tag: &str) -> (String, Vec<u8>) {
    let scratch = Scratch::new(tag);
    let trace = scratch.join("trace.csv");
    let out = cnc_run(
        cnc,
        &[scenario.to_str().expect("a UTF-8 path"), "--lockstep"],
        &crate::unique_instance(tag),
        &trace,
    );
    (report(&out), std::fs::read(&trace).expect("read the trace"))
}

/// Polls `check` until it holds: a watchdog of 30 s fails the test that waits for `what` (a
/// live process's state seen from outside; the wait is a poll, never a timing).
pub fn wait_until(what: &str, mut check: impl FnMut() -> bool) {
    let deadline = std::time::Instant::now() + Duration::from_secs(30);
    while !check() {
        assert!(std::time::Instant::now() < deadline, "watchdog: {what}");
        std::thread::sleep(Duration::from_millis(5));
    }
}
