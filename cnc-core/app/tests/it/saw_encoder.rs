//! The flying saw on an encoder master (seed 001, chapter 3): the extruder case of
//! `scenarios/saw-encoder`, where the saw follows a strip's noisy encoder and cuts it to the
//! length asked for, and the acceleration threshold at coupling with IGNOREMASTERACC beside it.

use cnc_app::scenario::{InProcess, Scenario};
use cnc_core::setpoint::Kinematic;
use hli::calls::axis::AxisCommandCall;
use hli::calls::saw::{sync_mask as m, SawCharacCall, SawGearInCall, SawSyncTarget};
use hli::enums::AxisState;
use hli::views::CncView;

const TICK: f64 = 0.001;
const STRIP: usize = 0;
const SAW: usize = 1;

fn set(run: &InProcess, axis: usize) -> Kinematic {
    run.machine.axes().axis(axis).unwrap().setpoint()
}

fn encoder(run: &InProcess, axis: usize) -> Kinematic {
    run.machine.axes().master(axis, true).unwrap()
}

/// The extruder scenario: in every synchronous tick the saw stands exactly where the strip's
/// encoder reading puts it (1300 mm when the encoder reads 1500, then 2500), so the two cuts
/// lie 1000 mm apart on the strip whatever the noise; the saw's set-point keeps its acceleration
/// limit (the encoder noise reaches it only through the master's acceleration), no axis
/// faults, and the saw ends at rest at home.
#[test]
fn the_saw_cuts_a_strip_it_knows_only_by_its_noisy_encoder() {
    let s = Scenario::load(&tests::cli::scenario("saw-encoder")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let (mut synchronous, mut cuts, mut was_sync) = (0, Vec::new(), false);
    let mut noisy = 0;
    for _ in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let saw = run.machine.axes().axis(SAW).unwrap();
        assert!(saw.error().is_none(), "{:?}", saw.error());
        let (strip, slave) = (encoder(&run, STRIP), set(&run, SAW));
        noisy += usize::from(strip.acceleration != 0.0);
        assert!(slave.acceleration.abs() <= 8000.0 * 1.05, "{slave:?}");
        let sync = saw
            .coupling()
            .is_some_and(|c| c.phase == AxisState::SlaveSynchronous);
        if sync {
            synchronous += 1;
            if !was_sync {
                cuts.push(strip.position);
            }
            // The saw's place on the strip: 1300 - 1500, then 1300 - 2500.
            let gap = slave.position - strip.position;
            let want = 1300.0 - [1500.0, 2500.0][cuts.len() - 1];
            assert!((gap - want).abs() < 1e-9, "saw {slave:?} strip {strip:?}");
        }
        was_sync = sync;
    }
    assert_eq!(cuts.len(), 2, "{cuts:?}");
    for (cut, at) in cuts.iter().zip([1500.0, 2500.0]) {
        // Synchronous from the tick the encoder passes the sync position: within one tick.
        assert!((0.0..0.21).contains(&(cut - at)), "{cuts:?}");
    }
    assert!(synchronous > 800, "{synchronous}");
    assert!(
        noisy > 5_000,
        "the encoder's acceleration is noise: {noisy}"
    );
    let saw = set(&run, SAW);
    assert!(saw.position.abs() < 1e-9 && saw.velocity == 0.0, "{saw:?}");
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
}

/// A machine of a strip on a slow drive whose encoder reads with noise `noise` (units), and a
/// saw; the strip at 200 mm/s, the saw at 100 mm/s.
fn strip_at_speed(noise: f64) -> InProcess {
    let axis = |name: &str, extra: &str| {
        format!(
            "[[axis]]\nname = \"{name}\"\npower = true\nsoft_limits = [-1e6, 1e6]\n\
             velocity = 3000.0\nacceleration = 20000.0\ndeceleration = 20000.0\njerk = 1e7\n{extra}"
        )
    };
    let toml = format!(
        "cycle_ms = 1.0\nticks = 10\n{}{}",
        axis(
            "Strip",
            &format!("drive = {{ model = \"pt1\", t1_ms = 40.0 }}\nencoder_noise = {noise}\n")
        ),
        axis("Saw", "")
    );
    let s = Scenario::parse("strip.toml", &toml, |_| unreachable!("no files")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    run.step(TICK);
    let view = CncView::new(&run.memory);
    let go = AxisCommandCall::move_velocity(1, [200.0, 2000.0, 2000.0, 1e5]);
    assert_eq!(
        run.machine.call(&view, STRIP as u32, &go).unwrap().error_id,
        0
    );
    // The saw moving too: a master's acceleration then shapes the slave's start.
    let slow = AxisCommandCall::move_velocity(1, [100.0, 2000.0, 2000.0, 1e5]);
    assert_eq!(
        run.machine.call(&view, SAW as u32, &slow).unwrap().error_id,
        0
    );
    for _ in 0..1000 {
        run.step(TICK);
    }
    run
}

/// Couples the saw to the strip's encoder when `pick` likes the encoder's acceleration (the
/// watchdog: 2,000 ticks), with check and operation bits `mask`; the number of points of the
/// planned phase (the organisation field NumberOfRows: 2 for a lone fifth-order polynomial,
/// 3 once a straight piece joins it).
fn points_of_the_plan(run: &mut InProcess, mask: u32, pick: impl Fn(f64) -> bool) -> u32 {
    let mut picked = false;
    for _ in 0..2000 {
        if pick(encoder(run, STRIP).acceleration) {
            picked = true;
            break;
        }
        run.step(TICK);
    }
    assert!(picked, "no tick with such an acceleration");
    let m0 = encoder(run, STRIP).position;
    let call = SawGearInCall {
        master: STRIP as u32,
        master_source: 1,
        target: SawSyncTarget::Position.raw(),
        master_sync_position: m0 + 1000.0,
        slave_sync_position: 600.0,
        ratio_numerator: 1.0,
        ratio_denominator: 1,
        mask,
        ..SawGearInCall::default()
    };
    let view = CncView::new(&run.memory);
    assert_eq!(
        run.machine.call(&view, SAW as u32, &call).unwrap().error_id,
        0
    );
    let org = run
        .machine
        .call(&view, SAW as u32, &SawCharacCall { part: 2 })
        .unwrap();
    org.values[1] as u32
}

/// Below 2 x 0.1 um / (1 ms)^2 = 200 mm/s^2 the encoder's acceleration counts as none at
/// coupling, and the planner joins a straight piece to its polynomial (step 1); a real
/// acceleration above it is kept and leaves the lone polynomial. IGNOREMASTERACC drops any.
#[test]
fn an_encoder_acceleration_below_the_threshold_counts_as_none_at_coupling() {
    let quantised = |a: f64| a != 0.0 && a.abs() < 200.0;
    let mut run = strip_at_speed(0.00003);
    assert_eq!(points_of_the_plan(&mut run, 0, quantised), 3);
    // A noisier encoder: above the threshold the acceleration stands, unless ignored.
    let beyond = |a: f64| a.abs() > 250.0;
    let mut run = strip_at_speed(0.0003);
    assert_eq!(points_of_the_plan(&mut run, 0, beyond), 2);
    let mut run = strip_at_speed(0.0003);
    assert_eq!(points_of_the_plan(&mut run, m::IGNOREMASTERACC, beyond), 3);
}
