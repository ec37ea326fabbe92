//! A channel's program folder: the PLC selects programs by file name (`SELECT` of the channel
//! control unit), and the machine loads and checks them here, between ticks, never in one.
//! A name is a plain file name (no path, no leading dot), a file is read up to a bound.

use super::program::LoadedProgram;
use crate::nc::decode::{DecoderSetup, DecoderState, ZeroVars};
use crate::nc::interp::{Interpreter, SearchPath, Step};
use crate::nc::Decoded;
use hli::enums::ChannelCommandError;
use hli::layout::PROGRAM_NAME_LEN;
use std::io::Read;
use std::path::PathBuf;

/// The largest program file a channel reads (bytes).
pub const MAX_PROGRAM_BYTES: u64 = 16 << 20;

/// Where a channel finds the programs the PLC selects, and what they are checked with.
#[derive(Debug, Clone)]
pub struct ProgramFolder {
    /// The folder.
    pub dir: PathBuf,
    /// The channel's machine data.
    pub setup: DecoderSetup,
    /// Where `L name` looks after the program's own folder.
    pub search: SearchPath,
}

/// A program name as the PLC wrote it: fixed room, no allocation in the tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProgramName {
    bytes: [u8; PROGRAM_NAME_LEN],
}

impl ProgramName {
    /// The name in `bytes` (NUL-padded), checked: a plain file name of `A-Z a-z 0-9 _ - .`,
    /// not starting with a dot, at most 63 bytes.
    pub fn parse(bytes: &[u8; PROGRAM_NAME_LEN]) -> Result<ProgramName, ChannelCommandError> {
        let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
        let name = &bytes[..end];
        let plain = |b: &u8| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.');
        let padded = bytes[end..].iter().all(|&b| b == 0);
        if name.is_empty() || end == bytes.len() || name[0] == b'.' || !padded {
            return Err(ChannelCommandError::BadName);
        }
        if !name.iter().all(plain) {
            return Err(ChannelCommandError::BadName);
        }
        Ok(ProgramName { bytes: *bytes })
    }

    /// The name as text.
    pub fn as_str(&self) -> &str {
        hli::layout::nul_padded_str(&self.bytes).unwrap_or("")
    }

    /// The bytes as the unit carries them.
    pub fn bytes(&self) -> &[u8; PROGRAM_NAME_LEN] {
        &self.bytes
    }
}

/// Why a program could not be selected: the code the PLC reads and the text beside it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SelectRefusal {
    /// The code.
    pub code: ChannelCommandError,
    /// The text (a check's first diagnostic, FILE:LINE:COL).
    pub message: String,
}

impl ProgramFolder {
    /// Reads and checks program `name` for a channel with `axes`.
    pub fn load(
        &self,
        name: &ProgramName,
        axes: &[String],
    ) -> Result<LoadedProgram, SelectRefusal> {
        let path = self.dir.join(name.as_str());
        let refuse = |code, message: String| SelectRefusal { code, message };
        let not_found = |e: &dyn std::fmt::Display| {
            refuse(
                ChannelCommandError::ProgramNotFound,
                format!("{}: {e}", path.display()),
            )
        };
        // Only a regular file: opening a FIFO or a device could block or never end.
        let meta = std::fs::metadata(&path).map_err(|e| not_found(&e))?;
        if !meta.is_file() {
            return Err(not_found(&"not a regular file"));
        }
        let file = std::fs::File::open(&path).map_err(|e| not_found(&e))?;
        let mut src = String::new();
        let read = file.take(MAX_PROGRAM_BYTES + 1).read_to_string(&mut src);
        let invalid = ChannelCommandError::ProgramInvalid;
        match read {
            Err(e) => return Err(refuse(invalid, format!("{}: {e}", path.display()))),
            Ok(n) if n as u64 > MAX_PROGRAM_BYTES => {
                return Err(refuse(
                    invalid,
                    format!("{}: larger than {MAX_PROGRAM_BYTES} bytes", path.display()),
                ))
            }
            Ok(_) => {}
        }
        LoadedProgram::load_with(
            &path.display().to_string(),
            &src,
            axes,
            &self.setup,
            Some(self.dir.clone()),
            &self.search,
        )
        .map_err(|e| {
            let first = e.diagnostics.first().map(|d| d.render(&e.name));
            refuse(invalid, first.unwrap_or_else(|| e.to_string()))
        })
    }
}

/// The most interpreter steps a block search takes before it gives up (a loop before the
/// start line that does not end without machine values).
pub const MAX_SEARCH_STEPS: usize = 1_000_000;

/// Where a program selected with a start line begins: the decoder's modal state and the
/// interpreter's position there, as the blocks before it left them (a block search that
/// runs no motion).
#[derive(Debug, Clone)]
pub struct StartPoint {
    /// Modal state (G90/G91, G17.., feed, zero offset, ...) at the start line.
    pub decoder: DecoderState,
    /// The interpreter at the start line (its variables and loops as the flow left them).
    pub interp: Interpreter,
}

/// A block search: follows `program`'s flow from its beginning to the first block of the main
/// program on source line `line`, decoding every block on the way without running it. Refused
/// when the line is not reached, when the flow there depends on machine values, or when a
/// block on the way does what a search cannot carry (a transformation, a coordinate system,
/// tracking, synchronisation, an M function, an independent move, a tool): the channel would
/// not be where the program expects it.
pub fn search_start(
    program: &LoadedProgram,
    axes: &[String],
    line: u32,
) -> Result<StartPoint, SelectRefusal> {
    let refuse = |code, message: String| SelectRefusal { code, message };
    let name = &program.name;
    let set = &program.set;
    let mut decoder = DecoderState::new(axes);
    decoder.configure(&program.setup);
    let mut interp = Interpreter::new();
    interp.start(set);
    let mut out = Vec::new();
    let main = &set.main().tree;
    for _ in 0..MAX_SEARCH_STEPS {
        if let (0, Some((0, b))) = (interp.depth(), interp.position()) {
            if main
                .blocks
                .get(b as usize)
                .is_some_and(|blk| blk.line == line)
            {
                return Ok(StartPoint { decoder, interp });
            }
        }
        let at = interp.position();
        out.clear();
        let step = interp.step(set, &mut decoder, &ZeroVars, &mut out);
        let here = at
            .and_then(|(u, b)| set.units.get(u as usize)?.tree.blocks.get(b as usize))
            .map_or(0, |b| b.line);
        match step {
            Ok(Step::End) => break,
            Ok(Step::Undecided) => {
                return Err(refuse(
                    ChannelCommandError::StartLineNotFound,
                    format!("{name}:{here}: the flow before line {line} depends on machine values: no block search"),
                ))
            }
            Ok(_) => {}
            Err(e) => {
                return Err(refuse(
                    ChannelCommandError::ProgramInvalid,
                    format!("{name}:{here}: block search: {}", e.fault),
                ))
            }
        }
        if let Some(what) = out.iter().find_map(not_searchable) {
            return Err(refuse(
                ChannelCommandError::StartLineNotFound,
                format!("{name}:{here}: {what} before line {line}: a block search does not carry it; start earlier"),
            ));
        }
    }
    Err(refuse(
        ChannelCommandError::StartLineNotFound,
        format!("{name}: no block of the main program at line {line} is reached"),
    ))
}

/// What a block search cannot skip over, by name; `None` for what it can (motion, dwell,
/// flush, messages).
fn not_searchable(element: &Decoded) -> Option<&'static str> {
    Some(match element {
        Decoded::Motion(_)
        | Decoded::Dwell { .. }
        | Decoded::Flush { .. }
        | Decoded::Message { .. }
        | Decoded::WaitIndependent { .. } => return None,
        Decoded::MFunction { .. } => "an M function",
        Decoded::IndependentMove { .. } => "an independent axis move",
        Decoded::Track { .. } | Decoded::TrackAbs { .. } => "#TRACK CS",
        Decoded::ChannelInterface { .. } => "#CHANNEL INTERFACE",
        Decoded::Cs { .. } => "#CS",
        Decoded::Trafo { .. } => "#TRAFO",
        Decoded::SignalSyn { .. } | Decoded::WaitSyn { .. } => "synchronisation",
        Decoded::Spindle { .. } => "a spindle command",
        Decoded::Tool { .. } | Decoded::ToolRecord { .. } => "a tool selection",
    })
}

/// Loads selected programs on a thread of its own, so that a real-time loop never waits for
/// a file: jobs go in between ticks, results are collected between later ticks.
#[derive(Debug)]
pub struct Loader {
    jobs: std::sync::mpsc::SyncSender<Job>,
    done: std::sync::mpsc::Receiver<Loaded>,
}

/// A program to load for a channel.
#[derive(Debug)]
pub struct Job {
    /// The channel.
    pub channel: usize,
    /// Its folder.
    pub folder: ProgramFolder,
    /// Its axes.
    pub axes: Vec<String>,
    /// The program.
    pub name: ProgramName,
    /// Its start line (0: the beginning).
    pub start_line: u32,
}

/// A program loaded (or refused) for a channel.
#[derive(Debug)]
pub struct Loaded {
    /// The channel.
    pub channel: usize,
    /// The program.
    pub name: ProgramName,
    /// Its start line.
    pub start_line: u32,
    /// The program and where it starts, or why not.
    pub result: Result<(LoadedProgram, Option<StartPoint>), SelectRefusal>,
}

impl Job {
    /// Loads, checks and searches the start line (what the loader thread does).
    pub fn run(self) -> Loaded {
        let result = self.folder.load(&self.name, &self.axes).and_then(|p| {
            let start = match self.start_line {
                0 => None,
                line => Some(search_start(&p, &self.axes, line)?),
            };
            Ok((p, start))
        });
        Loaded {
            channel: self.channel,
            name: self.name,
            start_line: self.start_line,
            result,
        }
    }
}

impl Loader {
    /// Starts the thread (`Err`: the system refused one).
    pub fn spawn() -> std::io::Result<Loader> {
        let (jobs, inbox) = std::sync::mpsc::sync_channel::<Job>(16);
        let (outbox, done) = std::sync::mpsc::channel();
        std::thread::Builder::new()
            .name("program-loader".into())
            .spawn(move || {
                for job in inbox {
                    if outbox.send(job.run()).is_err() {
                        break;
                    }
                }
            })?;
        Ok(Loader { jobs, done })
    }

    /// Hands a job to the thread; `false` when its queue is full or it ended (the caller
    /// tries again later).
    pub fn send(&self, job: Job) -> bool {
        self.jobs.try_send(job).is_ok()
    }

    /// A result, if one is ready.
    pub fn try_take(&self) -> Option<Loaded> {
        self.done.try_recv().ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(text: &str) -> [u8; PROGRAM_NAME_LEN] {
        hli::layout::nul_padded(text)
    }

    #[test]
    fn names_are_plain_file_names() {
        assert_eq!(
            ProgramName::parse(&name("part_1.nc")).unwrap().as_str(),
            "part_1.nc"
        );
        for bad in ["", "../etc/passwd", "a/b.nc", ".hidden", "a b", "ü.nc"] {
            assert_eq!(
                ProgramName::parse(&name(bad)),
                Err(ChannelCommandError::BadName),
                "{bad:?}"
            );
        }
        let mut garbage = name("a.nc");
        garbage[10] = b'x';
        assert_eq!(
            ProgramName::parse(&garbage),
            Err(ChannelCommandError::BadName)
        );
        assert_eq!(
            ProgramName::parse(&[b'a'; PROGRAM_NAME_LEN]),
            Err(ChannelCommandError::BadName)
        );
    }
}
