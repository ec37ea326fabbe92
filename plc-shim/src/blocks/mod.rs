//! The function blocks a PLC program calls, one file per family, all on the block kernel
//! ([`crate::kernel`]). Each family's file ends with its `TIMELINE` table, the blocks a
//! timeline calls by name ([`crate::timeline::registry`]); `dyn_cs` has none (its blocks
//! address a channel).

use crate::kernel::Outputs;

/// The outputs a timeline records for a block: the kernel's without the family's extra, and no
/// Status.
pub(crate) fn plain<X: Copy + Default>(out: Outputs<X>) -> (Outputs, bool) {
    (out.without_extra(), false)
}

/// `TimelineBlock::execute` and `cycle` of a block with an `execute` input and an `out`
/// output, called with its axis (`with_axis`), with it as its `slave` field (`as_slave`) or
/// without (`no_axis`); `$record` turns its outputs into what the timeline records (`plain`,
/// or a family's own).
macro_rules! execute_cycle {
    (with_axis, $record:path) => {
        fn execute(&mut self) -> Option<&mut bool> {
            Some(&mut self.execute)
        }
        fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool) {
            self.call(io, axis);
            $record(self.out)
        }
    };
    (as_slave, $record:path) => {
        fn execute(&mut self) -> Option<&mut bool> {
            Some(&mut self.execute)
        }
        fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool) {
            self.slave = axis;
            self.call(io);
            $record(self.out)
        }
    };
    (no_axis, $record:path) => {
        fn execute(&mut self) -> Option<&mut bool> {
            Some(&mut self.execute)
        }
        fn cycle(&mut self, io: &mut PlcIo<'_>, _: u32) -> (Outputs, bool) {
            self.call(io);
            $record(self.out)
        }
    };
}

/// Input tTimeout of a block on the kernel at `self.<path>`: its `set_timeout_cycles`.
macro_rules! timeout_input {
    ($($path:ident).+) => {
        /// Input tTimeout: cycles to wait for the CNC's answer (a read in parts: for each
        /// part).
        pub fn set_timeout_cycles(&mut self, cycles: u64) {
            self.$($path).+.set_timeout_cycles(cycles);
        }
    };
}

/// `TimelineBlock::timeout_cycles` of a block with input tTimeout (its `set_timeout_cycles`,
/// at `self.<path>` if given).
macro_rules! timeline_timeout {
    () => {
        fn timeout_cycles(&mut self, cycles: u64) -> bool {
            self.set_timeout_cycles(cycles);
            true
        }
    };
    ($($path:ident).+) => {
        fn timeout_cycles(&mut self, cycles: u64) -> bool {
            self.$($path).+.set_timeout_cycles(cycles);
            true
        }
    };
}

/// Inputs declared once, in the order a call lists them: each one's key, kind and the field
/// of `$target` it sets (a path below it). Gives the list `$list` (an `[InputSpec; N]` for a
/// `TIMELINE` entry, or part of one through `joined`) and `$set(target, key, value)`, which
/// sets the field of `key` and leaves the others. `required` before a key: every call gives
/// it; `as FORM` after a key: it reads as the `StForm` constant `FORM` in Structured Text. It
/// writes the `InputSpec` list every block declares its inputs with (a family may write
/// that list with `input`/`required` and its `set` by hand instead).
macro_rules! inputs {
    (
        $(#[doc = $doc:literal])*
        $list:ident, $set:ident: $target:ty {
            $($($required:ident)? $key:literal $(as $st:ident)?: $kind:expr => $($field:ident).+),* $(,)?
        }
    ) => {
        $(#[doc = $doc])*
        const $list: [$crate::timeline::registry::InputSpec; { [$($key),*].len() }] = [$(
            $crate::timeline::registry::InputSpec {
                key: $key,
                kind: $kind,
                required: inputs!(@required $($required)?),
                st: inputs!(@st $($st)?),
            }
        ),*];

        /// Sets input `key` of `target` (see the list beside it); other keys leave it.
        fn $set(target: &mut $target, key: &str, value: &$crate::timeline::registry::Value) {
            use $crate::timeline::registry::InputField;
            match key {
                $($key => target.$($field).+.take(value),)*
                _ => {}
            }
        }
    };
    (@st $st:ident) => { $st };
    (@st) => { $crate::timeline::registry::StForm::Key };
    (@required required) => { true };
    (@required) => { false };
}

pub mod cam;
pub mod cam_compat;
pub mod cam_data;
pub mod cam_multi;
pub mod cam_read;
pub mod cam_results;
pub mod cam_room;
pub mod channel;
pub mod dyn_cs;
pub mod fifo;
pub mod motion;
pub mod probe;
pub mod saw;
