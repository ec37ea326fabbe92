//! Every registered block, whatever its family: a unique name, an instance, and its own
//! inputs accepted.

use super::*;
use crate::timeline::instances::Instances;

#[test]
fn block_names_are_unique_ignoring_case() {
    let mut names: Vec<String> = blocks().map(|b| b.name.to_ascii_lowercase()).collect();
    let n = names.len();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), n, "a name is registered twice");
}

/// Each block's spec makes an instance whose Execute is the spec's, and a call that gives
/// every declared input a valid value of its kind is accepted and applied.
#[test]
fn every_block_takes_its_own_inputs() {
    for spec in blocks() {
        let mut block = (spec.make)(None);
        assert_eq!(block.execute().is_some(), spec.execute, "{}", spec.name);
        let mut call = toml::Table::new();
        call.insert("block".into(), spec.name.into());
        call.insert("instance".into(), "i".into());
        match spec.target {
            Target::Group => {}
            Target::Channel => {
                call.insert("channel".into(), 0.into());
            }
            _ => {
                call.insert("axis".into(), 1.into());
            }
        }
        let mut instances = Instances::default();
        for input in spec.inputs {
            let text = format!("v = {}", input.kind.example());
            let value: toml::Table = toml::from_str(&text).unwrap();
            call.insert(input.key.into(), value["v"].clone());
        }
        let checked = instances.parse_call(&call);
        let checked = checked.unwrap_or_else(|e| panic!("{}: {e}", spec.name));
        instances.apply(&checked);
        instances.begin_cycle();
    }
}

/// A mode takes the names and numbers of its wire enum, nothing else.
#[test]
fn a_mode_is_its_wire_enum() {
    use hli::calls::cam::CamActivationMode;
    let Kind::Mode(m) = mode::<CamActivationMode>() else {
        unreachable!()
    };
    assert_eq!((m.from_name)("Next_Cycle"), Some(3));
    assert!((m.valid)(7) && !(m.valid)(8));
    assert!((m.names)().starts_with("instantaneous (0), at_master_cam_pos (1), "));
}
