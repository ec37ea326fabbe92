//! Evaluating a cam while the master sweeps allocates nothing: motion functions and tables
//! with every interpolation, linear and cyclic.

use cnc_core::cam::{
    CamProfile, FunctionType, MotionFunction, MotionFunctionPoint, PointType, PositionTable,
    ProfileCursor, TableType,
};
use hli::calls::cam::CamInterpolation;

use crate::counting_alloc;
use counting_alloc::{allocations, deallocations};

#[test]
fn sweeping_the_master_through_every_kind_of_profile_allocates_nothing() {
    // Rest points with alternating strokes, joined by every rest-to-rest and motion law (the
    // trigonometric ones included): a cam that really moves.
    use cnc_core::cam::law::EndKind;
    let laws: Vec<FunctionType> = FunctionType::all()
        .iter()
        .copied()
        .filter(|l| {
            matches!(
                l.ends(),
                (EndKind::Rest, EndKind::Rest) | (EndKind::Motion, EndKind::Motion)
            )
        })
        .collect();
    let points: Vec<MotionFunctionPoint> = (0..40)
        .map(|i| {
            let slave = if i % 2 == 0 { 0.0 } else { 5.0 };
            MotionFunctionPoint::new(
                i as u32 + 1,
                laws[i % laws.len()],
                PointType::Rest,
                i as f64 * 10.0,
                slave,
            )
        })
        .collect();
    let mut profiles = vec![CamProfile::MotionFunction(
        MotionFunction::new(&points).expect("valid"),
    )];
    let rows: Vec<[f64; 2]> = (0..1000)
        .map(|i| [i as f64 * 0.4, (i as f64 * 0.01).sin()])
        .collect();
    for interpolation in [
        CamInterpolation::Linear,
        CamInterpolation::FourPoint,
        CamInterpolation::Spline,
    ] {
        for periodic in [false, true] {
            for ty in [TableType::Equidistant, TableType::NonEquidistant] {
                if let Ok(t) = PositionTable::new(&rows, ty, interpolation, periodic) {
                    profiles.push(CamProfile::Table(t));
                }
            }
        }
    }
    assert_eq!(profiles.len(), 11);
    let before = allocations();
    let mut sum = 0.0;
    for p in &profiles {
        let mut cursor = ProfileCursor::default();
        for i in 0..100_000 {
            // Beyond both ends too (cyclic continuation, edge values).
            let x = -50.0 + i as f64 * 0.006;
            sum += p.eval(x, &mut cursor).position;
        }
    }
    assert_eq!(allocations() - before, 0, "allocations while evaluating");
    assert!(sum.is_finite());
}

/// The machine tick with a cam slave coupled to a running conveyor, through a rescaling and
/// an online point change that both apply at cycle boundaries inside the measured ticks,
/// allocates and frees nothing (what a change replaces is freed with the next call).
#[test]
fn the_machine_tick_with_a_coupled_cam_slave_allocates_nothing() {
    use cnc_app::scenario::{InProcess, Scenario};
    use hli::calls::cam::CamScalingCall;
    use hli::calls::AcyclicCall;
    use hli::enums::AxisState;
    let path = tests::cli::scenario("cam-conveyor");
    let s = Scenario::load(&path).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    // The PLC couples the lifter and starts the conveyor within the first ticks.
    for _ in 0..300 {
        run.step(s.cycle_s);
    }
    let slave = run.machine.axes().axis(1).unwrap();
    assert_eq!(
        slave.motion_state(slave.setpoint()),
        AxisState::SlaveSynchronous
    );
    // A rescaling for the next cycle, queued before the measured ticks.
    let scaling = CamScalingCall {
        activation_mode: 3,
        master_scaling_mode: 2,
        slave_scaling_mode: 1,
        slave_scaling: 0.5,
        master_scaling: 1.0,
        ..CamScalingCall::default()
    };
    let (body, body_len) = hli::wire::encode_body(&scaling);
    let request = hli::wire::AcyclicRequest {
        invoke_id: 9,
        kind: CamScalingCall::KIND.raw(),
        target: 1,
        body_len,
        body,
    };
    let view = hli::views::CncView::new(&run.memory);
    run.machine
        .dispatch(&view, CamScalingCall::KIND, &request)
        .unwrap();
    // A point change for the next cycle: point 4 of the seed's cam to 30.
    let send =
        |run: &mut InProcess, kind: hli::calls::CallKind, target: u32, body: ([u8; 240], u32)| {
            let request = hli::wire::AcyclicRequest {
                invoke_id: 10,
                kind: kind.raw(),
                target,
                body_len: body.1,
                body: body.0,
            };
            let view = hli::views::CncView::new(&run.memory);
            let (reply, len) = run.machine.dispatch(&view, kind, &request).unwrap();
            let reply: hli::calls::cam::CamReply =
                bytemuck::pod_read_unaligned(&reply[..len as usize]);
            assert_eq!(reply.error_id, 0);
        };
    let mode = hli::calls::cam::CamOnlineModeCall {
        activation_mode: 3,
        ..Default::default()
    };
    send(
        &mut run,
        hli::calls::CallKind::CAM_ONLINE_MODE,
        1,
        hli::wire::encode_body(&mode),
    );
    let write = hli::calls::cam::CamPointsWriteCall::one(crate::cam_engine::seed_point_4(30.0));
    send(
        &mut run,
        hli::calls::CallKind::CAM_POINTS_WRITE,
        1,
        hli::wire::encode_body(&write),
    );
    let mut top: f64 = 0.0;
    // MC_CamScaling's poll while its scaling waits (a `Queued` read each cycle), answered
    // between the ticks as the loop's acyclic part does: counted too.
    let (body, body_len) = hli::wire::encode_body(&hli::calls::cam::CamReadCall {
        what: hli::calls::cam::CamReadKind::Queued.raw(),
        ..Default::default()
    });
    let poll = hli::wire::AcyclicRequest {
        invoke_id: 11,
        kind: hli::calls::CallKind::CAM_READ.raw(),
        target: 1,
        body_len,
        body,
    };
    let mut waited = 0;
    let (mut tick_allocs, mut tick_frees, mut poll_allocs) = (0, 0, 0);
    for tick in 0..3000 {
        let (a, f) = (allocations(), deallocations());
        run.machine.tick(&run.memory);
        tick_allocs += allocations() - a;
        tick_frees += deallocations() - f;
        let a = allocations();
        let view = hli::views::CncView::new(&run.memory);
        let (reply, len) = run
            .machine
            .dispatch(&view, hli::calls::CallKind::CAM_READ, &poll)
            .unwrap();
        let reply: hli::calls::cam::CamValuesReply =
            bytemuck::pod_read_unaligned(&reply[..len as usize]);
        waited += usize::from(reply.values[0] == 1.0);
        poll_allocs += allocations() - a;
        if tick >= 2000 {
            top = top.max(run.machine.axes().axis(1).unwrap().setpoint().position);
        }
    }
    assert_eq!(
        tick_allocs, 0,
        "{tick_allocs} allocations in 3000 machine ticks"
    );
    assert_eq!(tick_frees, 0, "{tick_frees} frees in 3000 machine ticks");
    // The polls allocate nothing; a call frees, between ticks, what the ticks retired (the
    // replaced profiles: a handful, not one per poll).
    assert_eq!(poll_allocs, 0, "{poll_allocs} allocations in 3000 polls");
    assert!(
        waited > 0 && waited < 3000,
        "the scaling waited, then activated: {waited}"
    );
    // The full stroke reaches about 42; halved about 21; halved with point 4 at 30 about 15.
    assert!(top > 12.0 && top < 17.0, "top of the last turn {top}");
    // Three turns of the conveyor went by, the stroke halved on the way.
    let lifter = run.machine.axes().axis(1).unwrap();
    assert_eq!(
        lifter.motion_state(lifter.setpoint()),
        AxisState::SlaveSynchronous
    );
}
