//! The PLC's part of the image, set back for a new PLC: after a PLC was lost, the CNC clears
//! every leaf the PLC writes (commands, `*_w`) and every semaphore both sides write (command
//! units empty, requests withdrawn), then writes the PLC defaults again, before a new PLC may
//! attach. The header keeps the old PLC's pid and heartbeat: the new PLC writes its own.

use super::{write_plc_defaults, CncSegment, HEADER_SIZE};
use hli::desc::SymbolWriter;
use hli::symbols::{SymbolKind, SymbolTable};

impl CncSegment {
    /// Clears the PLC-written leaves and the semaphores of the image and writes the PLC
    /// defaults; returns how many leaves it cleared. Walks the symbol table: not for the
    /// tick (the CNC calls it once the machine is at rest without a PLC).
    pub fn reset_plc_units(&self) -> usize {
        let mut cleared = 0;
        for symbol in SymbolTable::global().symbols() {
            let plc_side = matches!(symbol.writer, SymbolWriter::Plc | SymbolWriter::Both);
            if !plc_side || symbol.offset < HEADER_SIZE {
                continue;
            }
            if !matches!(symbol.kind, SymbolKind::Leaf(_)) {
                continue;
            }
            let m = &self.memory;
            match symbol.size {
                1 => m.place::<u8>(symbol.offset).store_release(0),
                2 => m.place::<u16>(symbol.offset).store_release(0),
                4 => m.place::<u32>(symbol.offset).store_release(0),
                8 => m.place::<u64>(symbol.offset).store_release(0),
                _ => continue,
            }
            cleared += 1;
        }
        write_plc_defaults(&self.memory, self.expected.channel_count);
        cleared
    }
}
