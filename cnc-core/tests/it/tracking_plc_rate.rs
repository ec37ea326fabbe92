//! A PLC master whose task runs every N-th NC tick (`plc --period-ticks N`) writes a new frame
//! only every N ticks. Its motion is carried on between its cycles, so a slave follows a
//! master moving at a steady speed without a catch-up, every tick within its axes' limits.

use tests::channel_rig as support;

use hli::enums::DynCsState;
use hli::views::{CncView, PlcView};
use support::{cartesian, controller, cs, image, CYCLE};

/// A PLC master that writes every `period` ticks and moves X at 200 mm/s from 0.3 s on,
/// followed for 1.5 s: the slave's largest acceleration, its largest distance from the
/// master's line once caught up, and the axis's acceleration limit.
fn run(period: u32) -> (f64, f64, f64) {
    let config = cartesian("slave");
    let limits = config.axis_limits(0);
    let mut ctl = controller(vec![(
        config,
        "#TRACK CS ON [ID=0 FILTER=0 WAIT]\n#TIME 5\nM30\n",
    )]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    let (mut last, mut last_v, mut worst_a, mut worst_lag) = (0.0, 0.0, 0.0f64, 0.0f64);
    for tick in 0..1500u32 {
        let x = if tick < 300 {
            0.0
        } else {
            200.0 * f64::from(tick - 300) * CYCLE
        };
        if tick % period == 0 {
            let frame = cs([(x * 1e4).round() as i32, 0, 0]);
            plc.dyn_cs_command(0).unwrap().try_send(&frame).unwrap();
        }
        ctl.tick(&view);
        let p = ctl.channels()[0].set_points()[0];
        let v = (p - last) / CYCLE;
        assert!(v.abs() <= limits.velocity * 1.000_001, "tick {tick}: v {v}");
        worst_a = worst_a.max(((v - last_v) / CYCLE).abs());
        if tick > 400 {
            worst_lag = worst_lag.max((p - x).abs());
        }
        (last, last_v) = (p, v);
    }
    let ch = &ctl.channels()[0];
    assert!(ch.error().is_none(), "period {period}: {:?}", ch.error());
    assert_eq!(ch.tracker().state(), DynCsState::Active);
    (worst_a, worst_lag, limits.acceleration)
}

#[test]
fn a_master_written_every_few_ticks_is_followed_on_a_line_within_the_limits() {
    for period in [1, 2, 3, 4] {
        let (worst_a, worst_lag, limit) = run(period);
        assert!(worst_a <= limit * 1.01, "period {period}: a {worst_a}");
        // Steady motion: on the master, up to the 0.1 um of the frame's integers.
        assert!(worst_lag < 1e-3, "period {period}: lag {worst_lag} mm");
    }
}
