//! The cam engine through the PLC: the conveyor scenario end to end in-process (the PLC's cam
//! blocks through the acyclic service), the coupling law checked tick by tick against the
//! master's set-points; the data, multi-table and compatibility scenarios; the cam blocks in
//! PLC timelines. The engine's own tests, on acyclic calls alone, live beside it in
//! `cnc_core::cam::machine` (on `cnc_core::harness::Harness`).

use cnc_app::scenario::{InProcess, Scenario};
use cnc_core::cam::coupling::{CamLaw, Scaling};
use cnc_core::cam::{CamProfile, ProfileCursor};
use cnc_core::setpoint::Kinematic;
use hli::calls::cam::CamCouplingError;
use hli::calls::cam::CamReply;
use hli::calls::cam::CamStartMode;
use hli::calls::AcyclicCall;
use hli::enums::{AxisState, CouplingState};
use hli::views::CncView;
use hli::wire::{encode_body, AcyclicRequest};
use std::path::PathBuf;

pub(crate) mod data;
mod manual_gaps;
mod modes;
mod selection;
mod superimposed;

const MASTER: usize = 0;
const SLAVE: usize = 1;

fn scenarios() -> PathBuf {
    tests::cli::repo_root().join("scenarios")
}

fn seed_cam() -> CamProfile {
    let text = std::fs::read(scenarios().join("cams/seed_example.json")).unwrap();
    cnc_core::cam::file::parse(&text, Default::default())
        .unwrap()
        .profile
}

fn set(run: &InProcess, axis: usize) -> Kinematic {
    run.machine.axes().axis(axis).unwrap().setpoint()
}

fn phase(run: &InProcess, axis: usize) -> AxisState {
    run.machine
        .axes()
        .axis(axis)
        .unwrap()
        .motion_state(set(run, axis))
}

/// The zigzag of the compatibility scenario's table 22 (+-9 per turn, linear) at master `m`.
fn zigzag(m: f64) -> f64 {
    let m = m.rem_euclid(360.0);
    match m {
        m if m < 90.0 => m / 10.0,
        m if m < 270.0 => 9.0 - (m - 90.0) / 10.0,
        m => -9.0 + (m - 270.0) / 10.0,
    }
}

/// The seed cam's point 4 (the fall's start at master 240) at slave position `slave`.
pub(crate) fn seed_point_4(slave: f64) -> hli::calls::cam::McMotionFunctionPoint {
    hli::calls::cam::McMotionFunctionPoint {
        point_index: 4,
        function_type: 15,
        point_type: 2,
        rel_index_next_point: 1,
        master_pos: 240.0,
        slave_pos: slave,
        ..Default::default()
    }
}

/// The law of a slave coupled absolute, unscaled, to the seed cam at master 0, slave 0.
fn seed_law(periodic: bool) -> CamLaw {
    CamLaw::new(
        &seed_cam(),
        Scaling::default(),
        CamStartMode::Absolute,
        periodic,
        0.0,
        0.0,
    )
}

/// The first steps of a timeline on the seed cam: table 1 selected cyclic and absolute, the
/// lifter (axis 1) coupled to the conveyor (axis 0), and the conveyor run at 360 degree/s.
const COUPLED_AND_RUNNING: &str = r#"
[[step]]
at_tick = 2
call = { block = "MC_CamTableSelect", instance = "select", axis = 1, table = 1, periodic = true, master_absolute = true, slave_absolute = true }
[[step]]
wait = "select.Done"
call = { block = "MC_CamIn", instance = "cam", axis = 1, master = 0, table = 1, start_mode = "absolute" }
[[step]]
wait = "cam.InSync"
call = { block = "MC_MoveVelocity", instance = "run", axis = 0, velocity = 360.0, direction = 1, acceleration = 3600.0, deceleration = 3600.0, jerk = 36000.0 }
"#;

/// The line of block `instance` in a timeline's report.
fn block_line(report: &str, instance: &str) -> String {
    let start = format!("block {instance} ");
    let line = report.lines().find(|l| l.starts_with(&start));
    line.unwrap_or_else(|| panic!("no block {instance}\n{report}"))
        .to_string()
}

/// A scenario `toml` whose `plc.toml` is `timeline` and whose other files are the cam
/// examples (`scenarios/cams`).
fn with_timeline(name: &str, toml: &str, timeline: &str) -> Scenario {
    with_timeline_result(name, toml, timeline).unwrap()
}

/// [`with_timeline`], or why the scenario is refused.
fn with_timeline_result(name: &str, toml: &str, timeline: &str) -> Result<Scenario, String> {
    Scenario::parse(name, toml, |f| {
        if f == "plc.toml" {
            return Ok((PathBuf::from(f), timeline.to_string()));
        }
        let path = scenarios().join("cams").join(f);
        Ok((path.clone(), std::fs::read_to_string(path).unwrap()))
    })
    .map_err(|e| e.to_string())
}

fn law_at(law: &CamLaw, profile: &CamProfile, master: Kinematic) -> Kinematic {
    law.slave(profile, &mut ProfileCursor::default(), &master).0
}

/// The seed cam with point 4 at 30 instead of 40, as the conveyor's PLC writes it.
fn changed_cam(profile: &CamProfile) -> CamProfile {
    let CamProfile::MotionFunction(f) = profile else {
        unreachable!("the seed cam is a motion function")
    };
    let mut p4 = f.points()[3];
    p4.slave = 30.0;
    CamProfile::MotionFunction(f.with_points_written(4, &[p4]).unwrap())
}

#[test]
fn the_conveyor_scenario_follows_the_law_scales_changes_a_point_and_decouples() {
    let s = Scenario::load(&scenarios().join("cam-conveyor/scenario.toml")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let original = seed_cam();
    let changed = changed_cam(&original);
    let law = seed_law(true);
    // The three phases: scaling 1 with the original cam, 0.5 with it, 0.5 with the changed
    // one. Each switch happens where the laws before and after agree (the rest at the cycle
    // start), so the phase a tick belongs to is the first that explains it from the last.
    let phases = [(1.0, &original), (0.5, &original), (0.5, &changed)];
    let mut phase = 0;
    let mut entered = [None; 3];
    let mut synced_ticks = 0;
    let mut last: Option<f64> = None;
    let mut max_step: f64 = 0.0;
    for tick in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let slave = set(&run, SLAVE);
        if let Some(p) = last {
            max_step = max_step.max((slave.position - p).abs());
        }
        last = Some(slave.position);
        if run.machine.axes().axis(SLAVE).unwrap().coupling().is_none()
            || self::phase(&run, SLAVE) != AxisState::SlaveSynchronous
        {
            continue;
        }
        synced_ticks += 1;
        let master = set(&run, MASTER);
        let fits = |(ss, profile): (f64, &CamProfile)| {
            let expected = law_at(&law, profile, master);
            (slave.position - ss * expected.position).abs() < 1e-9
                && (slave.velocity - ss * expected.velocity).abs() < 1e-6
        };
        while !fits(phases[phase]) {
            phase += 1;
            assert!(
                phase < 3,
                "tick {tick}: slave {slave:?} for master {master:?} fits no phase"
            );
            entered[phase] = Some((tick, law.locate(master.position)));
        }
    }
    assert!(synced_ticks > 3000, "synchronous for {synced_ticks} ticks");
    // Both changes took effect after they were sent (1700, 2602), each in the cam's first 30
    // degrees of a new turn (where it rests and the phases agree, they cannot be told apart).
    for (k, sent) in [(1, 1700), (2, 2602)] {
        let (tick, at) = entered[k].unwrap_or_else(|| panic!("phase {k} never came"));
        assert!(tick > sent, "phase {k} at tick {tick}");
        assert!(at.local <= 30.5, "phase {k} at {} degrees", at.local);
    }
    let (t1, a1) = entered[1].unwrap();
    let (t2, a2) = entered[2].unwrap();
    assert!(t2 > t1 && a2.cycle > a1.cycle);
    // No jump anywhere: at most one tick's travel at the cam's top speed.
    assert!(max_step < 0.35, "largest step {max_step} mm");
    // Decoupled in a rest phase: free, at rest, where the cam left it.
    let lifter = run.machine.axes().axis(SLAVE).unwrap();
    assert!(lifter.coupling().is_none());
    assert_eq!(set(&run, SLAVE).velocity, 0.0);
    assert!(lifter.error().is_none());
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(report.contains("InSync"), "{report}");
    assert!(
        report.contains("block out (MC_CamOut on gpAx[1]): Done"),
        "{report}"
    );
    assert!(
        report.contains("block point (MC_WriteMotionFunctionPoint on gpAx[1]): Done"),
        "{report}"
    );
}

fn dispatch_raw<C: AcyclicCall>(run: &mut InProcess, target: u32, body: &C) -> Vec<u8> {
    let (body, body_len) = encode_body(body);
    let request = AcyclicRequest {
        invoke_id: 3,
        kind: C::KIND.raw(),
        target,
        body_len,
        body,
    };
    let view = CncView::new(&run.memory);
    let (reply, len) = run.machine.dispatch(&view, C::KIND, &request).unwrap();
    reply[..len as usize].to_vec()
}

/// Every part of a read, joined.
fn read_all(
    run: &mut InProcess,
    target: u32,
    call: hli::calls::cam::CamReadCall,
) -> (Vec<f64>, u32) {
    let mut values = Vec::new();
    let mut columns = 1;
    for part in 0.. {
        let reply: hli::calls::cam::CamValuesReply = bytemuck::pod_read_unaligned(&dispatch_raw(
            run,
            target,
            &hli::calls::cam::CamReadCall { part, ..call },
        ));
        assert_eq!(reply.error_id, 0, "part {part}");
        values.extend_from_slice(&reply.values[..reply.count as usize]);
        columns = reply.columns;
        if values.len() >= reply.total as usize {
            break;
        }
    }
    (values, columns)
}
