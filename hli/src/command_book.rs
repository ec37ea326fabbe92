//! Reading an axis's command book (`HLI_AXIS_COMMAND_STATE`) from the PLC side: what a
//! motion block holding a command id makes of it.

use crate::enums::CommandResult;
use crate::layout::HliAxisCommandState;

/// What a PLC block holding command `id` makes of the book it reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandView {
    /// Still owns the axis; `true` once its goal is reached (in velocity, stopped and held).
    Busy(bool),
    /// Reached its goal.
    Done,
    /// Replaced by a newer command.
    Aborted,
    /// Failed with this code.
    Error(u32),
    /// Neither active nor in the ring: ended too long ago to tell.
    Unknown,
}

/// Reads the state of command `id` from a book image.
pub fn view_command(book: &HliAxisCommandState, id: u32) -> CommandView {
    if id != 0 && book.active_id_r == id {
        return CommandView::Busy(book.active_reached_r != 0);
    }
    // The reply can overtake the image by a tick: an id newer than the last one the image
    // shows was accepted but is not written yet (ids count up, wrapping).
    if id != 0 && (id.wrapping_sub(book.issued_id_r) as i32) > 0 {
        return CommandView::Busy(false);
    }
    let outcome = book
        .outcomes_r
        .iter()
        .find(|o| o.command_id == id && id != 0);
    match outcome.map(|o| (CommandResult::decode(o.result), o.error_id)) {
        Some((Ok(CommandResult::Done), _)) => CommandView::Done,
        Some((Ok(CommandResult::Aborted), _)) => CommandView::Aborted,
        Some((Ok(CommandResult::Error), code)) => CommandView::Error(code),
        _ => CommandView::Unknown,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reply_that_overtakes_the_image_reads_as_busy() {
        let mut book: HliAxisCommandState = bytemuck::Zeroable::zeroed();
        book.issued_id_r = 1;
        assert_eq!(view_command(&book, 2), CommandView::Busy(false));
        assert_eq!(view_command(&book, 1), CommandView::Unknown);
        book.issued_id_r = u32::MAX;
        assert_eq!(
            view_command(&book, 1),
            CommandView::Busy(false),
            "across the wrap"
        );
        assert_eq!(view_command(&book, 0), CommandView::Unknown);
    }
}
