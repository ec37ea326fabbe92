//! `cnc diag dyncs --channel N`: the dynamic-CS diagnosis (per-tick history and switching
//! log, in the controller's listing layout) of a channel of a running or a finished CNC.
//!
//! * **Running** (the instance's segment exists): the history and the log are read entry by
//!   entry over the acyclic channel ([`hli::calls::diag`], a few calls in flight at a time; the
//!   CNC answers between ticks from its rings) up to the entries recorded when the read
//!   began, and rendered here.
//! * **Finished**: `cnc demo` and `cnc run --keep-diagnosis` leave every channel's listing in
//!   [`finished_dir`] when they end; the tool prints the one of the channel.
//!
//! Exit codes: 0 printed, 1 no such CNC (neither running nor finished) or the read failed,
//! 2 bad input (a channel the CNC does not have).

use crate::scenario::runner::ChannelReport;
use cnc_core::channel::diag_wire::{history_entry, log_event, WireError};
use cnc_core::channel::diagnosis::render_entries;
use cnc_core::channel::dyn_cs::{HistoryEntry, TrackEvent};
use hli::calls::diag::{DiagWindow, DynCsHistoryReadCall, DynCsLogReadCall};
use hli::calls::{AcyclicCall, CallError};
use hli_transport::rpc::{AcyclicClient, PendingCall};
use hli_transport::segment::{AttachError, PlcSegment};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// `cnc diag` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum DiagCommand {
    /// The dynamic-CS history and switching log of a channel of a running or finished CNC.
    Dyncs(DyncsArgs),
}

/// Arguments of `cnc diag dyncs`.
#[derive(Debug, clap::Args)]
pub struct DyncsArgs {
    /// Channel number, from 1 (as the listing's CHANNEL-NR.).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=hli::layout::HLI_MAX_CHANNELS as i64))]
    pub channel: u32,
    /// Instance of the CNC (`cnc run --instance`; the demo's by default).
    #[arg(long, default_value = plc_shim::tools::DEFAULT_INSTANCE)]
    pub instance: String,
}

/// Why the diagnosis could not be printed.
#[derive(Debug, thiserror::Error)]
pub enum DiagError {
    /// Neither a running CNC nor a finished run of this instance.
    #[error("no CNC {instance:?} is running and no finished run left a diagnosis in {dir} (`cnc demo` and `cnc run --keep-diagnosis` do)")]
    NoCnc {
        /// The instance.
        instance: String,
        /// Where a finished run would have left it.
        dir: String,
    },
    /// The CNC has fewer channels.
    #[error("channel {channel}: CNC {instance:?} has {count} channel(s)")]
    NoSuchChannel {
        /// The instance.
        instance: String,
        /// The channel asked for (1-based).
        channel: u32,
        /// Channels it has.
        count: u32,
    },
    /// The segment could not be opened.
    #[error(transparent)]
    Attach(#[from] AttachError),
    /// A call failed.
    #[error("reading the diagnosis: {0}")]
    Call(#[from] CallError),
    /// A reply did not decode.
    #[error("reading the diagnosis: {0}")]
    Wire(#[from] WireError),
    /// A reply's window is impossible (an entry past the recorded ones, a flag not 0 or 1).
    #[error("reading the diagnosis: malformed window {0:?}")]
    BadWindow(DiagWindow),
    /// The CNC's segment is there but it does not answer.
    #[error("CNC {instance:?} does not answer diagnosis calls within {limit:?} (stopped or hung)")]
    NoAnswer {
        /// The instance.
        instance: String,
        /// How long the read waited.
        limit: Duration,
    },
    /// A finished run's file could not be read.
    #[error("{file}: {message}")]
    Read {
        /// The file.
        file: String,
        /// The OS error.
        message: String,
    },
}

impl DiagError {
    fn exit_code(&self) -> u8 {
        match self {
            DiagError::NoSuchChannel { .. } => 2,
            _ => 1,
        }
    }
}

/// Where a finished run of `instance` leaves its channels' listings. The prefix keeps an
/// instance named `.` or `..` (valid segment names) inside the base folder.
pub fn finished_dir(instance: &str) -> PathBuf {
    std::env::temp_dir()
        .join("cncplc-diag")
        .join(format!("instance-{instance}"))
}

fn finished_file(instance: &str, channel: u32) -> PathBuf {
    finished_dir(instance).join(format!("dyncs-channel-{channel}.txt"))
}

/// Leaves every channel's listing of a finished run for `cnc diag dyncs` (replacing those
/// of an earlier run of the same instance); returns the folder.
pub fn keep_finished(instance: &str, channels: &[ChannelReport]) -> Result<PathBuf, String> {
    let dir = finished_dir(instance);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for (i, c) in channels.iter().enumerate() {
        let file = finished_file(instance, i as u32 + 1);
        std::fs::write(&file, &c.diagnosis).map_err(|e| format!("{}: {e}", file.display()))?;
    }
    Ok(dir)
}

/// Runs a `cnc diag` command.
pub fn main(command: DiagCommand) -> ExitCode {
    let DiagCommand::Dyncs(args) = command;
    match dyncs(&args) {
        Ok((text, origin)) => {
            println!("{origin}");
            print!("{text}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("cnc diag: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

/// The listing of `args.channel` and where it came from.
pub fn dyncs(args: &DyncsArgs) -> Result<(String, String), DiagError> {
    match PlcSegment::inspect(&args.instance) {
        Ok(segment) => {
            let count = segment.channel_count();
            if args.channel > count {
                return Err(DiagError::NoSuchChannel {
                    instance: args.instance.clone(),
                    channel: args.channel,
                    count,
                });
            }
            let index = args.channel - 1;
            let mut client = AcyclicClient::open(&args.instance)?;
            let no_answer = |e: DiagError| match e {
                DiagError::Call(CallError::Timeout(limit)) => DiagError::NoAnswer {
                    instance: args.instance.clone(),
                    limit,
                },
                e => e,
            };
            let (history, lost_h) = read_all(&mut client, index, |sequence| DynCsHistoryReadCall {
                sequence,
            })
            .map_err(no_answer)?;
            let history: Vec<HistoryEntry> = history.iter().filter_map(history_entry).collect();
            let (log, lost_l) =
                read_all(&mut client, index, |sequence| DynCsLogReadCall { sequence })
                    .map_err(no_answer)?;
            let log = log
                .iter()
                .filter_map(|r| log_event(r).transpose())
                .collect::<Result<Vec<(u64, TrackEvent)>, _>>()?;
            let text = render_entries(index as usize, history.into_iter(), log.into_iter());
            let mut origin = format!(
                "running CNC {:?}, read over the acyclic channel",
                args.instance
            );
            if lost_h + lost_l > 0 {
                origin.push_str(&format!(
                    " ({lost_h} history and {lost_l} log entries overwritten while reading)"
                ));
            }
            Ok((text, origin))
        }
        // Gone, or closed and on its way out: what the finished run left.
        Err(AttachError::NotFound { .. } | AttachError::NotReady { .. }) => {
            let file = finished_file(&args.instance, args.channel);
            match std::fs::read_to_string(&file) {
                Ok(text) => Ok((
                    text,
                    format!("finished run of {:?} ({})", args.instance, file.display()),
                )),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    if finished_dir(&args.instance).is_dir() {
                        let count = std::fs::read_dir(finished_dir(&args.instance))
                            .map_or(0, |d| d.count()) as u32;
                        return Err(DiagError::NoSuchChannel {
                            instance: args.instance.clone(),
                            channel: args.channel,
                            count,
                        });
                    }
                    Err(DiagError::NoCnc {
                        instance: args.instance.clone(),
                        dir: finished_dir(&args.instance).display().to_string(),
                    })
                }
                Err(e) => Err(DiagError::Read {
                    file: file.display().to_string(),
                    message: e.to_string(),
                }),
            }
        }
        Err(e) => Err(e.into()),
    }
}

/// Calls in flight at a time: the CNC answers every waiting call in its next tick.
const IN_FLIGHT: usize = 16;
/// How long a whole read may take.
const READ_LIMIT: Duration = Duration::from_secs(10);

/// A reply of a diagnosis read: where its entry lies.
trait Windowed {
    fn window(&self) -> DiagWindow;
}

impl Windowed for hli::calls::diag::DynCsHistoryReply {
    fn window(&self) -> DiagWindow {
        self.window
    }
}

impl Windowed for hli::calls::diag::DynCsLogReply {
    fn window(&self) -> DiagWindow {
        self.window
    }
}

/// Reads every entry kept when the read begins, oldest first; returns them and how many were
/// overwritten before their call was answered.
fn read_all<C>(
    client: &mut AcyclicClient,
    channel: u32,
    call: impl Fn(u64) -> C,
) -> Result<(Vec<C::Reply>, u64), DiagError>
where
    C: AcyclicCall,
    C::Reply: Windowed,
{
    let deadline = Instant::now() + READ_LIMIT;
    let wait = |pending: &PendingCall<C>| -> Result<C::Reply, DiagError> {
        loop {
            if let Some(result) = pending.poll() {
                return Ok(result?);
            }
            if Instant::now() > deadline {
                return Err(CallError::Timeout(READ_LIMIT).into());
            }
            std::thread::sleep(Duration::from_micros(200));
        }
    };
    // The first reply names the window: from the oldest kept to the last recorded now.
    let first = wait(&client.start(channel, &call(0))?)?;
    let window = first.window();
    let end = window.recorded;
    let plausible = window.present <= 1
        && window.sequence <= end
        && end - window.sequence <= u64::from(window.kept);
    if !plausible {
        return Err(DiagError::BadWindow(window));
    }
    let mut replies = Vec::with_capacity((end - window.sequence) as usize);
    let mut lost = 0;
    if window.present == 1 {
        replies.push(first);
    }
    let mut next = window.sequence + 1;
    let mut flight: std::collections::VecDeque<(u64, PendingCall<C>)> = Default::default();
    while next < end || !flight.is_empty() {
        while next < end && flight.len() < IN_FLIGHT {
            flight.push_back((next, client.start(channel, &call(next))?));
            next += 1;
        }
        if let Some((sequence, pending)) = flight.pop_front() {
            let reply = wait(&pending)?;
            // Overwritten since: the ring answered with a newer entry, read in its own turn.
            if reply.window().sequence == sequence && reply.window().present == 1 {
                replies.push(reply);
            } else {
                lost += 1;
            }
        }
    }
    Ok((replies, lost))
}
