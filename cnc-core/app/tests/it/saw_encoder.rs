//! The flying saw on an encoder master (seed 001, chapter 3): the extruder case of
//! `scenarios/saw-encoder`, where the saw follows a strip's noisy encoder and cuts it to the
//! length asked for (a scenario file with its PLC timeline: it needs the application). The
//! acceleration threshold at coupling with IGNOREMASTERACC beside it runs in the library on
//! its machine harness: `cnc_core::saw`'s `engine_tests`.

use cnc_app::scenario::{InProcess, Scenario};
use cnc_core::setpoint::Kinematic;
use hli::enums::AxisState;

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
