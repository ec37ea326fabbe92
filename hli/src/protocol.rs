//! The handshake protocol of the image as a write sees it: who writes a leaf (the CNC, the
//! PLC, both), and which semaphore or command word guards it, from the symbol table's naming
//! rule. A tool or server that writes PLC leaves from outside a PLC program (`plc set`, the
//! OPC UA server) checks its writes here first, so it never breaks a handshake the CNC relies
//! on; nothing here writes.

use crate::access::{Leaf, Value};
use crate::desc::{Scalar, SymbolWriter};
use crate::symbols::SymbolTable;
use crate::ImageMemory;

/// A write the protocol refused, with the path as given.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{path}`: {reason}")]
pub struct Refused {
    /// The path.
    pub path: String,
    /// Why.
    pub reason: Refusal,
}

/// Why the protocol refused a write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Refusal {
    /// The CNC writes this leaf.
    #[error("written by the CNC, read-only for the PLC")]
    CncOwned,
    /// The payload's semaphore is TRUE: the CNC has not taken the previous datum.
    #[error("the CNC has not taken the previous datum yet (its semaphore is TRUE)")]
    Pending,
    /// A PLC→CNC semaphore may only be set TRUE, and only while FALSE.
    #[error("a PLC-to-CNC semaphore is set TRUE (publish) while FALSE; the CNC clears it")]
    PublishOnly,
    /// A CNC→PLC semaphore may only be cleared, and only while TRUE.
    #[error("a CNC-to-PLC semaphore is set FALSE (taken) while TRUE; the CNC sets it")]
    TakeOnly,
    /// The transition's command word is not 0: the CNC has not taken the previous command.
    #[error("the CNC has not taken the previous transition command yet (command is not 0)")]
    CommandPending,
    /// A transition command must not be 0 (the CNC writes 0 when it takes one).
    #[error("write a command other than 0; the CNC writes 0 when it takes one")]
    CommandZero,
}

/// How a leaf takes part in a handshake.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    /// Written by the CNC only.
    CncOwned,
    /// A PLC leaf outside any handshake.
    Free,
    /// Payload published by this semaphore (PLC→CNC).
    Payload(Leaf),
    /// The semaphore of a PLC→CNC unit.
    PublishSemaphore,
    /// The semaphore of a CNC→PLC unit.
    TakeSemaphore,
    /// A parameter of a unit guarded by this command word.
    Parameter(Leaf),
    /// A command word (0 = free).
    CommandWord,
}

/// The handshake role of `path`, from the symbol table's naming rule: in a unit, the field
/// `X_semaphore_rw` guards its sibling `X_w` (PLC→CNC) or `X_r` (CNC→PLC); a struct with a
/// `command` leaf both sides write is guarded by it.
fn role(path: &str, leaf: &Leaf) -> Role {
    if let Some(unit) = path.strip_suffix("_semaphore_rw") {
        // `unit` is `...prefix.X`: the sibling payload is `X_w` or `X_r`.
        return if SymbolTable::global().lookup(&format!("{unit}_w")).is_some() {
            Role::PublishSemaphore
        } else {
            Role::TakeSemaphore
        };
    }
    if leaf.writer == SymbolWriter::Both && path.ends_with(".command") {
        return Role::CommandWord;
    }
    if leaf.writer == SymbolWriter::Cnc {
        return Role::CncOwned;
    }
    // Walk the path's components from the leaf up: the first `X_w` with a sibling
    // `X_semaphore_rw`, or the first struct with a shared `command` word, guards it.
    let mut end = path.len();
    while let Some(dot) = path[..end].rfind(['.', '^']) {
        let component = &path[..end];
        if let Some(stem) = component.strip_suffix("_w") {
            if let Ok(sem) = Leaf::resolve(&format!("{stem}_semaphore_rw")) {
                return Role::Payload(sem);
            }
        }
        if let Ok(command) = Leaf::resolve(&format!("{component}.command")) {
            if command.writer == SymbolWriter::Both && component.len() < path.len() {
                return Role::Parameter(command);
            }
        }
        end = dot;
    }
    Role::Free
}

/// Shows a value the way ST writes it (BOOL as TRUE/FALSE).
pub fn show(leaf: &Leaf, value: Value) -> String {
    match (leaf.scalar, value) {
        (Scalar::Bool, Value::Unsigned(0)) => "FALSE".into(),
        (Scalar::Bool, Value::Unsigned(_)) => "TRUE".into(),
        _ => value.to_string(),
    }
}

/// One write: a resolved leaf and a value in its range.
#[derive(Debug, Clone, Copy)]
pub struct Write<'p> {
    /// The path as given.
    pub path: &'p str,
    /// The leaf.
    pub leaf: Leaf,
    /// The value, in range.
    pub value: Value,
}

/// Checks `writes` against the image and the protocol, each seeing the state the writes
/// before it leave. Nothing is written.
pub fn check_protocol(memory: &ImageMemory, writes: &[Write<'_>]) -> Result<(), Refused> {
    for (k, w) in writes.iter().enumerate() {
        let (leaf, value) = (&w.leaf, w.value);
        // The value of a leaf after the writes before this one.
        let now = |l: &Leaf| {
            writes[..k]
                .iter()
                .rev()
                .find(|e| e.leaf.offset == l.offset)
                .map_or_else(|| l.read(memory), |e| e.value)
                .as_f64()
        };
        let refuse = |reason| {
            Err(Refused {
                path: w.path.to_string(),
                reason,
            })
        };
        match role(w.path, leaf) {
            Role::CncOwned => return refuse(Refusal::CncOwned),
            Role::Free => {}
            Role::Payload(sem) if now(&sem) != 0.0 => return refuse(Refusal::Pending),
            Role::Payload(_) => {}
            Role::PublishSemaphore if now(leaf) != 0.0 || value.as_f64() == 0.0 => {
                return refuse(Refusal::PublishOnly)
            }
            Role::PublishSemaphore => {}
            Role::TakeSemaphore if now(leaf) == 0.0 || value.as_f64() != 0.0 => {
                return refuse(Refusal::TakeOnly)
            }
            Role::TakeSemaphore => {}
            Role::Parameter(command) if now(&command) != 0.0 => {
                return refuse(Refusal::CommandPending)
            }
            Role::Parameter(_) => {}
            Role::CommandWord if value.as_f64() == 0.0 => return refuse(Refusal::CommandZero),
            Role::CommandWord if now(leaf) != 0.0 => return refuse(Refusal::CommandPending),
            Role::CommandWord => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const SEM: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_semaphore_rw";
    const ROT: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[2]";
    const REQ_SEM: &str = "gpCh[0]^channel_mc_control.dyn_cs.request_semaphore_rw";
    const ENABLE: &str = "gpCh[0]^channel_mc_control.dyn_cs.enable_w";
    const T_CMD: &str = "gpCh[0]^channel_mc_control.dyn_cs.transition_w.command";
    const T_FILTER: &str = "gpCh[0]^channel_mc_control.dyn_cs.transition_w.filter_max_ticks";
    const STATE: &str = "gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state";

    #[test]
    fn roles_follow_the_naming_rule() {
        let r = |p: &str| role(p, &Leaf::resolve(p).unwrap());
        assert_eq!(r(SEM), Role::PublishSemaphore);
        assert_eq!(r(REQ_SEM), Role::TakeSemaphore);
        assert_eq!(r(ROT), Role::Payload(Leaf::resolve(SEM).unwrap()));
        assert_eq!(r(ENABLE), Role::Free);
        assert_eq!(r(T_CMD), Role::CommandWord);
        assert_eq!(r(T_FILTER), Role::Parameter(Leaf::resolve(T_CMD).unwrap()));
        assert_eq!(r(STATE), Role::CncOwned);
        let ack = "gpCh[2]^channel_mc_control.m_function.ack_w.m_code";
        let ack_sem = "gpCh[2]^channel_mc_control.m_function.ack_semaphore_rw";
        assert_eq!(r(ack), Role::Payload(Leaf::resolve(ack_sem).unwrap()));
        assert_eq!(r(ack_sem), Role::PublishSemaphore);
        assert_eq!(
            r("gpCh[2]^channel_mc_control.m_function.request_semaphore_rw"),
            Role::TakeSemaphore
        );
    }
}
