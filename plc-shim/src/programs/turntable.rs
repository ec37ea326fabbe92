//! Seed 003, application example 4: the PLC as master of the dynamic CS of a robot that
//! machines a workpiece on a turntable, in both of the seed's variants, written with the
//! blocks of [`crate::blocks::dyn_cs`]:
//!
//! * **hybrid**: the NC program switches the tracking (`#TRACK CS ON [.. KIN_BASE X=-1305.92]`);
//!   the PLC takes over the unit and, while tracking is ACTIVE, commands the table angle as the
//!   frame's rotation every cycle the CNC has taken the previous frame;
//! * **PLC-only**: the PLC also holds the turntable's geometry (KIN_BASE with the robot base
//!   1305.92 mm in -X of the table centre and 800 mm above it, the manual's numbers, OPTION=1,
//!   WAIT, no filter) and switches the tracking
//!   itself: on when the NC program announces M100, off on M101, acknowledging each M
//!   function in the cycle it sends the transition.
//!
//! The frame's rotation is minus the table's actual position: the compensation turns by the
//! inverse of the table. In `scenarios/example4-*` the table is channel 0's seventh axis
//! (`gpAx[6]`, the default); [`Turntable::on`] puts the program on another channel and axis.

use crate::blocks::dyn_cs::{DynCsMaster, MFunctionHandshake, McDynCsTransition};
use crate::runtime::{PlcIo, PlcProgram};
use hli::enums::{DynCsOption, DynCsState};

/// The channel whose unit the PLC masters in `scenarios/example4-*`.
pub const SCENARIO_CHANNEL: usize = 0;
/// The table axis there, `gpAx[6]`.
pub const SCENARIO_TABLE_AXIS: usize = 6;
/// Robot base seen from the table centre, -X, 0.1 um (1305.92 mm).
const KIN_BASE_X: i32 = -13_059_200;
/// Robot base seen from the table centre, +Z, 0.1 um (800 mm; a translation along the table's
/// axis does not change the compensation of a turn about it).
const KIN_BASE_Z: i32 = 8_000_000;

/// Which of the seed's variants.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// The NC switches the tracking; the PLC commands the frame.
    Hybrid,
    /// The PLC switches the tracking on M100/M101 and commands the frame.
    PlcOnly,
}

/// The turntable program.
#[derive(Debug)]
pub struct Turntable {
    variant: Variant,
    /// The robot's channel.
    channel: usize,
    /// The table axis (`gpAx` index).
    table_axis: usize,
    master: DynCsMaster,
    switch: McDynCsTransition,
    m: MFunctionHandshake,
    /// Transitions the block finished (Done).
    pub transitions_done: u64,
    /// Blocks that ended in Error or CommandAborted.
    pub transition_failures: u64,
}

impl Turntable {
    /// The program of `variant` on the seed example's channel and table axis.
    pub fn new(variant: Variant) -> Turntable {
        Turntable::on(variant, SCENARIO_CHANNEL, SCENARIO_TABLE_AXIS)
    }

    /// The program of `variant` for the robot of `channel` with the table on `gpAx[table_axis]`.
    pub fn on(variant: Variant, channel: usize, table_axis: usize) -> Turntable {
        let mut switch = McDynCsTransition::default();
        switch.option = DynCsOption::TranslationOnly;
        switch.wait = true;
        switch.kin_base = true;
        switch.filter_max_ticks = 0;
        switch.kinematic_base_cs.translation[0] = KIN_BASE_X;
        switch.kinematic_base_cs.translation[2] = KIN_BASE_Z;
        Turntable {
            variant,
            channel,
            table_axis,
            master: DynCsMaster::default(),
            switch,
            m: MFunctionHandshake::default(),
            transitions_done: 0,
            transition_failures: 0,
        }
    }
}

impl PlcProgram for Turntable {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        let channel = self.channel;
        if self.variant == Variant::PlcOnly {
            self.m.call(io, channel);
            let asked = match self.m.m_code() {
                Some(100) => Some(true),
                Some(101) => Some(false),
                _ => None,
            };
            // A one-cycle pulse on Execute per M function: the block runs on while Busy.
            self.switch.execute = asked.is_some();
            if let Some(on) = asked {
                self.switch.on = on;
            }
            self.switch.call(io, channel);
            if asked.is_some() {
                self.m.acknowledge(io, channel);
            }
            let out = self.switch.out;
            self.transitions_done += u64::from(out.done);
            self.transition_failures += u64::from(out.error || out.command_aborted);
        }
        let table = io
            .gp_ax(self.table_axis)
            .map_or(0, |axis| axis.lr_state().current_position_acs_r);
        self.master.enable = true;
        // The state as the CNC reports it in this cycle decides (not the one of the last).
        let state = io.gp_ch(channel).and_then(|ch| ch.dyn_cs_state().ok());
        self.master.send = state == Some(DynCsState::Active);
        self.master.frame.rotation[2] = table.saturating_neg();
        self.master.call(io, channel);
    }

    fn summary(&self) -> String {
        format!(
            "turntable ({:?}): transitions sent {} done {} failed {}, M functions {} acknowledged {}, frames {} (waited {}), error {:#x}, last state {:?}",
            self.variant,
            self.switch.sent,
            self.transitions_done,
            self.transition_failures,
            self.m.received,
            self.m.acknowledged,
            self.master.frames_sent,
            self.master.frames_waiting,
            self.master.error_id.max(self.switch.out.error_id),
            self.master.state
        )
    }
}
