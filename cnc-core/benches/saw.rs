//! What planning a flying-saw command costs, beside rsruckig planning the same velocity
//! change in the same run.
//!
//! 1. **GearInPos planning.** `saw::plan` for MC_GearInPos commands from a set of slave
//!    states onto a master at 500 mm/s (the seed's position examples and variations: P5+P1,
//!    P1+P5, P5-P1-P5 with PREFERCONSTVELO, the plain P5 capped at a velocity limit), each
//!    with its characteristic values and every check on: what the CNC does between two ticks
//!    when the PLC's Execute edge arrives. Target: <= 20 us per command.
//! 2. **GearInVelo time-based planning** (our jerk-limited phase) for the same velocity
//!    changes.
//! 3. **rsruckig**, the peer: one `Ruckig::calculate` of the same velocity change (from the
//!    slave's velocity to ratio x master velocity, same acceleration and jerk, velocity
//!    interface), the time-optimal jerk-limited profile without positions to meet.
//!
//! Each figure is the median over 21 interleaved repeats of a batch of 2,000 commands
//! (the three measured in turn within every repeat); the ratio is ours / rsruckig's.
//! Run: `cargo bench -p cnc-core --bench saw`.

use bench_kit::{median, scaled};
use cnc_core::saw::{self, Limits, SawRequest, SyncOn};
use cnc_core::setpoint::Kinematic;
use hli::calls::saw::sync_mask as m;
use rsruckig::prelude::*;
use std::hint::black_box;
use std::time::Instant;

const BATCH: usize = 2000;
const REPEATS: usize = 21;

fn kin(position: f64, velocity: f64) -> Kinematic {
    Kinematic {
        position,
        velocity,
        acceleration: 0.0,
        jerk: 0.0,
    }
}

/// (slave position, slave velocity, slave sync position, mask) onto a master at 0 with
/// 500 mm/s and sync at master 1500.
const CASES: [(f64, f64, f64, u32); 5] = [
    (250.0, 250.0, 1500.0, 0),
    (0.0, -250.0, 1000.0, 0),
    (0.0, 500.0, 1700.0, m::PREFERCONSTVELO),
    (0.0, 250.0, 600.0, 0),
    (0.0, 500.0, 2600.0, m::MAXVELO),
];

fn limits() -> Limits {
    Limits {
        velocity: 1200.0,
        acceleration: 2500.0,
        deceleration: 2500.0,
        jerk: 1e5,
    }
}

fn all_checks() -> u32 {
    m::MAXVELO | m::MAXACC | m::MAXDEC | m::MAXJERK
}

fn gear_in_pos(k: usize) -> f64 {
    let (s0, vs, ss, mask) = CASES[k % CASES.len()];
    let req = SawRequest {
        on: SyncOn::Position {
            master: 1500.0,
            slave: ss,
        },
        time_based: false,
        mask,
        ratio: 1.0,
        limits: limits(),
    };
    let plan = saw::plan(&req, &kin(0.0, 500.0), &kin(s0, vs), Some([-1e6, 1e6]));
    plan.map_or(0.0, |p| p.profile.length)
}

fn gear_in_velo(k: usize) -> f64 {
    let (s0, vs, _, _) = CASES[k % CASES.len()];
    let req = SawRequest {
        on: SyncOn::Velocity,
        time_based: true,
        mask: all_checks(),
        ratio: 1.0,
        limits: limits(),
    };
    let plan = saw::plan(&req, &kin(0.0, 500.0), &kin(s0, vs), None);
    plan.map_or(0.0, |p| p.profile.length)
}

struct Peer {
    otg: Ruckig<1, ThrowErrorHandler>,
    input: InputParameter<1>,
    trajectory: Trajectory<1>,
}

impl Peer {
    fn new() -> Peer {
        let one = |v: f64| DataArrayOrVec::Stack([v]);
        let mut input = InputParameter::<1>::new(None);
        input.control_interface = ControlInterface::Velocity;
        input.current_position = one(0.0);
        input.current_acceleration = one(0.0);
        input.target_velocity = one(500.0);
        input.target_acceleration = one(0.0);
        input.max_velocity = one(1200.0);
        input.max_acceleration = one(2500.0);
        input.min_acceleration = Some(one(-2500.0));
        input.max_jerk = one(1e5);
        Peer {
            otg: Ruckig::new(None, 0.001),
            input,
            trajectory: Trajectory::new(None),
        }
    }

    fn plan(&mut self, k: usize) -> f64 {
        let (_, vs, _, _) = CASES[k % CASES.len()];
        self.input.current_velocity = DataArrayOrVec::Stack([vs]);
        match self.otg.calculate(&self.input, &mut self.trajectory) {
            Ok(_) => self.trajectory.get_duration(),
            Err(_) => 0.0,
        }
    }
}

fn time_batch(mut f: impl FnMut(usize) -> f64) -> f64 {
    let start = Instant::now();
    let mut sink = 0.0;
    for k in 0..scaled(BATCH) {
        sink += f(black_box(k));
    }
    black_box(sink);
    start.elapsed().as_secs_f64() / scaled(BATCH) as f64 * 1e6
}

fn main() {
    // Every case plans (a refused one would measure the refusal).
    for k in 0..CASES.len() {
        assert!(gear_in_pos(k) > 0.0, "case {k} refused");
    }
    let mut peer = Peer::new();
    let (mut pos, mut velo, mut theirs) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..scaled(REPEATS) {
        pos.push(time_batch(gear_in_pos));
        velo.push(time_batch(gear_in_velo));
        theirs.push(time_batch(|k| peer.plan(k)));
    }
    let (pos, velo, theirs) = (median(pos), median(velo), median(theirs));
    println!("flying saw planning, median of {REPEATS} interleaved repeats x {BATCH} commands");
    println!("  MC_GearInPos (position-based, characteristic values, checks): {pos:8.3} us/command (target <= 20 us)");
    println!(
        "  MC_GearInVelo time-based (jerk-limited, same):                {velo:8.3} us/command"
    );
    println!(
        "  rsruckig 3 velocity change (peer):                            {theirs:8.3} us/command"
    );
    println!("  ratio GearInPos / rsruckig: {:.2}", pos / theirs);
    println!(
        "  ratio GearInVelo time-based / rsruckig: {:.2}",
        velo / theirs
    );
    println!(
        "TARGET | MC_GearInPos planning <= 20 us per command | {pos:.3} us (rsruckig {theirs:.3} us) | {}",
        if pos <= 20.0 { "met" } else { "MISSED" }
    );
}
