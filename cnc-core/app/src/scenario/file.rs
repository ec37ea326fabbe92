//! The scenario file: a machine configuration (cycle time, channels under the controller's
//! parameter names) plus what to run on it (NC programs, a PLC timeline or built-in program)
//! and what to trace.
//!
//! ```toml
//! cycle_ms = 1.0
//! ticks = 12000                   # default run length (`--ticks` overrides)
//! [[channel]]
//! name = "master"
//! axes = ["X", "Y", "Z", "A", "B", "C"]
//! kinematics = { id = 45, preset = "kr6r900sixx" }
//! program = "master.nc"           # relative to this file
//! [[cam_table]]                  # any key an engine reads goes to that engine
//! file = "seed_example.json"      # (cnc_core::machine::engines; docs/machine.md)
//! id = 1
//! [plc]
//! timeline = "plc.toml"           # or: program = "rotary-table"; program = "fifo-stream"
//!                                 # with file = "contour.csv" (and fifo_override = 80.0)
//! [trace]
//! signals = ["gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state"]
//! ```

use cnc_core::channel::{ChannelConfig, LoadedProgram};
use cnc_core::machine::engines::{self, ConfigInput, EngineConfigs};
use hli::access::Leaf;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Why a scenario cannot run.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// A file could not be read.
    #[error("{file}: {message}")]
    Read {
        /// The file.
        file: String,
        /// The OS error.
        message: String,
    },
    /// The TOML did not parse, has unknown fields or values out of range.
    #[error("{file}: {message}")]
    Invalid {
        /// The file.
        file: String,
        /// What is wrong (with line and column where the parser knows them).
        message: String,
    },
    /// An NC program was refused (its diagnostics, FILE:LINE:COL each).
    #[error("{0}")]
    Program(#[from] cnc_core::channel::ProgramError),
}

/// What the drives do once the stop after a lost PLC reached rest, while the CNC waits for a
/// new PLC (`plc_loss_drives`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DrivesOnLoss {
    /// Powered, holding their positions (the new PLC can move them at once).
    #[default]
    Hold,
    /// Disabled (MC_Power off): the new PLC powers them with MC_Power first.
    Disable,
}

/// The scenario's own keys; every other top-level key must be one an engine reads
/// (`cnc_core::machine::engines::sections`), and goes to the engines untouched.
#[derive(Debug, Deserialize)]
struct ScenarioFile {
    #[serde(default = "default_cycle_ms")]
    cycle_ms: f64,
    ticks: Option<u64>,
    plc_watchdog_ticks: Option<u64>,
    #[serde(default)]
    plc_loss_drives: DrivesOnLoss,
    #[serde(default)]
    channel: Vec<ChannelConfig>,
    #[serde(default)]
    axis: Vec<super::axes::AxisFile>,
    plc: Option<PlcFile>,
    #[serde(default)]
    trace: TraceFile,
    #[serde(default)]
    realtime: plc_shim::realtime::RealtimeOptions,
    #[serde(default)]
    realtime_plc: plc_shim::realtime::RealtimeOptions,
}

fn default_cycle_ms() -> f64 {
    1.0
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PlcFile {
    timeline: Option<String>,
    program: Option<String>,
    /// A built-in program's data file (fifo-stream's positions), relative to the scenario.
    file: Option<String>,
    /// fifo-stream's override before the start, percent.
    fifo_override: Option<f64>,
    /// Cuts of saw-cut and demo-machine's saw.
    saw_cuts: Option<usize>,
    /// Piece length of the saw, mm.
    saw_length: Option<f64>,
    /// Structured Text files run as the PLC program (docs/plc-st.md), relative to the
    /// scenario.
    st: Option<Vec<String>>,
    /// The PLC task's period (ms): a whole number of CNC cycles (default: every cycle).
    period_ms: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct TraceFile {
    #[serde(default)]
    signals: Vec<String>,
}

/// What runs in the PLC process.
#[derive(Debug, Clone)]
pub enum PlcSetup {
    /// No PLC.
    None,
    /// A timeline: its path (as given, resolved), its text (for the PLC process) and the
    /// parsed, checked timeline (for in-process runs).
    Timeline {
        /// Where it came from.
        path: PathBuf,
        /// The TOML text.
        text: String,
        /// The parsed timeline.
        timeline: Box<plc_shim::timeline::Timeline>,
    },
    /// A built-in program of `plc-shim` by name, with its arguments (`--file PATH`...).
    Program(String, Vec<String>),
}

/// A checked scenario, every file read.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Where the scenario came from (for messages).
    pub name: String,
    /// Tick period, seconds (the file's `cycle_ms`, or what the run set:
    /// [`Scenario::set_cycle_ms`]).
    pub cycle_s: f64,
    /// The file's `cycle_ms` (s): what its `ticks` and its timeline's `at_tick` count in.
    pub file_cycle_s: f64,
    /// Default run length, in ticks of `cycle_s`.
    pub ticks: Option<u64>,
    /// The PLC task's period (`[plc] period_ms`, ms); none: every tick.
    pub plc_period_ms: Option<f64>,
    /// Ticks without a PLC cycle before the PLC counts as lost.
    pub plc_watchdog_ticks: Option<u64>,
    /// What the drives do once a stop after a lost PLC reached rest (`cnc run --plc-restart`).
    pub plc_loss_drives: DrivesOnLoss,
    /// The channels.
    pub channels: Vec<ChannelConfig>,
    /// Their programs, checked (None: the channel stays idle).
    pub programs: Vec<Option<LoadedProgram>>,
    /// Their program folders (`programs`), where the PLC's SELECT loads from.
    pub folders: Vec<Option<cnc_core::channel::folder::ProgramFolder>>,
    /// Single axes, behind the channel axes.
    pub axes: Vec<super::axes::ScenarioAxis>,
    /// The engines' configurations, each made by its engine from the keys it reads.
    pub engines: EngineConfigs,
    /// The PLC.
    pub plc: PlcSetup,
    /// Trace signals: ST path and resolved leaf.
    pub signals: Vec<(String, Leaf)>,
    /// Real-time options of the CNC's tick loop (`[realtime]`).
    pub realtime: plc_shim::realtime::RealtimeOptions,
    /// Real-time options of the spawned PLC (`[realtime_plc]`).
    pub realtime_plc: plc_shim::realtime::RealtimeOptions,
}

impl Scenario {
    /// Loads `path` and the files it names.
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        let read = |p: &Path| {
            std::fs::read_to_string(p).map_err(|e| ScenarioError::Read {
                file: p.display().to_string(),
                message: e.to_string(),
            })
        };
        let text = read(path)?;
        let mut scenario = Scenario::parse(&path.display().to_string(), &text, |relative| {
            let p = dir.join(relative);
            read(&p).map(|text| (p, text))
        })?;
        // Folders are named relative to the scenario's file.
        for folder in scenario.folders.iter_mut().flatten() {
            folder.dir = dir.join(&folder.dir);
            for d in &mut folder.search.0 {
                *d = dir.join(&*d);
            }
        }
        Ok(scenario)
    }

    /// Parses scenario `text`; `open` reads a file named in it (relative path) and returns
    /// its resolved path and text. The demo passes files embedded in the binary this way.
    pub fn parse(
        name: &str,
        text: &str,
        open: impl Fn(&str) -> Result<(PathBuf, String), ScenarioError>,
    ) -> Result<Scenario, ScenarioError> {
        let invalid = invalid_in(name);
        let (file, sections) = scenario_file(text).map_err(&invalid)?;
        file.check_shape().map_err(&invalid)?;
        let programs = load_programs(name, &file.channel, &open)?;
        let folders = program_folders(name, &file.channel)?;
        let plc_period_ms = file.plc.as_ref().and_then(|p| p.period_ms);
        plc_period_ticks(plc_period_ms, file.cycle_ms)
            .map_err(|e| invalid(format!("[plc] period_ms: {e}")))?;
        let plc = plc_setup(name, file.plc, &open)?;
        if file.channel.is_empty() && file.ticks.is_none() {
            return Err(invalid(
                "a scenario without channels needs `ticks` (no program says when it ends)".into(),
            ));
        }
        cnc_core::machine::check_channel_images(&file.channel)
            .map_err(|e| invalid(e.to_string()))?;
        let channel_axes = super::axes::axis_names(&file.channel, &[]).len();
        let axes = super::axes::axes(&file.axis, channel_axes as u32 + 1).map_err(&invalid)?;
        if channel_axes + axes.len() > hli::layout::HLI_MAX_AXES {
            return Err(invalid(format!(
                "{channel_axes} channel axes and {} [[axis]]: the image holds {}",
                axes.len(),
                hli::layout::HLI_MAX_AXES
            )));
        }
        let names = super::axes::axis_names(&file.channel, &axes);
        let open_file = |relative: &str| {
            confined("a file", Path::new(relative))?;
            open(relative).map_err(|e| e.to_string())
        };
        let engines = engines::configure(&ConfigInput {
            sections: &sections,
            axis_names: &names,
            channel_axes,
            open: &open_file,
        })
        .map_err(|e| invalid(e.to_string()))?;
        check_block_axes(&plc, channel_axes, &names).map_err(&invalid)?;
        let ids: Vec<u32> = (1..=channel_axes as u32)
            .chain(axes.iter().map(|a| a.config.id))
            .collect();
        check_block_axis_ids(&plc, channel_axes, &ids, &names).map_err(&invalid)?;
        check_block_channels(&plc, file.channel.len()).map_err(&invalid)?;
        let signals = trace_signals(file.trace.signals).map_err(&invalid)?;
        Ok(Scenario {
            name: name.to_string(),
            cycle_s: file.cycle_ms * 1e-3,
            file_cycle_s: file.cycle_ms * 1e-3,
            ticks: file.ticks,
            plc_period_ms,
            plc_watchdog_ticks: file.plc_watchdog_ticks,
            plc_loss_drives: file.plc_loss_drives,
            channels: file.channel,
            programs,
            folders,
            axes,
            engines,
            plc,
            signals,
            realtime: file.realtime,
            realtime_plc: file.realtime_plc,
        })
    }
}

/// A relative path a scenario gives under `key` must stay inside the scenario's folder; an
/// absolute one names a file elsewhere on purpose.
fn confined(key: &str, path: &Path) -> Result<(), String> {
    use std::path::Component;
    let mut depth = 0usize;
    for part in path.components() {
        match part {
            Component::RootDir | Component::Prefix(_) => return Ok(()),
            Component::CurDir => {}
            Component::Normal(_) => depth += 1,
            Component::ParentDir => {
                depth = depth.checked_sub(1).ok_or_else(|| {
                    format!(
                        "{key} {:?} leaves the scenario's folder: give an absolute path for a file outside it",
                        path.display().to_string()
                    )
                })?;
            }
        }
    }
    Ok(())
}

/// The refusal of scenario `name` with a message.
fn invalid_in(name: &str) -> impl Fn(String) -> ScenarioError + '_ {
    move |message: String| ScenarioError::Invalid {
        file: name.to_string(),
        message,
    }
}

/// The PLC task's period in ticks of `cycle_ms`: `period_ms` must be a whole number of them
/// (1 to 1000); none: every tick.
pub fn plc_period_ticks(period_ms: Option<f64>, cycle_ms: f64) -> Result<u64, String> {
    let Some(period) = period_ms else {
        return Ok(1);
    };
    let ticks = period / cycle_ms;
    let whole = ticks.round();
    if !(period.is_finite() && period > 0.0) || (ticks - whole).abs() > 1e-9 * ticks.max(1.0) {
        return Err(format!(
            "{period} ms is not a whole number of CNC cycles of {cycle_ms} ms"
        ));
    }
    if !(1.0..=1000.0).contains(&whole) {
        return Err(format!(
            "{period} ms is {whole} CNC cycles of {cycle_ms} ms: the PLC task runs every 1 to 1000"
        ));
    }
    Ok(whole as u64)
}

impl Scenario {
    /// The PLC task's period in ticks of the run's cycle (checked at load and by
    /// [`Scenario::set_cycle_ms`]).
    pub fn plc_period_ticks(&self) -> u64 {
        plc_period_ticks(self.plc_period_ms, self.cycle_s * 1e3).unwrap_or(1)
    }

    /// Runs the machine at `cycle_ms` instead of the file's cycle, keeping the file's times:
    /// its `ticks` become as many of the new cycle as last as long (rounded to the nearest),
    /// its timeline's `at_tick` and its `plc_watchdog_ticks` the same (the PLC scales the
    /// timeline, `plc --timeline-cycle-ms`), and the PLC task keeps its period in ms. Refused with the reason: a cycle outside
    /// 0.05..=100 ms, or one the PLC's period is not a whole number of.
    pub fn set_cycle_ms(&mut self, cycle_ms: f64) -> Result<(), String> {
        check_cycle_ms(cycle_ms)?;
        plc_period_ticks(self.plc_period_ms, cycle_ms).map_err(|e| {
            format!("the PLC task's period ([plc] period_ms) does not follow it: {e}")
        })?;
        // Ticks of the run's cycle back to the file's, then to the new cycle's.
        let (file, now, new) = (self.file_cycle_s, self.cycle_s, cycle_ms * 1e-3);
        let rescale = |t: u64| {
            ((t as f64 * now / file).round() * file / new)
                .round()
                .max(1.0) as u64
        };
        self.ticks = self.ticks.map(rescale);
        self.plc_watchdog_ticks = self.plc_watchdog_ticks.map(rescale);
        self.cycle_s = new;
        Ok(())
    }
}

/// A tick cycle in ms that a machine may have: 0.05..=100.
pub fn check_cycle_ms(cycle_ms: f64) -> Result<(), String> {
    if cycle_ms.is_finite() && (0.05..=100.0).contains(&cycle_ms) {
        Ok(())
    } else {
        Err(format!("cycle_ms = {cycle_ms}: must lie in 0.05..=100"))
    }
}

impl ScenarioFile {
    /// The cycle time and the number of channels (and that there is a machine at all).
    fn check_shape(&self) -> Result<(), String> {
        check_cycle_ms(self.cycle_ms)?;
        let no_machine = self.channel.is_empty() && self.axis.is_empty();
        if no_machine || self.channel.len() > cnc_core::channel::MAX_CHANNELS {
            return Err(format!(
                "{} channels: a scenario has 0 to {} (and at least one [[channel]] or [[axis]])",
                self.channel.len(),
                cnc_core::channel::MAX_CHANNELS
            ));
        }
        Ok(())
    }
}

/// Each channel's program, read through `open` and checked (None: the channel has none).
fn load_programs(
    name: &str,
    channels: &[ChannelConfig],
    open: &impl Fn(&str) -> Result<(PathBuf, String), ScenarioError>,
) -> Result<Vec<Option<LoadedProgram>>, ScenarioError> {
    let mut programs = Vec::with_capacity(channels.len());
    for c in channels {
        programs.push(match &c.program {
            Some(p) => {
                confined("[[channel]] program", Path::new(p)).map_err(invalid_in(name))?;
                for d in &c.nc.search_path {
                    let beside = Path::new(p).parent().unwrap_or(Path::new("")).join(d);
                    confined("[[channel]] nc.search_path", &beside).map_err(invalid_in(name))?;
                }
                let (path, src) = open(p)?;
                let search = cnc_core::nc::interp::SearchPath(
                    c.nc.search_path
                        .iter()
                        .map(|d| path.parent().unwrap_or(Path::new(".")).join(d))
                        .collect(),
                );
                Some(LoadedProgram::load_with(
                    &path.display().to_string(),
                    &src,
                    &c.axes,
                    &c.nc.setup(),
                    path.parent().map(std::path::Path::to_path_buf),
                    &search,
                )?)
            }
            None => None,
        });
    }
    Ok(programs)
}

/// Each channel's program folder (`programs`), relative to the scenario's folder, with the
/// channel's machine data and search path (None: SELECT is refused).
fn program_folders(
    name: &str,
    channels: &[ChannelConfig],
) -> Result<Vec<Option<cnc_core::channel::folder::ProgramFolder>>, ScenarioError> {
    let mut folders = Vec::with_capacity(channels.len());
    for c in channels {
        let Some(dir) = &c.programs else {
            folders.push(None);
            continue;
        };
        confined("[[channel]] programs", Path::new(dir)).map_err(invalid_in(name))?;
        let mut search = Vec::with_capacity(c.nc.search_path.len());
        for d in &c.nc.search_path {
            let beside = Path::new(dir).join(d);
            confined("[[channel]] nc.search_path", &beside).map_err(invalid_in(name))?;
            search.push(beside);
        }
        folders.push(Some(cnc_core::channel::folder::ProgramFolder {
            dir: PathBuf::from(dir),
            setup: c.nc.setup(),
            search: cnc_core::nc::interp::SearchPath(search),
        }));
    }
    Ok(folders)
}

/// The PLC of scenario `name`: none, a timeline (read through `open` and checked), or a
/// built-in program with its arguments.
fn plc_setup(
    name: &str,
    plc: Option<PlcFile>,
    open: &impl Fn(&str) -> Result<(PathBuf, String), ScenarioError>,
) -> Result<PlcSetup, ScenarioError> {
    let invalid = invalid_in(name);
    if let Some(PlcFile {
        st: Some(files), ..
    }) = &plc
    {
        return st_setup(name, plc.as_ref(), files, open);
    }
    Ok(match plc {
        None => PlcSetup::None,
        Some(PlcFile {
            timeline: Some(t),
            program: None,
            file: None,
            fifo_override: None,
            saw_cuts: None,
            saw_length: None,
            st: None,
            period_ms: _,
        }) => {
            confined("[plc] timeline", Path::new(&t)).map_err(&invalid)?;
            let (path, text) = open(&t)?;
            // Checked here, so a bad timeline fails before any process starts.
            let timeline = plc_shim::timeline::Timeline::parse(&path.display().to_string(), &text)
                .map_err(|e| invalid(e.to_string()))?;
            PlcSetup::Timeline {
                path,
                text,
                timeline: Box::new(timeline),
            }
        }
        Some(PlcFile {
            timeline: None,
            program: Some(p),
            file,
            fifo_override,
            saw_cuts,
            saw_length,
            st: None,
            period_ms: _,
        }) => {
            let args = program_args(name, &p, file, fifo_override, (saw_cuts, saw_length))
                .map_err(invalid)?;
            PlcSetup::Program(p, args)
        }
        Some(PlcFile {
            timeline: Some(_),
            program: None,
            ..
        }) => {
            return Err(invalid(
                "[plc] `file`, `fifo_override`, `saw_cuts` and `saw_length` belong to a built-in program".into(),
            ))
        }
        Some(_) => {
            return Err(invalid(
                "[plc] takes exactly one of `timeline` and `program`".into(),
            ))
        }
    })
}

/// `[plc] st = [..]`: the files checked now (a program with a diagnostic fails before any
/// process starts), run as the PLC program `st` with `--st PATH..`.
fn st_setup(
    name: &str,
    plc: Option<&PlcFile>,
    files: &[String],
    open: &impl Fn(&str) -> Result<(PathBuf, String), ScenarioError>,
) -> Result<PlcSetup, ScenarioError> {
    let invalid = invalid_in(name);
    let alone = plc.is_some_and(|p| {
        p.timeline.is_none()
            && p.program.is_none()
            && p.file.is_none()
            && p.fifo_override.is_none()
            && p.saw_cuts.is_none()
            && p.saw_length.is_none()
    });
    if !alone || files.is_empty() {
        return Err(invalid(
            "[plc] `st` takes one or more files and nothing else".into(),
        ));
    }
    let mut args = vec!["--st".to_string()];
    let mut texts = Vec::with_capacity(files.len());
    for f in files {
        confined("[plc] st", Path::new(f)).map_err(&invalid)?;
        let (path, text) = open(f)?;
        args.push(path.display().to_string());
        texts.push((path.display().to_string(), text));
    }
    plc_shim::st::StProgram::from_texts(&texts, 1).map_err(invalid)?;
    Ok(PlcSetup::Program("st".into(), args))
}

/// The command-line arguments of built-in program `p` of scenario `name`: its data file
/// (resolved beside the scenario), the FIFO override, the saw's cuts and piece length.
fn program_args(
    name: &str,
    p: &str,
    file: Option<String>,
    fifo_override: Option<f64>,
    (saw_cuts, saw_length): (Option<usize>, Option<f64>),
) -> Result<Vec<String>, String> {
    if !plc_shim::cli::BUILT_IN_PROGRAMS.contains(&p) {
        return Err(format!(
            "[plc] program {p:?}: known are {:?}",
            plc_shim::cli::BUILT_IN_PROGRAMS
        ));
    }
    let mut args = Vec::new();
    if let Some(f) = file {
        confined("[plc] file", Path::new(&f))?;
        // Resolved beside the scenario and checked (header or first row) now.
        let path = Path::new(name).parent().unwrap_or(Path::new(".")).join(&f);
        plc_shim::fifo_file::RowReader::open(&path).map_err(|e| format!("[plc] file: {e}"))?;
        let path = std::fs::canonicalize(&path).unwrap_or(path);
        args.extend(["--file".to_string(), path.display().to_string()]);
    }
    if let Some(o) = fifo_override {
        if !(0.0..=100.0).contains(&o) {
            return Err(format!("[plc] fifo_override = {o}: 0 to 100 percent"));
        }
        args.extend(["--fifo-override".to_string(), o.to_string()]);
    }
    let has_saw = plc_shim::cli::SAW_PROGRAMS.contains(&p);
    if !has_saw && (saw_cuts.is_some() || saw_length.is_some()) {
        return Err(format!(
            "[plc] saw_cuts and saw_length belong to saw-cut and demo-machine, not {p:?}"
        ));
    }
    if let Some(n) = saw_cuts {
        let max = plc_shim::programs::saw_cut::MAX_CUTS;
        if !(1..=max).contains(&n) {
            return Err(format!("[plc] saw_cuts = {n}: 1 to {max}"));
        }
        args.extend(["--saw-cuts".to_string(), n.to_string()]);
    }
    if let Some(l) = saw_length {
        if !(l.is_finite() && l > 0.0) {
            return Err(format!("[plc] saw_length = {l}: mm above 0"));
        }
        args.extend(["--saw-length".to_string(), l.to_string()]);
    }
    Ok(args)
}

/// A timeline's blocks command single axes only, and only axes the machine has.
fn check_block_axes(plc: &PlcSetup, channel_axes: usize, names: &[String]) -> Result<(), String> {
    let PlcSetup::Timeline { timeline, path, .. } = plc else {
        return Ok(());
    };
    for (instance, axis) in timeline.block_axes() {
        if (axis as usize) < channel_axes {
            return Err(format!(
                "{}: block {instance:?}: axis {axis} ({}) is a channel axis, commanded by its channel",
                path.display(),
                names[axis as usize]
            ));
        }
        if axis as usize >= names.len() {
            return Err(format!(
                "{}: block {instance:?}: axis {axis} does not exist (the machine has {} axes: {})",
                path.display(),
                names.len(),
                names.join(", ")
            ));
        }
    }
    Ok(())
}

/// The NC axis IDs a timeline's blocks name (`axis_id`, `master_id`) are the machine's
/// (`ids[i]` is axis `i`'s), and a block's own axis is a single axis.
fn check_block_axis_ids(
    plc: &PlcSetup,
    channel_axes: usize,
    ids: &[u32],
    names: &[String],
) -> Result<(), String> {
    let PlcSetup::Timeline { timeline, path, .. } = plc else {
        return Ok(());
    };
    for (instance, id, own) in timeline.block_axis_ids() {
        let key = if own { "axis_id" } else { "master_id" };
        let Some(axis) = ids.iter().position(|&i| i == id) else {
            return Err(format!(
                "{}: block {instance:?}: `{key}` = {id}: no axis has that ID (the machine's: {ids:?})",
                path.display()
            ));
        };
        if own && axis < channel_axes {
            return Err(format!(
                "{}: block {instance:?}: axis ID {id} ({}) is a channel axis, commanded by its channel",
                path.display(),
                names[axis]
            ));
        }
    }
    Ok(())
}

/// Every channel block of a timeline addresses a channel of the machine.
fn check_block_channels(plc: &PlcSetup, channels: usize) -> Result<(), String> {
    let PlcSetup::Timeline { timeline, path, .. } = plc else {
        return Ok(());
    };
    for (instance, channel) in timeline.block_channels() {
        if channel as usize >= channels {
            return Err(format!(
                "{}: block {instance:?}: channel {channel} does not exist (the machine has {channels})",
                path.display()
            ));
        }
    }
    Ok(())
}

/// The scenario's own keys, and the keys the engines read (`sections`); a key neither
/// reads is refused by name (the TOML reader's errors keep their line and column).
fn scenario_file(text: &str) -> Result<(ScenarioFile, toml::Table), String> {
    let mut ignored = Vec::new();
    let file: ScenarioFile = serde_ignored::deserialize(toml::Deserializer::new(text), |path| {
        ignored.push(path.to_string())
    })
    .map_err(|e| e.to_string())?;
    let engine_keys: Vec<&str> = engines::sections().collect();
    if let Some(key) = ignored.iter().find(|k| !engine_keys.contains(&k.as_str())) {
        return Err(format!(
            "unknown key `{key}` (neither the scenario's nor an engine's: {})",
            engine_keys.join(", ")
        ));
    }
    let mut all: toml::Table = toml::from_str(text).map_err(|e| e.to_string())?;
    all.retain(|key, _| engine_keys.contains(&key));
    Ok((file, all))
}

/// The trace signals resolved to leaves of the image.
fn trace_signals(signals: Vec<String>) -> Result<Vec<(String, Leaf)>, String> {
    let mut out = Vec::with_capacity(signals.len());
    for s in signals {
        let leaf = Leaf::resolve(&s).map_err(|e| format!("[trace] {e}"))?;
        out.push((s, leaf));
    }
    Ok(out)
}
