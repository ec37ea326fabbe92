//! The OPC UA server beside a CNC: `cnc opcua` runs the `cnc-opcua` binary built beside
//! `cnc` (the OPC UA stack stays out of this package's build), and `cnc run`/`cnc demo
//! --opcua [PORT]` start it on their own instance once the segment is up and stop it after the
//! last tick (SIGTERM, killed after 5 s). They hold its stdin, so it ends with them even when
//! they are killed.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// How long the server may take to say it serves (a watchdog: it normally takes well under a
/// second, a first start that makes its certificate a few).
const START_WATCHDOG: Duration = Duration::from_secs(60);

/// `--opcua [PORT]` and `--opcua-config FILE` of `cnc run` and `cnc demo`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct OpcuaArgs {
    /// Serve the image over OPC UA while the run goes, on PORT (default 4840): the
    /// `cnc-opcua` binary beside `cnc`, attached to this run's instance (docs/opcua.md).
    #[arg(long, num_args = 0..=1, default_missing_value = "4840", value_name = "PORT")]
    pub opcua: Option<u16>,
    /// The OPC UA server's configuration (users, writable leaves, certificates, limits).
    #[arg(long, requires = "opcua", value_name = "FILE")]
    pub opcua_config: Option<PathBuf>,
}

/// The `cnc-opcua` binary beside the running one.
fn binary() -> Result<PathBuf, String> {
    std::env::current_exe()
        .ok()
        .and_then(|me| me.parent().map(|dir| dir.join("cnc-opcua")))
        .filter(|path| path.is_file())
        .ok_or_else(|| {
            "no cnc-opcua binary beside cnc (build it: cargo build --release -p cnc-opcua)".into()
        })
}

/// `cnc opcua`: replaced by the binary with the same arguments (so its exit code is this
/// one's).
pub fn main(instance: &str, port: u16, pki: Option<&Path>, config: Option<&Path>) -> ExitCode {
    let binary = match binary() {
        Ok(b) => b,
        Err(e) => {
            eprintln!("cnc opcua: {e}");
            return ExitCode::from(2);
        }
    };
    let mut command = Command::new(binary);
    command.args(["--instance", instance, "--port", &port.to_string()]);
    if let Some(pki) = pki {
        command.arg("--pki").arg(pki);
    }
    if let Some(config) = config {
        command.arg("--config").arg(config);
    }
    // This process becomes the server: a signal to it reaches the server, none is left
    // behind.
    let e = std::os::unix::process::CommandExt::exec(&mut command);
    eprintln!(
        "cnc opcua: {}: {e}",
        command.get_program().to_string_lossy()
    );
    ExitCode::from(1)
}

/// A server started beside a run.
pub struct Beside {
    child: Child,
    /// The server's stdin: it ends when this closes, so also when this process is killed.
    _lifeline: std::process::ChildStdin,
    forward: Option<std::thread::JoinHandle<()>>,
}

impl Beside {
    /// Starts the server on `instance` when `args` ask for one; returns once it serves, or
    /// why it did not (it said so and ended: a port in use, a bad configuration).
    pub fn start(instance: &str, args: &OpcuaArgs) -> Result<Option<Beside>, String> {
        let Some(port) = args.opcua else {
            return Ok(None);
        };
        let mut command = Command::new(binary()?);
        command.args(["--instance", instance, "--port", &port.to_string()]);
        command.arg("--end-with-stdin");
        if let Some(config) = &args.opcua_config {
            command.arg("--config").arg(config);
        }
        let mut child = command
            .stdin(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("cnc-opcua: {e}"))?;
        let stderr = child.stderr.take().ok_or("cnc-opcua: no stderr")?;
        let lifeline = child.stdin.take().ok_or("cnc-opcua: no stdin")?;
        let (serving, seen) = mpsc::channel();
        // Its lines go on to our stderr; the first that says it serves is reported.
        let forward = std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                // A closed stderr of ours must not end the forwarding.
                cnc_os::stdio::line_err(&line);
                if line.contains("serving on") {
                    let _ = serving.send(());
                }
            }
        });
        match seen.recv_timeout(START_WATCHDOG) {
            Ok(()) => Ok(Some(Beside {
                child,
                _lifeline: lifeline,
                forward: Some(forward),
            })),
            Err(_) => {
                let _ = child.kill();
                let status = child.wait().map_err(|e| e.to_string())?;
                let _ = forward.join();
                Err(format!("the OPC UA server did not start ({status})"))
            }
        }
    }
}

/// How long the server may take to end after SIGTERM before it is killed.
const STOP_WATCHDOG: Duration = Duration::from_secs(5);

/// Dropped (after the last tick, or when the run fails before it): the server is stopped
/// with SIGTERM, killed if it has not ended within [`STOP_WATCHDOG`] (or at once when the
/// signal could not be sent), and waited for.
impl Drop for Beside {
    fn drop(&mut self) {
        let ended = match cnc_os::terminate(&self.child) {
            Ok(()) => self.wait_until(std::time::Instant::now() + STOP_WATCHDOG),
            Err(e) => Err(format!("SIGTERM not sent ({e})")),
        };
        let status = match ended {
            Ok(status) => Some(status),
            Err(why) => {
                cnc_os::stdio::line_err(&format!("cnc-opcua: {why}: killed"));
                let _ = self.child.kill();
                self.child.wait().ok()
            }
        };
        if let Some(status) = status.filter(|s| !s.success()) {
            cnc_os::stdio::line_err(&format!("cnc-opcua ended: {status}"));
        }
        if let Some(forward) = self.forward.take() {
            let _ = forward.join();
        }
    }
}

impl Beside {
    /// The server's exit status once it ended; why not, if it still runs at `deadline`.
    fn wait_until(&mut self, deadline: std::time::Instant) -> Result<ExitStatus, String> {
        loop {
            match self.child.try_wait() {
                Ok(Some(status)) => return Ok(status),
                Ok(None) if std::time::Instant::now() < deadline => {
                    // A poll bounded by the deadline (std has no wait with a timeout).
                    std::thread::sleep(Duration::from_millis(10));
                }
                Ok(None) => return Err(format!("not ended {STOP_WATCHDOG:?} after SIGTERM")),
                Err(e) => return Err(format!("not waited for ({e})")),
            }
        }
    }
}
