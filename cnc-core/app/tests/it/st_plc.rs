//! A Structured Text PLC in a scenario (`[plc] st = [..]`): in-process and as the PLC process
//! of `cnc run`, it writes the channel's path override through `gpCh` as the manuals write it,
//! and a run-time fault stops the PLC and the CNC stops as for a lost PLC, the fault named.

use cnc_app::scenario::{InProcess, Scenario};
use tests::{Cli, Scratch};

const SCENARIO: &str = "cycle_ms = 1.0\nticks = 400\n\
    [[channel]]\nname = \"mill\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"part.nc\"\n\
    [plc]\nst = [\"override.st\"]\n\
    [trace]\nsignals = [\"gpCh[0]^channel_mc_control.path_override.feed_override_r\"]\n";

const PART: &str = "G01 X100 F6000\nM30\n";

/// Half the feed from the first cycle on; with `fault`, a division by zero at cycle 50.
fn override_st(fault: bool) -> String {
    let crash = if fault {
        "IF n = 50 THEN n := n / zero; END_IF\n"
    } else {
        ""
    };
    format!(
        "PROGRAM MAIN\nVAR\n    pOverride : POINTER TO HLI_CHANNEL_OVERRIDE_UNIT;\n    n, zero : DINT;\nEND_VAR\n\
         pOverride := ADR(gpCh[0]^channel_mc_control.path_override);\n\
         pOverride^.feed_override_w := UDINT#500;\nn := n + 1;\n{crash}END_PROGRAM\n"
    )
}

fn write_scenario(dir: &Scratch, fault: bool) -> std::path::PathBuf {
    std::fs::write(dir.join("part.nc"), PART).unwrap();
    std::fs::write(dir.join("override.st"), override_st(fault)).unwrap();
    let path = dir.join("scenario.toml");
    std::fs::write(&path, SCENARIO).unwrap();
    path
}

#[test]
fn an_st_program_sets_the_feed_override_in_process() {
    let dir = Scratch::new("st-plc-inproc");
    let s = Scenario::load(&write_scenario(&dir, false)).unwrap();
    let run = InProcess::run_through(&s).unwrap();
    let csv = String::from_utf8(run.trace_csv()).unwrap();
    let last = csv.lines().last().unwrap();
    assert!(
        last.ends_with(",500"),
        "the CNC took the PLC's 50 %: {last}"
    );
}

#[test]
fn an_st_plc_process_runs_and_a_fault_stops_it_and_the_machine() {
    let dir = Scratch::new("st-plc-process");
    let path = write_scenario(&dir, false);
    let trace = dir.join("t.csv");
    let out = tests::cli::cnc_run(
        env!("CARGO_BIN_EXE_cnc"),
        &[path.to_str().unwrap(), "--lockstep"],
        &tests::unique_instance("st-plc"),
        &trace,
    );
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("st: "),
        "{}",
        tests::cli::report(&out)
    );
    let text = std::fs::read_to_string(&trace).unwrap();
    assert!(text.lines().last().unwrap().ends_with(",500"));

    let dir = Scratch::new("st-plc-fault");
    let path = write_scenario(&dir, true);
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["run", path.to_str().unwrap(), "--lockstep"])
        .args(["--instance", &tests::unique_instance("st-fault")])
        .output()
        .unwrap();
    let report = tests::cli::report(&out);
    assert!(!out.status.success(), "{report}");
    assert!(
        report.contains("override.st:9:16: fault: division by zero"),
        "{report}"
    );
    assert!(
        report.contains("PLC lost") && report.contains("machine at rest"),
        "{report}"
    );
}

#[test]
fn a_scenario_refuses_an_st_program_with_a_mistake_before_anything_runs() {
    let dir = Scratch::new("st-plc-bad");
    let path = write_scenario(&dir, false);
    std::fs::write(
        dir.join("override.st"),
        "PROGRAM MAIN\n  x := 1;\nEND_PROGRAM\n",
    )
    .unwrap();
    let e = Scenario::load(&path).unwrap_err().to_string();
    assert!(
        e.contains("override.st:2:3: error: unknown name `x`"),
        "{e}"
    );
}

#[test]
fn plc_check_reports_every_diagnostic_with_its_place() {
    let dir = Scratch::new("st-plc-check");
    let bad = dir.join("bad.st");
    std::fs::write(
        &bad,
        "PROGRAM MAIN\nVAR b : BOOL; END_VAR\n  x := 1;\n  b := 5 + TRUE;\nEND_PROGRAM\n",
    )
    .unwrap();
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["plc", "check", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.st:3:3: error: unknown name `x`"), "{err}");
    assert!(
        err.contains("bad.st:4:10: error: `+` of DINT and BOOL"),
        "{err}"
    );
    let good = dir.join("good.st");
    std::fs::write(&good, override_st(false)).unwrap();
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["plc", "check", good.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", tests::cli::report(&out));
    // The machines CI runs on are ones Cranelift compiles for.
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("as native code"), "{said}");
}

/// The lockstep trace of `scenarios/DIR/FILE` (`cnc run --lockstep`, the PLC a process).
fn trace_of(dir: &str, file: &str) -> Vec<u8> {
    let path = tests::cli::repo_root()
        .join("scenarios")
        .join(dir)
        .join(file);
    let tag = format!("twin-{}", &dir[..dir.len().min(12)]);
    tests::cli::cnc_run_lockstep(env!("CARGO_BIN_EXE_cnc"), &path, &tag).1
}

/// The manuals' programs in ST (`scenario-st.toml` beside each twin): their traces equal
/// their timeline twins' tick for tick, every signal.
#[test]
fn the_st_twins_trace_as_their_timelines_do() {
    for dir in [
        "axes-plcopen",
        "example4-turntable-hybrid",
        "example4-turntable-plc",
        "cam-conveyor",
        "cam-compat",
        "cam-data",
        "cam-multi-table",
        "cam-ref",
        "channel-control",
        "saw-blocks",
        "fifo-blocks",
    ] {
        let (timeline, st) = (
            trace_of(dir, "scenario.toml"),
            trace_of(dir, "scenario-st.toml"),
        );
        assert!(timeline.len() > 10_000, "{dir}: a trace of a run");
        let first_difference = timeline.iter().zip(&st).position(|(a, b)| a != b);
        assert!(
            timeline == st,
            "{dir}: the ST twin's trace differs from byte {first_difference:?} on"
        );
    }
}

/// The same twin written in TwinCAT 3's object-oriented style (`plc-oop.st`: an axis block
/// with METHODs that set what its body passes to its PLCopen blocks, a PRIVATE method and
/// `THIS^`): its trace equals the timeline's tick for tick too.
#[test]
fn the_object_oriented_twin_traces_as_its_timeline_does() {
    let dir = "axes-plcopen";
    let (timeline, oop) = (
        trace_of(dir, "scenario.toml"),
        trace_of(dir, "scenario-oop.toml"),
    );
    assert!(timeline.len() > 10_000, "a trace of a run");
    let first_difference = timeline.iter().zip(&oop).position(|(a, b)| a != b);
    assert!(
        timeline == oop,
        "the object-oriented twin's trace differs from byte {first_difference:?} on"
    );
}

/// `cnc demo --lockstep [--st]` into a scratch folder: the demo's trace.
fn demo_trace(st: bool) -> Vec<u8> {
    let dir = Scratch::new(if st { "demo-st" } else { "demo-rust" });
    let plc = if st { &["--st"][..] } else { &[] };
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["demo", "--lockstep", "--out", dir.path().to_str().unwrap()])
        .args(["--instance", &tests::unique_instance("demo-st")])
        .args(plc)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", tests::cli::report(&out));
    std::fs::read(dir.join("demo.csv")).unwrap()
}

/// The demo machine's PLC program in ST (`scenarios/demo/plc.st`: the robots' ChannelStart,
/// the turntable, the cam station, the flying saw) runs the whole machine as the Rust
/// program does: `cnc demo --st` traces the same, byte for byte.
#[test]
fn cnc_demo_st_traces_as_the_rust_program_does() {
    let (rust, st) = (demo_trace(false), demo_trace(true));
    assert!(rust.len() > 100_000, "a trace of the demo");
    let first_difference = rust.iter().zip(&st).position(|(a, b)| a != b);
    assert!(
        rust == st,
        "the ST demo differs from byte {first_difference:?} on"
    );
}

/// An ST program shared with the test while the in-process run cycles it.
struct Shared(std::rc::Rc<std::cell::RefCell<plc_shim::st::StProgram>>);

impl plc_shim::runtime::PlcProgram for Shared {
    fn cycle(&mut self, io: &mut plc_shim::runtime::PlcIo<'_>) {
        self.0.borrow_mut().cycle(io);
    }
    fn summary(&self) -> String {
        self.0.borrow().summary()
    }
}

/// The ST twin of the scenario in `dir` (`scenario-st.toml`, `plc.st`) run in-process to
/// its end: its program, to look into.
fn st_in_process(dir: &str) -> std::rc::Rc<std::cell::RefCell<plc_shim::st::StProgram>> {
    let st = Scenario::load(std::path::Path::new(&format!("{dir}/scenario-st.toml"))).unwrap();
    let program =
        plc_shim::st::StProgram::load(&[format!("{dir}/plc.st").into()], 1).expect("plc.st");
    let shared = std::rc::Rc::new(std::cell::RefCell::new(program));
    let mut run = InProcess::new(&st, 0).unwrap();
    run.program = Some(cnc_app::scenario::machine::BuiltIn(Box::new(Shared(
        shared.clone(),
    ))));
    for _ in 0..st.ticks.unwrap() {
        run.step(st.cycle_s);
    }
    shared
}

/// The value at `path` (`MAIN.aValues[1,2]`, `MAIN.fbInfo.CamInfo.Periodic`) of a program's
/// memory, as a number (LREAL, REAL, or an unsigned integer or BOOL).
fn lreal_of(p: &plc_shim::st::StProgram, path: &str) -> f64 {
    let symbols = p.program().symbols(100_000);
    let s = symbols.iter().find(|s| s.path == path).expect(path);
    let (at, n) = (s.offset as usize, s.elem.size());
    let mut bytes = [0u8; 8];
    bytes[..n].copy_from_slice(&p.program().memory()[at..at + n]);
    match s.elem.name() {
        "LREAL" => f64::from_le_bytes(bytes),
        "REAL" => f64::from(f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])),
        _ => u64::from_le_bytes(bytes) as f64,
    }
}

/// The numbers a timeline's report shows of block `instance`'s read.
fn reported(summary: &str, instance: &str) -> Vec<f64> {
    crate::cam_engine::data::read_values(summary, instance)
}

/// The reads of scenarios/cam-data in ST (MC_ReadMotionFunctionValues and
/// MC_ReadMotionFunction through an MC_CAM_REF) fill the program's arrays with the numbers
/// the timeline twin's blocks read, on the same machine.
#[test]
fn st_reads_fill_the_programs_arrays_with_what_the_timeline_reads() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios/cam-data");
    let timeline = Scenario::load(std::path::Path::new(&format!("{dir}/scenario.toml"))).unwrap();
    let run = InProcess::run_through(&timeline).unwrap();
    let summary = run.timeline.as_ref().unwrap().summary();
    let (values, points) = (reported(&summary, "values"), reported(&summary, "points"));
    assert!(values.len() >= 12 && points.len() >= 12, "{summary}");

    let p = st_in_process(dir);
    let p = p.borrow();
    let lreal = |path: &str| lreal_of(&p, path);
    let row_major: Vec<f64> = (1..=6)
        .flat_map(|r| (1..=2).map(move |c| (r, c)))
        .map(|(r, c)| lreal(&format!("MAIN.aValues[{r},{c}]")))
        .collect();
    assert_eq!(row_major, values[..12]);
    // The reads' outputs of their own (seed 000: SlavePosition .., CamTableCharac, Point,
    // CamInfo), as the timeline's blocks read them.
    let dynamics = reported(&summary, "dynamics");
    let shown = ["SlavePosition", "SlaveVelocity", "SlaveAcceleration"]
        .map(|o| lreal(&format!("MAIN.fbDynamics.{o}")));
    assert_eq!(shown[..], dynamics[..3]);
    let charac = reported(&summary, "charac");
    let fields = [
        "fMasterVeloNom",
        "fMasterPosStart",
        "fSlavePosStart",
        "fMasterPosEnd",
    ];
    let shown = fields.map(|f| lreal(&format!("MAIN.fbCharac.CamTableCharac.{f}")));
    assert_eq!(shown, [charac[0], charac[1], charac[2], charac[6]]);
    let point = reported(&summary, "point4");
    let fields = ["PointIndex", "MasterPos", "SlavePos"];
    let shown = fields.map(|f| lreal(&format!("MAIN.fbPoint4.Point.{f}")));
    assert_eq!(shown[..], point[..3]);
    let info = reported(&summary, "info");
    let fields = [
        "CamTableID",
        "TableType",
        "Periodic",
        "InterpolationType",
        "NumberOfRows",
    ];
    let shown = fields.map(|f| lreal(&format!("MAIN.fbInfo.CamInfo.{f}")));
    assert_eq!(shown[..], info[..5]);
    for k in 0..4 {
        let field = |f: &str| lreal(&format!("MAIN.aPoints[{}].{f}", k + 1));
        assert_eq!(
            [field("MasterPos"), field("SlavePos")],
            [points[3 * k + 1], points[3 * k + 2]],
            "point {}",
            k + 1
        );
    }
}

/// CamTableReadData in ST (seed 000 5.2.1.5) reads table 21's rows into the program's array
/// through `AdrDataArray`: the rows CamTableWriteData wrote from another array; and
/// CamTableReadSlavePos shows the slave position the timeline's block reads.
#[test]
fn st_cam_table_read_data_fills_the_array_adr_data_array_points_to() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios/cam-compat");
    let p = st_in_process(dir);
    let p = p.borrow();
    let read: Vec<f64> = (1..=4)
        .flat_map(|r| (1..=2).map(move |c| (r, c)))
        .map(|(r, c)| lreal_of(&p, &format!("MAIN.aRead[{r},{c}]")))
        .collect();
    assert_eq!(read, [0.0, 0.0, 40.0, 4.0, 100.0, 5.0, 0.0, 0.0]);
    // CamTableReadSlavePos's fSlavePos, as the timeline's block reads it.
    let timeline = Scenario::load(std::path::Path::new(&format!("{dir}/scenario.toml"))).unwrap();
    let run = InProcess::run_through(&timeline).unwrap();
    let slave = reported(&run.timeline.as_ref().unwrap().summary(), "slavepos")[0];
    assert_eq!(lreal_of(&p, "MAIN.fbSlavePos.fSlavePos"), slave);
    assert!(slave > 0.0, "2 at master 20 of 0..40 -> 0..4: {slave}");
}

/// MC_ReadFlyingSawCharacteristics in ST (seed 001 12.1.3) shows the characteristic values
/// of the sync phase in `CamTableCharac : MC_FlyingSawCharacValues`, as the timeline twin's
/// block reads them.
#[test]
fn st_flying_saw_characteristics_show_what_the_timeline_reads() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios/saw-blocks");
    let timeline = Scenario::load(std::path::Path::new(&format!("{dir}/scenario.toml"))).unwrap();
    let run = InProcess::run_through(&timeline).unwrap();
    let charac = reported(&run.timeline.as_ref().unwrap().summary(), "charac");
    let p = st_in_process(dir);
    let p = p.borrow();
    let fields = [
        "fMasterVeloNom",
        "fMasterPosStart",
        "fSlavePosStart",
        "fSlaveVeloStart",
    ];
    let shown = fields.map(|f| lreal_of(&p, &format!("MAIN.fbCharac.CamTableCharac.{f}")));
    assert_eq!(shown[..], charac[..4]);
    assert!(shown[2] != 0.0, "a read, not zeros: {shown:?}");
}

/// ReadChannelState in ST shows the channel's state while Valid (its outputs of its own): the
/// channel-control twin's panel ends as the timeline's block reads the channel.
#[test]
fn st_read_channel_state_shows_the_channels_state() {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/channel-control"
    );
    let timeline = Scenario::load(std::path::Path::new(&format!("{dir}/scenario.toml"))).unwrap();
    let run = InProcess::run_through(&timeline).unwrap();
    let panel = reported(&run.timeline.as_ref().unwrap().summary(), "panel");
    let p = st_in_process(dir);
    let p = p.borrow();
    let shown = [
        "State",
        "BlockNr",
        "ProgramsEnded",
        "ChannelErrorID",
        "Signals",
    ]
    .map(|o| lreal_of(&p, &format!("MAIN.fbPanel.{o}")));
    assert_eq!(shown[..], panel[..5]);
    assert!(shown[2] >= 4.0, "four parts ended: {shown:?}");
}
