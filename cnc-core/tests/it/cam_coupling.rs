//! The coupling law of chapter 4.3 against hand-computed values (every start mode, linear and
//! cyclic with stroke, offsets and scalings), the chain rule for the slave's derivatives, a
//! cyclic cam over many periods without drift, the validity tables of 5.1.16.13, and the
//! automatic offsets of 5.1.16.14.

use cnc_core::cam::coupling::{
    check_couple, check_not_passed, check_scaling, check_switch, Activation, CamLaw, CouplingError,
    Scaling,
};
use cnc_core::cam::online::MasterNow;
use cnc_core::cam::{CamProfile, PositionTable, ProfileCursor, TableType};
use cnc_core::setpoint::Kinematic;
use hli::calls::cam::CamInterpolation;
use hli::calls::cam::{CamScalingMode, CamStartMode};
use proptest::prelude::*;

/// T(x) = x / 2 on 0..100: period 100, stroke 50.
fn ramp() -> CamProfile {
    CamProfile::Table(
        PositionTable::new(
            &[[0.0, 0.0], [100.0, 50.0]],
            TableType::Equidistant,
            CamInterpolation::Linear,
            false,
        )
        .unwrap(),
    )
}

/// One period of a sine-like stroke-free cam on 0..360 (a motion-law free table).
fn wave() -> CamProfile {
    let rows: Vec<[f64; 2]> = (0..=36)
        .map(|i| {
            let x = i as f64 * 10.0;
            [x, 20.0 * (x.to_radians()).sin()]
        })
        .collect();
    CamProfile::Table(
        PositionTable::new(
            &rows,
            TableType::Equidistant,
            CamInterpolation::Spline,
            false,
        )
        .unwrap(),
    )
}

const SCALED: Scaling = Scaling {
    master_offset: 10.0,
    slave_offset: 5.0,
    master_scaling: 2.0,
    slave_scaling: 3.0,
};

fn at(position: f64) -> Kinematic {
    Kinematic {
        position,
        ..Kinematic::default()
    }
}

fn slave(law: &CamLaw, profile: &CamProfile, master: Kinematic) -> Kinematic {
    law.slave(profile, &mut ProfileCursor::default(), &master).0
}

#[test]
fn linear_law_in_every_start_mode_by_hand() {
    let p = ramp();
    // Coupled with the master at 20 and the slave at 7 (used by the relative sides only).
    let law = |start| CamLaw::new(&p, SCALED, start, false, 20.0, 7.0);
    // Master absolute: x = (10 + 50) / 2 = 30, T = 15. Relative: x = (10 + 50 - 20) / 2 = 20.
    let cases = [
        (CamStartMode::Absolute, 5.0 + 3.0 * 15.0),
        (CamStartMode::MasterRelSlaveAbs, 5.0 + 3.0 * 10.0),
        (CamStartMode::MasterAbsSlaveRel, 7.0 + 5.0 + 3.0 * 15.0),
        (CamStartMode::Relative, 7.0 + 5.0 + 3.0 * 10.0),
    ];
    for (start, expected) in cases {
        assert_eq!(
            slave(&law(start), &p, at(50.0)).position,
            expected,
            "{start:?}"
        );
    }
    // Outside the range a linear cam holds its edge value, at rest: x = 130 -> T(100) = 50.
    let edge = slave(&law(CamStartMode::Absolute), &p, at(250.0));
    assert_eq!((edge.position, edge.velocity), (5.0 + 150.0, 0.0));
    let below = slave(&law(CamStartMode::Absolute), &p, at(-100.0));
    assert_eq!(below.position, 5.0);
}

#[test]
fn cyclic_law_adds_the_scaled_stroke_per_cycle_by_hand() {
    let p = ramp();
    let law = CamLaw::new(&p, SCALED, CamStartMode::Absolute, true, 0.0, 0.0);
    // x = (10 + 250) / 2 = 130: cycle 1, local 30, T = 15 + 50.
    let (s, c) = law.slave(&p, &mut ProfileCursor::default(), &at(250.0));
    assert_eq!((c.cycle, c.local), (1, 30.0));
    assert_eq!(s.position, 5.0 + 3.0 * 65.0);
    // x = (10 - 100) / 2 = -45: cycle -1, local 55, T = 27.5 - 50.
    let (s, c) = law.slave(&p, &mut ProfileCursor::default(), &at(-100.0));
    assert_eq!((c.cycle, c.local), (-1, 55.0));
    assert_eq!(s.position, 5.0 + 3.0 * -22.5);
    // Relative master and slave: measured from the coupling positions 20 and 7.
    let rel = CamLaw::new(&p, SCALED, CamStartMode::Relative, true, 20.0, 7.0);
    // x = (10 + 250 - 20) / 2 = 120: cycle 1, local 20, T = 10 + 50.
    assert_eq!(slave(&rel, &p, at(250.0)).position, 7.0 + 5.0 + 3.0 * 60.0);
}

#[test]
fn the_slave_derivatives_follow_the_chain_rule() {
    let p = wave();
    let law = CamLaw::new(&p, SCALED, CamStartMode::Absolute, true, 0.0, 0.0);
    let master = Kinematic {
        position: 123.0,
        velocity: 40.0,
        acceleration: -300.0,
        jerk: 5000.0,
    };
    let s = slave(&law, &p, master);
    // Central differences of the position along the master's own Taylor expansion.
    let h = 1e-4;
    let along = |t: f64| {
        let m = master.position
            + master.velocity * t
            + master.acceleration * t * t / 2.0
            + master.jerk * t * t * t / 6.0;
        slave(&law, &p, at(m)).position
    };
    let v = (along(h) - along(-h)) / (2.0 * h);
    let a = (along(h) - 2.0 * along(0.0) + along(-h)) / (h * h);
    assert!(
        (s.velocity - v).abs() < 1e-6 * v.abs().max(1.0),
        "{} vs {v}",
        s.velocity
    );
    assert!(
        (s.acceleration - a).abs() < 1e-3 * a.abs().max(1.0),
        "{} vs {a}",
        s.acceleration
    );
}

#[test]
fn a_cyclic_cam_over_ten_thousand_periods_keeps_its_count_and_does_not_drift() {
    let p = ramp();
    let law = CamLaw::new(&p, SCALED, CamStartMode::Absolute, true, 0.0, 0.0);
    let mut cursor = ProfileCursor::default();
    // 1 ms ticks at 2000 units/s: x advances 1 per tick; 10_000 periods of 100.
    let mut last_cycle = i64::MIN;
    for tick in 0..1_000_000u64 {
        let m = tick as f64 * 2.0 - 10.0;
        let (s, c) = law.slave(&p, &mut cursor, &at(m));
        let x = (10.0 + m) / 2.0;
        // T(local) + 50 * cycle is x / 2 here: the closed form.
        assert!((s.position - (5.0 + 1.5 * x)).abs() < 1e-9, "tick {tick}");
        assert!(c.cycle >= last_cycle);
        assert_eq!(c.cycle, (x / 100.0).floor() as i64);
        last_cycle = c.cycle;
    }
    assert_eq!(last_cycle, 9_999);
}

proptest! {
    #[test]
    fn a_cyclic_slave_is_continuous_in_the_master(
        m in -5000.0f64..5000.0,
        dm in -0.5f64..0.5,
        mo in -400.0f64..400.0,
        ms in prop_oneof![0.25f64..4.0, -4.0f64..-0.25],
        ss in -3.0f64..3.0,
    ) {
        let p = ramp();
        let scaling = Scaling { master_offset: mo, slave_offset: 1.0, master_scaling: ms, slave_scaling: ss };
        let law = CamLaw::new(&p, scaling, CamStartMode::Absolute, true, 0.0, 0.0);
        let a = slave(&law, &p, at(m)).position;
        let b = slave(&law, &p, at(m + dm)).position;
        // Slope 0.5 of the cam, scaled: no jump at any cycle boundary.
        let bound = 0.5 * (ss / ms).abs() * dm.abs() + 1e-9 * (1.0 + a.abs());
        prop_assert!((b - a).abs() <= bound, "{a} -> {b} over {dm}");
    }
}

#[test]
fn coupling_modes_follow_the_seeds_table() {
    use Activation::*;
    let abs = CamStartMode::Absolute;
    let rel = CamStartMode::Relative;
    let modes = [
        Instantaneous,
        AtMasterAxisPos(1.0),
        AtMasterCamPos(1.0),
        NextCycle,
        DeleteQueuedData,
    ];
    // Rows: the modes above; columns: absolute, relative (no master auto-offset).
    let couple = [
        (true, true),
        (true, true),
        (true, false),
        (true, false),
        (false, false),
    ];
    let switch = [(true, true); 5];
    for (mode, (a, r)) in modes.iter().zip(couple) {
        assert_eq!(
            check_couple(*mode, abs, false).is_ok(),
            a,
            "couple {mode:?} abs"
        );
        assert_eq!(
            check_couple(*mode, rel, false).is_ok(),
            r,
            "couple {mode:?} rel"
        );
        // With master auto-offset nothing couples.
        assert!(check_couple(*mode, abs, true).is_err());
        assert!(check_couple(*mode, rel, true).is_err());
    }
    for (mode, (a, r)) in modes.iter().zip(switch) {
        assert_eq!(
            check_switch(*mode, abs, false).is_ok(),
            a,
            "switch {mode:?} abs"
        );
        assert_eq!(
            check_switch(*mode, rel, false).is_ok(),
            r,
            "switch {mode:?} rel"
        );
        // With master auto-offset: absolute only.
        assert!(check_switch(*mode, abs, true).is_ok());
        assert!(check_switch(*mode, rel, true).is_err());
    }
    // The master-relative start modes count as relative, the master-absolute ones not.
    assert!(check_couple(NextCycle, CamStartMode::MasterRelSlaveAbs, false).is_err());
    assert!(check_couple(NextCycle, CamStartMode::MasterAbsSlaveRel, false).is_ok());
    // Scaling: the five modes of its table; the others refused with the combination.
    for mode in [
        Instantaneous,
        AtMasterCamPos(0.0),
        AtMasterAxisPos(0.0),
        NextCycle,
        Off,
    ] {
        assert!(check_scaling(mode, abs, true).is_ok(), "{mode:?}");
    }
    for mode in [NextCycleOnce, AsSoonAsPossible, DeleteQueuedData] {
        assert_eq!(
            check_scaling(mode, abs, false),
            Err(CouplingError::Combination {
                activation: mode.mode().raw(),
                start: 1,
                master_auto: false,
                when: "scaling",
            })
        );
    }
    assert!(check_scaling(Instantaneous, rel, true).is_err());
}

#[test]
fn an_axis_position_behind_the_master_is_refused() {
    let moving_up = MasterNow {
        axis: (99.0, 100.0),
        ..MasterNow::default()
    };
    assert!(check_not_passed(Activation::AtMasterAxisPos(150.0), moving_up).is_ok());
    assert_eq!(
        check_not_passed(Activation::AtMasterAxisPos(50.0), moving_up),
        Err(CouplingError::Passed {
            position: 50.0,
            master: 100.0
        })
    );
    let moving_down = MasterNow {
        axis: (101.0, 100.0),
        ..MasterNow::default()
    };
    assert!(check_not_passed(Activation::AtMasterAxisPos(50.0), moving_down).is_ok());
}

#[test]
fn master_auto_offset_keeps_the_share_of_the_cycle() {
    // The seed's example: a 360 cam scaled by 2 at 90 (25 %) stays at 25 % of its now 720.
    let p = wave();
    let law = CamLaw::new(
        &p,
        Scaling::default(),
        CamStartMode::Absolute,
        true,
        0.0,
        0.0,
    );
    let twice = Scaling {
        master_scaling: 2.0,
        ..Scaling::default()
    };
    let modes = (CamScalingMode::AutoOffset, CamScalingMode::Off);
    let scaled = law.rescaled(
        &p,
        twice,
        modes,
        CamStartMode::Absolute,
        true,
        90.0,
        0.0,
        false,
        None,
    );
    assert_eq!(scaled.locate(90.0).local, 90.0);
    // From here the master needs 720 to run through the cam once: 180 more to the middle.
    assert!((scaled.locate(90.0 + 270.0).local - 225.0).abs() < 1e-9);
    assert_eq!(scaled.scaling.master_offset, 90.0);
}

#[test]
fn slave_auto_offset_keeps_the_slave_where_it_is() {
    let p = wave();
    let law = CamLaw::new(
        &p,
        Scaling::default(),
        CamStartMode::Absolute,
        true,
        0.0,
        0.0,
    );
    let before = slave(&law, &p, at(200.0)).position;
    // The seed's second example: MasterOffset 10 (a phase shift) with slave auto-offset.
    let shifted = Scaling {
        master_offset: 10.0,
        ..Scaling::default()
    };
    let modes = (CamScalingMode::UserDefined, CamScalingMode::AutoOffset);
    let after = law.rescaled(
        &p,
        shifted,
        modes,
        CamStartMode::Absolute,
        true,
        200.0,
        before,
        false,
        None,
    );
    assert_eq!(after.scaling.master_offset, 10.0);
    assert!((slave(&after, &p, at(200.0)).position - before).abs() < 1e-12);
    // Without it the slave would jump by T(210) - T(200).
    let user = law.rescaled(
        &p,
        shifted,
        (CamScalingMode::UserDefined, CamScalingMode::UserDefined),
        CamStartMode::Absolute,
        true,
        200.0,
        before,
        false,
        None,
    );
    assert!((slave(&user, &p, at(200.0)).position - before).abs() > 1.0);
    // Slave scaling 0 with Off on the master stops the slave's motion while coupled (the
    // seed's first example): the position holds wherever the master goes.
    let frozen = Scaling {
        slave_scaling: 0.0,
        ..Scaling::default()
    };
    let held = law.rescaled(
        &p,
        frozen,
        (CamScalingMode::Off, CamScalingMode::AutoOffset),
        CamStartMode::Absolute,
        true,
        200.0,
        before,
        false,
        None,
    );
    for m in [200.0, 250.0, 1000.0] {
        assert!((slave(&held, &p, at(m)).position - before).abs() < 1e-12);
    }
}

#[test]
fn bad_scalings_are_refused_with_the_value() {
    for (s, what) in [
        (
            Scaling {
                master_scaling: 0.0,
                ..Scaling::default()
            },
            "master scaling",
        ),
        (
            Scaling {
                slave_offset: f64::NAN,
                ..Scaling::default()
            },
            "slave offset",
        ),
        (
            Scaling {
                master_offset: f64::INFINITY,
                ..Scaling::default()
            },
            "master offset",
        ),
    ] {
        match s.check() {
            Err(CouplingError::Parameter { what: w, .. }) => assert_eq!(w, what),
            other => panic!("{other:?}"),
        }
    }
    assert!(SCALED.check().is_ok());
}

#[test]
fn a_slave_couples_in_the_base_cycle_wherever_the_master_stands() {
    // Seed 5.1.4: coupled with the master three periods on, the stroke counts from there.
    let p = ramp();
    let law = CamLaw::new(&p, SCALED, CamStartMode::Absolute, true, 650.0, 0.0);
    // x = (10 + 650) / 2 = 330: cycle 3, local 30; at coupling no stroke is added.
    assert_eq!(slave(&law, &p, at(650.0)).position, 5.0 + 3.0 * 15.0);
    assert_eq!(law.cycles_since_coupling(650.0), 0);
    // One period later (200 master units): one stroke of 50, scaled.
    assert_eq!(
        slave(&law, &p, at(850.0)).position,
        5.0 + 3.0 * (15.0 + 50.0)
    );
    assert_eq!(law.cycles_since_coupling(850.0), 1);
    // Before the coupling position: the cycle before the base one.
    assert_eq!(
        slave(&law, &p, at(450.0)).position,
        5.0 + 3.0 * (15.0 - 50.0)
    );
}

#[test]
fn master_auto_offset_keeps_the_share_when_switching_to_another_period() {
    // From a 360 cam at 90 (25 % into its second cycle) to a 100 cam scaled by 2 (200 of the
    // master per cycle): the master stands 25 % into the new cam's cycle, cycles counted on.
    let p = wave();
    let law = CamLaw::new(
        &p,
        Scaling::default(),
        CamStartMode::Absolute,
        true,
        0.0,
        0.0,
    );
    let master = 360.0 + 90.0;
    let next = ramp();
    let scaling = Scaling {
        master_scaling: 2.0,
        ..Scaling::default()
    };
    let modes = (CamScalingMode::AutoOffset, CamScalingMode::AutoOffset);
    let before = slave(&law, &p, at(master)).position;
    let switched = law.rescaled(
        &next,
        scaling,
        modes,
        CamStartMode::Absolute,
        true,
        master,
        before,
        true,
        None,
    );
    let c = switched.locate(master);
    assert!((c.local - 25.0).abs() < 1e-9, "{c:?}");
    assert_eq!(switched.cycles_since_coupling(master), 1);
    // The slave does not jump, and the new cam runs 0.25 of a slave unit per master unit.
    assert!((slave(&switched, &next, at(master)).position - before).abs() < 1e-9);
    let later = slave(&switched, &next, at(master + 20.0)).position;
    assert!(
        (later - before - 20.0 * 0.5 / 2.0).abs() < 1e-9,
        "{}",
        later - before
    );
}

/// NextCycle chaining of linear cams (seed 000: a linear cam's cycle ends at its range edges;
/// master and slave auto-offset make the next join seamlessly): the ramp T(x) = x / 2 on
/// 0..100 switched to itself at every end, the master at 0.02 a tick. The next cam is anchored
/// on the edge, so the slave is x / 2 on every tick across three switches (before, each
/// switch started one tick's travel into the new range and the slave fell 0.01 behind).
/// Backwards past the start the previous cycle's end is taken the same way.
#[test]
fn linear_cams_chained_at_next_cycle_join_exactly_at_their_edges() {
    let p = ramp();
    let modes = (CamScalingMode::AutoOffset, CamScalingMode::AutoOffset);
    for dir in [1.0, -1.0] {
        let mut law = CamLaw::new(
            &p,
            Scaling::default(),
            CamStartMode::Absolute,
            false,
            0.0,
            0.0,
        );
        let (mut master, mut switches) = (if dir > 0.0 { 0.0 } else { 100.0 }, 0);
        let start = master;
        for _ in 0..16_000 {
            let before = master;
            master += 0.02 * dir;
            let now = law.master_now(before, master);
            if now.cycle_changed {
                let set = slave(&law, &p, at(master)).position;
                law = law.rescaled(
                    &p,
                    Scaling::default(),
                    modes,
                    CamStartMode::Absolute,
                    false,
                    master,
                    set,
                    true,
                    now.edge,
                );
                switches += 1;
            }
            let s = slave(&law, &p, at(master)).position;
            let expected = (master - start) / 2.0 + if dir > 0.0 { 0.0 } else { 50.0 };
            assert!(
                (s - expected).abs() < 1e-9,
                "master {master}: {s} vs {expected}"
            );
        }
        assert_eq!(switches, 3, "{dir}");
    }
}
