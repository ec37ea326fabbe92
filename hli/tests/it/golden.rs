//! Golden bytes of a filled `MC_CONTROL_DYN_CS_UNIT`: the exact little-endian image a PLC
//! compiled against the specification's struct would see.

use hli::layout::*;
use hli::Bool;

fn le(v: i32) -> [u8; 4] {
    v.to_le_bytes()
}

#[test]
fn filled_dyn_cs_unit_has_the_specified_bytes() {
    let cs = |t: [i32; 3], r: [i32; 3]| HliCoordinateSystemInt {
        translation: t,
        fill_up_2: 0,
        rotation: r,
        fill_up_1: 0,
    };
    let unit = McControlDynCsUnit {
        enable_w: Bool::TRUE,
        request_semaphore_rw: Bool::FALSE,
        command_semaphore_rw: Bool::TRUE,
        fill_up_1: Bool::FALSE,
        fill_up_2: 0,
        request_r: cs([1, 2, 3], [4, 5, 6]),
        command_w: cs([10_000, -10_000, 0], [0, 0, 900_000]),
        transition_w: HliDynCsTransition {
            command: 1,
            filter_max_ticks: 1000,
            option: 1,
            f_wait: Bool::TRUE,
            f_set_zero: Bool::FALSE,
            f_kin_base: Bool::TRUE,
            f_rot_trans: Bool::FALSE,
            kinematic_base_cs: cs([2_000_000, 0, 0], [0, 0, -900_000]),
        },
        state_r: HliDynCsState {
            actual_state: hli::enums::DynCsState::Error.raw(),
            fill_up_1: 0,
        },
    };

    let mut expected = Vec::new();
    expected.extend_from_slice(&[1, 0, 1, 0]);
    expected.extend_from_slice(&le(0));
    for v in [1, 2, 3, 0, 4, 5, 6, 0] {
        expected.extend_from_slice(&le(v));
    }
    for v in [10_000, -10_000, 0, 0, 0, 0, 900_000, 0] {
        expected.extend_from_slice(&le(v));
    }
    expected.extend_from_slice(&le(1));
    expected.extend_from_slice(&1000u32.to_le_bytes());
    expected.extend_from_slice(&1u32.to_le_bytes());
    expected.extend_from_slice(&[1, 0, 1, 0]);
    for v in [2_000_000, 0, 0, 0, 0, 0, -900_000, 0] {
        expected.extend_from_slice(&le(v));
    }
    expected.extend_from_slice(&[0xFF, 0xFF, 0xFF, 0xFF]);
    expected.extend_from_slice(&le(0));

    assert_eq!(expected.len(), 128);
    assert_eq!(bytemuck::bytes_of(&unit), &expected[..]);
    // Byte 40 starts command_w, 72 transition_w, 120 state_r, as the specification lays out.
    assert_eq!(&expected[40..44], &le(10_000));
    assert_eq!(&expected[72..76], &le(1));
    assert_eq!(&expected[120..124], &[0xFF; 4]);
}
