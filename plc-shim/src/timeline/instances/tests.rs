//! Calls, Execute edges and waits.

use super::*;

fn table(text: &str) -> toml::Table {
    toml::from_str(text).unwrap()
}

fn execute(i: &mut Instances) -> bool {
    *i.list[0].block.execute().unwrap()
}

/// Every call is its own edge, a `wait` sees only the latest call's outputs, and
/// `execute = false` cancels a pending re-trigger.
#[test]
fn calls_make_edges_and_forget_old_outputs() {
    let mut i = Instances::default();
    let call = i
        .parse_call(&table(
            "block = \"MC_MoveAbsolute\"\ninstance = \"m\"\naxis = 0\nposition = 1.0",
        ))
        .unwrap();
    let lower = i
        .parse_call(&table(
            "block = \"MC_MoveAbsolute\"\ninstance = \"m\"\naxis = 0\nexecute = false",
        ))
        .unwrap();
    let done = i.parse_wait("m.Done").unwrap();
    i.apply(&call);
    assert!(execute(&mut i), "first call: rising edge now");
    i.list[0].last[0] = true; // the move finished: Done
    assert!(i.holds(done));
    i.apply(&call);
    assert!(!i.holds(done), "a new call forgets the old Done");
    assert!(
        !execute(&mut i) && i.list[0].raise_next_cycle,
        "FALSE for a cycle first"
    );
    i.apply(&call); // again in the same cycle: still one edge to come
    assert!(!execute(&mut i) && i.list[0].raise_next_cycle);
    i.begin_cycle();
    assert!(execute(&mut i));
    i.apply(&call);
    i.apply(&lower); // lowered before the edge came: no edge
    i.begin_cycle();
    assert!(!execute(&mut i) && !i.list[0].raise_next_cycle);
}

/// The errors name what is wrong, as the scenario tests and the docs quote them.
#[test]
fn bad_calls_name_the_key() {
    let err = |text: &str| Instances::default().parse_call(&table(text)).unwrap_err();
    assert!(err("block = \"MC_Jump\"\naxis = 0").starts_with("call: unknown block \"MC_Jump\""));
    assert_eq!(
        err("block = \"MC_Halt\"\naxis = 0\nposition = 1.0"),
        "call: MC_Halt has no input `position` (inputs: deceleration, jerk)"
    );
    assert_eq!(
        err("block = \"MC_Reset\"\naxis = 0\njerk = 1.0"),
        "call: MC_Reset has no input `jerk` (inputs: none)"
    );
    assert_eq!(
        err("block = \"MC_Halt\""),
        "call: `axis` (the gpAx index) is missing"
    );
    assert_eq!(
        err("block = \"FiFoStart\"\naxis = 0"),
        "call: FiFoStart addresses a FIFO group: no `axis`"
    );
    assert_eq!(
        err("block = \"MC_MoveVelocity\"\naxis = 1\ndirection = 2"),
        "call: `direction` = 2: 1 or -1"
    );
    assert_eq!(
        err("block = \"MC_CamIn\"\naxis = 1\nmaster_source = \"x\""),
        "call: `master_source` = \"x\": \"set_point\" or \"actual\""
    );
    assert_eq!(
        err("block = \"MC_CamTableSelect\"\naxis = 1\ntable_type = 12"),
        "call: `table_type` = 12: 10 (equidistant) or 11 (non-equidistant)"
    );
    assert_eq!(
        err("block = \"MC_CamIn\"\naxis = 1\nstart_mode = \"sideways\""),
        "call: `start_mode` = \"sideways\": known are absolute (1), relative (2), \
         master_abs_slave_rel (3), master_rel_slave_abs (4)"
    );
    assert_eq!(
        err("block = \"MC_CamScaling\"\naxis = 1\nmaster_scaling_mode = 3"),
        "call: `master_scaling_mode` = 3: known are user_defined (0), auto_offset (1), off (2)"
    );
    assert_eq!(
        err("block = \"MC_ReadMotionFunction\"\naxis = 1\nroom = 0"),
        "call: `room` = 0: 1..=1048576"
    );
    assert_eq!(
        err("block = \"MC_Power\"\naxis = 0\nexecute = true"),
        "call: MC_Power has no input `execute` (inputs: enable)"
    );
    assert_eq!(
        err("block = \"MC_Halt\"\naxis = 0\ndeceleration = \"fast\""),
        "call: MC_Halt input `deceleration` = \"fast\" is not valid"
    );
    assert_eq!(
        err("block = \"MC_Halt\"\naxis = 0\ntimeout_cycles = 10"),
        "call: MC_Halt has no tTimeout: no `timeout_cycles`"
    );
    assert_eq!(
        err("block = \"MC_CamIn\"\naxis = 1\ntimeout_cycles = 0"),
        "call: `timeout_cycles` = 0: PLC cycles 1..=10000000"
    );
    assert_eq!(
        err("block = \"CamTableReadData\"\naxis = 1\ntable = 1\nblock_size = 8"),
        "call: CamTableReadData input `block_size` = 8: 0 (the default) or 16 to 4294967295"
    );
    assert_eq!(
        err("block = \"MC_GearOut\"\nSlave = 1\naxis = 2"),
        "call: MC_GearOut: `Slave` = 1 and `axis` = 2 differ"
    );
    assert!(Instances::default()
        .parse_call(&table("block = \"MC_GearOut\"\nslave = 1\naxis = 1"))
        .is_ok());
    assert!(err("block = \"CamTableDelete\"\naxis = 1\nblock_size = 32")
        .starts_with("call: CamTableDelete has no input `block_size`"));
    let mut i = Instances::default();
    i.parse_call(&table("block = \"MC_Halt\"\ninstance = \"h\"\naxis = 0"))
        .unwrap();
    assert_eq!(
        i.parse_call(&table("block = \"MC_Stop\"\ninstance = \"h\"\naxis = 0"))
            .unwrap_err(),
        "call: instance \"h\" is a MC_Halt on axis 0, not a MC_Stop on axis 0"
    );
}

/// Modes by name (any case) or number; the names come from hli's wire enums.
#[test]
fn modes_by_name_or_number() {
    let mut i = Instances::default();
    for text in [
        "start_mode = \"MASTER_ABS_SLAVE_REL\"\ninterpolation = \"spline\"",
        "start_mode = 3\ninterpolation = 2",
    ] {
        let call = i
            .parse_call(&table(&format!(
                "block = \"mc_camin\"\ninstance = \"c\"\naxis = 1\n{text}"
            )))
            .unwrap();
        let modes: Vec<i64> = call
            .inputs
            .iter()
            .filter_map(|(_, v)| match v {
                Value::Int(m) => Some(*m),
                _ => None,
            })
            .collect();
        assert_eq!(modes, [3, 2]);
    }
    assert_eq!(
        i.summary(),
        "block c (MC_CamIn on gpAx[1]): no output rose\n"
    );
}

/// tTimeout (`timeout_cycles`) on any block that has it, beside a whole-table family's own
/// inputs; applied with the call.
#[test]
fn a_timeout_is_taken_by_blocks_that_have_one() {
    let mut i = Instances::default();
    for text in [
        "block = \"CamTableReadData\"\naxis = 1\ntable = 1\nblock_size = 32\ntimeout_cycles = 50",
        "block = \"MC_CamIn\"\naxis = 1\nmaster = 0\ntable = 1\ntimeout_cycles = 50",
        "block = \"MC_GearOut\"\naxis = 1\ntimeout_cycles = 50",
        "block = \"FiFoStart\"\ngroup = 0\ntimeout_cycles = 50",
    ] {
        let call = i.parse_call(&table(text)).unwrap();
        assert_eq!(call.timeout, Some(50), "{text}");
        i.apply(&call);
    }
}

/// An NC axis ID is found in the image's `nc_axis_id_r` (as the CNC writes it), kept while the
/// image still shows it there; an ID no axis has stays unresolved (the CNC then refuses the
/// block's calls: an Error, never a wrong axis).
#[test]
fn axis_ids_resolve_from_the_image() {
    use hli::layout::{HliAxis, HliAxisLrState};
    use hli::PlaceExt;
    let memory = hli::image::heap_image(1, 3);
    let cnc = hli::views::CncView::new(&memory);
    let write_id = |axis: usize, id: u32| {
        cnc.axis(axis)
            .unwrap()
            .field::<HliAxisLrState>(core::mem::offset_of!(HliAxis, lr_state))
            .write(&HliAxisLrState {
                nc_axis_id_r: id,
                ..bytemuck::Zeroable::zeroed()
            });
    };
    write_id(1, 9);
    write_id(2, 7);
    let view = hli::views::PlcView::new(&memory);
    assert_eq!(resolve(&view, UNRESOLVED, 9), 1);
    assert_eq!(resolve(&view, UNRESOLVED, 7), 2);
    assert_eq!(resolve(&view, UNRESOLVED, 12), UNRESOLVED);
    assert_eq!(view.axis_index_by_id(0), None);
    write_id(1, 4);
    write_id(0, 9);
    assert_eq!(
        resolve(&view, 1, 9),
        0,
        "found anew when the image moved it"
    );
    let mut i = Instances::default();
    i.parse_call(&table("block = \"MC_Halt\"\ninstance = \"h\"\naxis_id = 9"))
        .unwrap();
    assert_eq!(i.axes().count(), 0, "not an index");
    let e = i
        .parse_call(&table("block = \"MC_Halt\"\ninstance = \"h\"\naxis = 1"))
        .unwrap_err();
    assert_eq!(
        e,
        "call: instance \"h\" is a MC_Halt on axis ID 9, not a MC_Halt on axis 1"
    );
}
