//! Table data in chunks, points, reads, the multi-table operations, and a transfer cut by a
//! stop.

use super::*;

#[test]
fn a_table_of_100000_rows_arrives_in_chunks_and_a_coupling_runs_on_it() {
    let mut run = machine();
    run.step();
    let total = 100_000;
    let rows: Vec<[f64; 2]> = (0..total)
        .map(|i| {
            [
                i as f64 * 0.0036,
                5.0 * (i as f64 / (total - 1) as f64 * std::f64::consts::TAU).sin(),
            ]
        })
        .collect();
    let chunks: Vec<&[[f64; 2]]> = rows.chunks(hli::calls::cam::CAM_ROWS_PER_CALL).collect();
    for (k, chunk) in chunks.iter().enumerate() {
        let first = k * hli::calls::cam::CAM_ROWS_PER_CALL;
        let last = k + 1 == chunks.len();
        let reply = answer(&mut run, 5, &rows_chunk(chunk, first, total, last));
        assert_eq!(reply.error_id, 0, "chunk {k}");
        if k % 1000 == 0 {
            // The machine ticks on between chunks: the upload never holds a tick up.
            run.step();
        }
    }
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(5)), 0);
    run_master(&mut run, 360.0);
    for _ in 0..3000 {
        run.step();
        assert!(run.axis(SLAVE).error().is_none());
    }
    // The slave follows the uploaded wave (period 360, amplitude 5).
    let m = set(&run, MASTER).position;
    let expected = 5.0 * ((m.rem_euclid(360.0)) / 360.0 * std::f64::consts::TAU).sin();
    assert!(
        (set(&run, SLAVE).position - expected).abs() < 1e-3,
        "{} vs {expected}",
        set(&run, SLAVE).position
    );
    // A coupled table is not replaced.
    let one = rows_chunk(&rows[..13], 0, 13, true);
    let reply = answer(&mut run, 5, &one);
    assert_eq!(reply.error_id, CamCouplingError::TableInUse.raw());
}

#[test]
fn chunks_out_of_order_and_bad_tables_are_refused_whole() {
    let mut run = machine();
    run.step();
    let rows: Vec<[f64; 2]> = (0..26).map(|i| [i as f64, 0.0]).collect();
    let first = rows_chunk(&rows[..13], 0, 26, false);
    let skipped = rows_chunk(&rows[..13], 20, 26, true);
    assert_eq!(rows_answer(&mut run, 7, &first), 0);
    assert_eq!(
        rows_answer(&mut run, 7, &skipped),
        CamCouplingError::ChunkOutOfOrder.raw()
    );
    // Nothing was stored: table 7 does not exist.
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(7)), 0x4B32);
    // A table whose masters do not rise: refused with the table code, nothing stored.
    let mut bad = rows.clone();
    bad[5][0] = 1.0;
    assert_eq!(
        rows_answer(&mut run, 7, &rows_chunk(&bad[..13], 0, 26, false)),
        0
    );
    let reply = rows_answer(&mut run, 7, &rows_chunk(&bad[13..], 13, 26, true));
    assert!((0x4B30..=0x4B38).contains(&reply), "{reply:#x}");
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(7)), 0x4B32);
}

#[test]
fn points_read_back_and_a_refused_write_leaves_the_function() {
    use hli::calls::cam::{CamPointsReadCall, CamPointsReply, McMotionFunctionPoint};
    let mut run = machine();
    run.step();
    let read = |run: &mut Harness, first: u32| -> CamPointsReply {
        answer(run, 1, &CamPointsReadCall { first, count: 0 })
    };
    let r = read(&mut run, 1);
    assert_eq!((r.error_id, r.count, r.total), (0, 4, 6));
    assert_eq!(r.points[3].master_pos, 240.0);
    assert_eq!(r.points[3].slave_pos, 40.0);
    let r = read(&mut run, 5);
    assert_eq!((r.count, r.points[1].master_pos), (2, 360.0));
    assert_eq!(read(&mut run, 7).error_id, 0x4B33);
    // A point whose master position breaks the monotonic order: refused whole.
    let mut p4: McMotionFunctionPoint = read(&mut run, 4).points[0];
    p4.master_pos = 400.0;
    let write = hli::calls::cam::CamPointsWriteCall::one(p4);
    let reply = answer(&mut run, 1, &write);
    assert!(
        (0x4B30..=0x4B38).contains(&reply.error_id),
        "{:#x}",
        reply.error_id
    );
    run.step();
    assert_eq!(read(&mut run, 4).points[0].master_pos, 240.0);
    // A good one applies (instantaneous mode, nothing coupled).
    p4.master_pos = 250.0;
    let write = hli::calls::cam::CamPointsWriteCall::one(p4);
    let reply = answer(&mut run, 1, &write);
    assert_eq!(reply.error_id, 0);
    run.step();
    assert_eq!(read(&mut run, 4).points[0].master_pos, 250.0);
}

#[test]
fn reads_give_dynamics_characteristics_value_tables_and_the_coupling_info() {
    use hli::calls::cam::{CamReadCall, CamReadKind};
    let mut run = machine();
    run.step();
    let seed = seed_cam();
    // Slave dynamics of the motion function: position, velocity, acceleration of the raw cam.
    let (v, _) = read_all(
        &mut run,
        1,
        CamReadCall {
            what: CamReadKind::SlaveDynamics.raw(),
            a: 90.0,
            ..Default::default()
        },
    );
    let s = seed.eval(90.0, &mut ProfileCursor::default());
    assert_eq!(v, vec![s.position, s.velocity, s.acceleration]);
    // An equidistant table gives no acceleration (seed 5.1.7).
    let (v, _) = read_all(
        &mut run,
        2,
        CamReadCall {
            what: CamReadKind::SlaveDynamics.raw(),
            a: 100.0,
            ..Default::default()
        },
    );
    assert_eq!(v[2], 0.0);
    assert!(v[1] != 0.0);
    // Characteristics: the 31 values of MC_TableCharacValues, then the organisation fields,
    // in two parts.
    let (v, _) = read_all(
        &mut run,
        1,
        CamReadCall {
            what: CamReadKind::Characteristics.raw(),
            ..Default::default()
        },
    );
    let expected: Vec<f64> = crate::cam::CharacValues::normed(&seed)
        .fields()
        .iter()
        .map(|(_, v)| *v)
        .collect();
    assert_eq!(v[..31], expected);
    // Table 1 is the seed's motion function: its points, one column, type 22.
    let org = hli::calls::cam::TableOrganisation::from_values(&v[31..]).unwrap();
    let points = match &seed {
        CamProfile::MotionFunction(f) => f.points().len() as u32,
        _ => unreachable!("table 1 is a motion function"),
    };
    assert_eq!((org.table_id, org.rows, org.columns), (1, points, 1));
    assert_eq!((org.table_type, org.periodic), (22, false));
    // Table 2, an equidistant position table: its rows, two columns, type 10.
    let (v, _) = read_all(
        &mut run,
        2,
        CamReadCall {
            what: CamReadKind::Characteristics.raw(),
            ..Default::default()
        },
    );
    let org = hli::calls::cam::TableOrganisation::from_values(&v[31..]).unwrap();
    assert_eq!((org.table_id, org.columns, org.table_type), (2, 2, 10));
    assert!(org.rows >= 2, "{org:?}");
    // Rescaled on the PLC path (seed 000 3.4): to a working master velocity, also a negative
    // one; a velocity that is not a number is refused.
    for velocity in [2.0, -2.0] {
        let (v, _) = read_all(
            &mut run,
            1,
            CamReadCall {
                what: CamReadKind::Characteristics.raw(),
                a: velocity,
                ..Default::default()
            },
        );
        let expected: Vec<f64> = crate::cam::CharacValues::normed(&seed)
            .rescaled(velocity)
            .unwrap()
            .fields()
            .iter()
            .map(|(_, v)| *v)
            .collect();
        assert_eq!(v[..31], expected, "at {velocity}");
        assert_eq!(v[0], velocity, "fMasterVeloNom");
    }
    let nan = answer(
        &mut run,
        1,
        &CamReadCall {
            what: CamReadKind::Characteristics.raw(),
            a: f64::NAN,
            ..Default::default()
        },
    );
    assert_eq!(nan.error_id, CamCouplingError::BadParameter.raw());
    // A value table of position and velocity from 0 to 360 in steps of 10: 37 rows of 3.
    let (v, columns) = read_all(
        &mut run,
        1,
        CamReadCall {
            what: CamReadKind::Values.raw(),
            mask: 3,
            a: 0.0,
            b: 360.0,
            c: 10.0,
            ..Default::default()
        },
    );
    assert_eq!((v.len(), columns), (111, 3));
    for row in v.chunks(3) {
        let s = seed.eval(row[0], &mut ProfileCursor::default());
        assert_eq!([row[1], row[2]], [s.position, s.velocity], "at {}", row[0]);
    }
    // The coupling info of a scaled coupling, at a master position given.
    let scaled = CamInCall {
        slave_scaling: 2.0,
        slave_offset: 1.0,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, scaled), 0);
    run.step();
    let (v, _) = read_all(
        &mut run,
        SLAVE as u32,
        CamReadCall {
            what: CamReadKind::Info.raw(),
            flags: 1,
            a: 90.0,
            ..Default::default()
        },
    );
    assert_eq!(v.len(), 40);
    assert_eq!(v[0], 1.0, "table");
    assert_eq!(v[1], 22.0, "a motion function");
    assert_eq!((v[4], v[5]), (6.0, 1.0), "points, columns");
    assert_eq!((v[6], v[8]), (0.0, 360.0), "master start, period");
    assert_eq!((v[15], v[17]), (1.0, 2.0), "slave offset, scaling");
    assert_eq!(v[20], 90.0, "at the master position given");
    assert_eq!(
        v[21],
        1.0 + 2.0 * s_at(&seed, 90.0),
        "slave set-point there"
    );
    assert_eq!(v[22], 90.0, "cam master coordinate");
    // Not coupled: refused.
    let reply = answer(
        &mut run,
        2,
        &CamReadCall {
            what: CamReadKind::Info.raw(),
            ..Default::default()
        },
    );
    assert_eq!(reply.error_id, CamCouplingError::NotCamCoupled.raw());
    // A kind of read that does not exist: refused as an unknown mode.
    for what in [0, 7] {
        let reply = answer(
            &mut run,
            1,
            &CamReadCall {
                what,
                ..Default::default()
            },
        );
        assert_eq!(
            reply.error_id,
            CamCouplingError::UnknownMode.raw(),
            "what {what}"
        );
    }
}

#[test]
fn a_multi_table_call_refuses_an_operation_it_does_not_have() {
    use hli::calls::cam::{CamMultiTableCall, CamMultiTableOp};
    let mut run = machine();
    run.step();
    assert_eq!(call(&mut run, SLAVE as u32, multi_couple(2, 0)), 0);
    let on_table = |op, table| CamMultiTableCall {
        op,
        table,
        ..CamMultiTableCall::default()
    };
    for op in [0, 3] {
        let refused = call(&mut run, SLAVE as u32, on_table(op, 2));
        assert_eq!(refused, CamCouplingError::UnknownMode.raw(), "op {op}");
    }
    // A known operation gets as far as the table: one the slave does not use is refused.
    let enable = on_table(CamMultiTableOp::EnableCorrection.raw(), 9);
    let refused = call(&mut run, SLAVE as u32, enable);
    assert_eq!(
        refused,
        crate::cam::TableErrorCode::CamTableIdInvalid as u32
    );
}

fn s_at(p: &CamProfile, x: f64) -> f64 {
    p.eval(x, &mut ProfileCursor::default()).position
}

#[test]
fn a_transfer_cut_between_chunks_by_a_lost_plc_is_dropped_with_the_stop() {
    // A PLC lost between two chunks (docs/reliability.md): the first chunk was taken, the last
    // never comes, and the machine stops. A new PLC that sends the missing chunk must not
    // complete a table half of which is the old PLC's: the stop dropped the transfer.
    let mut run = machine();
    run.step();
    let rows: Vec<[f64; 2]> = (0..26).map(|i| [i as f64 * 10.0, 0.0]).collect();
    assert_eq!(
        rows_answer(&mut run, 7, &rows_chunk(&rows[..13], 0, 26, false)),
        0
    );
    run.machine.stop("machine stop: PLC lost");
    for _ in 0..2000 {
        run.step();
        if run.machine.at_rest() {
            break;
        }
    }
    assert!(run.machine.rearm(), "re-armed at rest for the new PLC");
    assert_eq!(
        rows_answer(&mut run, 7, &rows_chunk(&rows[13..], 13, 26, true)),
        CamCouplingError::ChunkOutOfOrder.raw(),
        "the old transfer is gone"
    );
    assert_eq!(
        call(&mut run, SLAVE as u32, cam_in(7)),
        0x4B32,
        "nothing stored"
    );
    // The new PLC's own transfer, from its first chunk, is taken whole.
    assert_eq!(
        rows_answer(&mut run, 7, &rows_chunk(&rows[..13], 0, 26, false)),
        0
    );
    assert_eq!(
        rows_answer(&mut run, 7, &rows_chunk(&rows[13..], 13, 26, true)),
        0
    );
    assert_eq!(
        call(&mut run, SLAVE as u32, cam_in(7)),
        0,
        "the new table couples"
    );
}
