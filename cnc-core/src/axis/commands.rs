//! The command book of an axis: ids for accepted commands, which one owns the set-point
//! generator, and how the last ones ended, in the HLI layout the PLC reads.

pub use hli::command_book::{view_command, CommandView};
use hli::enums::{AxisCommandKind, AxisError, CommandResult};
use hli::layout::{HliAxisCommandOutcome, HliAxisCommandState, HLI_AXIS_OUTCOMES};

/// The command that owns the generator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ActiveCommand {
    /// Its id.
    pub id: u32,
    /// Its kind.
    pub kind: AxisCommandKind,
}

/// Ids, the active command and the ring of outcomes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommandBook {
    issued: u32,
    active: Option<ActiveCommand>,
    reached: bool,
    outcomes: [HliAxisCommandOutcome; HLI_AXIS_OUTCOMES],
    last: usize,
}

impl Default for CommandBook {
    fn default() -> Self {
        Self {
            issued: 0,
            active: None,
            reached: false,
            outcomes: [bytemuck::Zeroable::zeroed(); HLI_AXIS_OUTCOMES],
            last: HLI_AXIS_OUTCOMES - 1,
        }
    }
}

impl CommandBook {
    /// The active command, if any.
    pub fn active(&self) -> Option<ActiveCommand> {
        self.active
    }

    fn next_id(&mut self) -> u32 {
        // Ids stay above 0 (0 means "none") even after 2^32 commands.
        self.issued = self.issued.wrapping_add(1).max(1);
        self.issued
    }

    fn record(
        &mut self,
        id: u32,
        kind: AxisCommandKind,
        result: CommandResult,
        error: Option<AxisError>,
    ) {
        self.last = (self.last + 1) % HLI_AXIS_OUTCOMES;
        self.outcomes[self.last] = HliAxisCommandOutcome {
            command_id: id,
            result: result.raw(),
            error_id: error.map_or(0, AxisError::raw),
            kind: kind.raw(),
        };
    }

    /// Starts a motion command: the one active before is aborted. Returns the new id.
    pub fn begin(&mut self, kind: AxisCommandKind) -> u32 {
        if let Some(old) = self.active.take() {
            self.record(old.id, old.kind, CommandResult::Aborted, None);
        }
        let id = self.next_id();
        self.active = Some(ActiveCommand { id, kind });
        self.reached = false;
        id
    }

    /// A command that completes at once without touching the active one (power, reset).
    pub fn instant(&mut self, kind: AxisCommandKind) -> u32 {
        let id = self.next_id();
        self.record(id, kind, CommandResult::Done, None);
        id
    }

    /// A command that runs beside the active one (MC_MoveSuperimposed): an id, the active
    /// one untouched; its end is recorded with [`CommandBook::end_beside`].
    pub fn begin_beside(&mut self) -> u32 {
        self.next_id()
    }

    /// Records how a command begun with [`CommandBook::begin_beside`] ended.
    pub fn end_beside(
        &mut self,
        id: u32,
        kind: AxisCommandKind,
        result: CommandResult,
        error: Option<AxisError>,
    ) {
        self.record(id, kind, result, error);
    }

    /// Marks the active command as having reached its goal while it keeps the axis.
    pub fn mark_reached(&mut self) {
        self.reached = self.active.is_some();
    }

    /// Ends the active command (if any) with `result`.
    pub fn finish(&mut self, result: CommandResult, error: Option<AxisError>) {
        if let Some(active) = self.active.take() {
            self.record(active.id, active.kind, result, error);
        }
        self.reached = false;
    }

    /// The HLI image of the book.
    pub fn image(&self) -> HliAxisCommandState {
        HliAxisCommandState {
            issued_id_r: self.issued,
            active_id_r: self.active.map_or(0, |a| a.id),
            active_reached_r: u32::from(self.reached),
            last_outcome_r: self.last as u32,
            outcomes_r: self.outcomes,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hli::command_book::{view_command, CommandView};

    #[test]
    fn a_new_motion_aborts_the_active_one_and_instants_leave_it() {
        let mut book = CommandBook::default();
        let a = book.begin(AxisCommandKind::MoveAbsolute);
        let p = book.instant(AxisCommandKind::Power);
        assert_eq!(view_command(&book.image(), a), CommandView::Busy(false));
        assert_eq!(view_command(&book.image(), p), CommandView::Done);
        let b = book.begin(AxisCommandKind::MoveVelocity);
        book.mark_reached();
        assert_eq!(view_command(&book.image(), a), CommandView::Aborted);
        assert_eq!(view_command(&book.image(), b), CommandView::Busy(true));
        book.finish(CommandResult::Error, Some(AxisError::FollowingError));
        assert_eq!(view_command(&book.image(), b), CommandView::Error(0x4240));
        assert_eq!(view_command(&book.image(), 0), CommandView::Unknown);
        for _ in 0..4 {
            book.instant(AxisCommandKind::Reset);
        }
        assert_eq!(view_command(&book.image(), a), CommandView::Unknown);
    }
}
