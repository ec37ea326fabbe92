//! A scenario run at another cycle than its file's (`cnc run --cycle-ms`, `cnc demo
//! --cycle-ms`) keeps its times: its length, its timeline's `at_tick`, the waits of the
//! built-in programs, and the PLC task's period in ms; a cycle the PLC's period does not
//! follow is refused with the reason.

use cnc_app::scenario::{InProcess, Scenario};

fn scenario(name: &str) -> Scenario {
    Scenario::load(&tests::cli::scenario(name)).unwrap_or_else(|e| panic!("{e}"))
}

fn run(s: &Scenario) -> InProcess {
    InProcess::run_through(s).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_timeline_fires_at_the_same_times_at_a_quarter_of_the_cycle() {
    let at_1ms = scenario("axes-plcopen");
    let mut at_quarter = at_1ms.clone();
    at_quarter.set_cycle_ms(0.25).unwrap();
    assert_eq!(at_quarter.ticks, Some(4 * at_1ms.ticks.unwrap()));
    let fired = |s: &Scenario| -> Vec<Option<u64>> {
        let run = run(s);
        let timeline = run.timeline.as_ref().unwrap();
        timeline
            .records()
            .iter()
            .map(|r| r.first_fired_at)
            .collect()
    };
    let (slow, fast) = (fired(&at_1ms), fired(&at_quarter));
    assert_eq!(slow.len(), fast.len());
    let mut timed = 0;
    for (i, (s, f)) in slow.iter().zip(&fast).enumerate() {
        let at = at_1ms_timeline_at(&at_1ms, i);
        if let (Some(at), Some(s), Some(f)) = (at, s, f) {
            // A step waiting for its tick fires at that time in both (the heartbeat it sees
            // is one tick after the tick it waited for at the most).
            if *s == at {
                assert_eq!(*f, 4 * at, "step {}", i + 1);
                timed += 1;
            }
        }
    }
    assert!(timed >= 2, "steps that fired on their at_tick: {timed}");
}

/// `at_tick` of step `i` of the scenario's timeline (ticks of its file's cycle).
fn at_1ms_timeline_at(s: &Scenario, i: usize) -> Option<u64> {
    let cnc_app::scenario::PlcSetup::Timeline { timeline, .. } = &s.plc else {
        return None;
    };
    timeline.at_ticks().nth(i).flatten()
}

#[test]
fn the_cam_program_waits_in_time_not_in_cycles() {
    let summary = |cycle_ms: f64, ticks: u64| {
        let mut s = scenario("cam-conveyor-program");
        s.set_cycle_ms(cycle_ms).unwrap();
        s.ticks = Some(ticks);
        let run = run(&s);
        run.program.as_ref().unwrap().0.summary()
    };
    let slow = summary(1.0, 1800);
    let fast = summary(0.25, 7200);
    assert!(slow.contains("Scale at cycle 1700"), "{slow}");
    assert!(fast.contains("Scale at cycle 6800"), "{fast}");
}

#[test]
fn the_plc_period_is_whole_cycles_or_refused() {
    let text = |period: &str| {
        format!(
            "cycle_ms = 1.0\nticks = 10\nplc_watchdog_ticks = 50\n[[axis]]\nname = \"A\"\n[plc]\ntimeline = \"t.toml\"\n{period}"
        )
    };
    let load = |toml: &str| {
        Scenario::parse("p.toml", toml, |f| {
            Ok((f.into(), "[[step]]\nat_tick = 1\n".to_string()))
        })
    };
    let e = load(&text("period_ms = 1.5\n")).unwrap_err().to_string();
    assert!(
        e.contains("[plc] period_ms: 1.5 ms is not a whole number of CNC cycles of 1 ms"),
        "{e}"
    );
    let mut s = load(&text("period_ms = 2.0\n")).unwrap();
    assert_eq!(s.plc_period_ticks(), 2);
    s.set_cycle_ms(0.5).unwrap();
    assert_eq!((s.plc_period_ticks(), s.ticks), (4, Some(20)));
    assert_eq!(s.plc_watchdog_ticks, Some(100), "50 ms of watchdog");
    let e = s.set_cycle_ms(0.3).unwrap_err();
    assert!(
        e.contains("([plc] period_ms) does not follow it: 2 ms is not a whole number of CNC cycles of 0.3 ms"),
        "{e}"
    );
    assert_eq!(s.cycle_s, 0.0005, "a refused cycle changes nothing");
    assert!(s
        .set_cycle_ms(0.01)
        .unwrap_err()
        .contains("must lie in 0.05..=100"));
}

/// A PLC task every 2nd tick: the timeline runs after ticks 0, 2, 4, ... only, so a step
/// due at tick 3 fires at the heartbeat of the cycle after it.
#[test]
fn an_in_process_plc_task_runs_every_period() {
    let toml = "cycle_ms = 1.0\nticks = 10\n[[axis]]\nname = \"A\"\n[plc]\ntimeline = \"t.toml\"\nperiod_ms = 2.0\n";
    let s = Scenario::parse("p.toml", toml, |f| {
        Ok((f.into(), "[[step]]\nat_tick = 4\n".to_string()))
    })
    .unwrap();
    let run = run(&s);
    let fired = run.timeline.as_ref().unwrap().records()[0].first_fired_at;
    assert_eq!(
        fired,
        Some(5),
        "heartbeats 1, 3, 5: the first at or after 4"
    );
}
