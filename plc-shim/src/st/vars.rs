//! An ST program's variables for the tools: the PLC process publishes them in a
//! shared-memory object of its own (`cncplc_<instance>.st`, removed when the PLC ends), and
//! `plc get|set|watch` reach them by name (`MAIN.fbCam.Busy`) as they reach the image.
//!
//! ```text
//!   0  magic "CNCPLCST"        24 cycles published (u64)
//!   8  the PLC's pid (u32)     32 write request: state (u32: 0 free, 4 claimed, 1 asked,
//!  12  symbols (u32)              2 done, 3 refused)
//!  16  table bytes (u32)       36 the symbol's index (u32)   40 the value (f64 bits)
//!  20  data bytes (u32)        48 copies asked for (u32)   52 copies made (u32)
//!                              64 the table: `PATH TYPE OFFSET` per line, then the memory
//! ```
//!
//! A STRING's TYPE is `STRING(n)`: a tool reads its text (`plc get` prints it as ST writes a
//! literal) and never writes it (the PLC refuses a write to it whatever the request says).
//!
//! Every cycle, before the program runs, the PLC takes a write a tool asked for (the symbol's
//! index and a number, checked against the symbol's type: a value that does not fit is
//! refused, never wrapped), and after it counts the cycle and, when a tool has asked for a
//! copy since the last (it raises the count at 48), copies the program's memory into the
//! object (8-byte atomic stores, no allocation, no system call) and answers with that count
//! at 52. A tool asks, waits for the answer, and reads a variable from the copy: a cycle
//! nobody reads copies nothing. A
//! tool claims the request slot (FREE to CLAIMED, compare-and-swap) before it fills it, so two
//! tools never mix their writes; the PLC takes the index and value only after the state says
//! ASKED (release and acquire). The magic is written last, so a tool never reads a table half
//! written. Nothing the PLC reads from the object is trusted: the index and value are checked,
//! the counter of cycles is the PLC's own.

use hli::ImageMemory;
use plc_st::types::Elem;
use plc_st::vm::{Program, Symbol};
use std::sync::atomic::Ordering::{AcqRel, Acquire};

const MAGIC: u64 = u64::from_le_bytes(*b"CNCPLCST");
const PID: usize = 8;
const SYMBOLS: usize = 12;
const TABLE_BYTES: usize = 16;
const DATA_BYTES: usize = 20;
const CYCLES: usize = 24;
const REQUEST: usize = 32;
const REQUEST_INDEX: usize = 36;
const REQUEST_VALUE: usize = 40;
const ASKED_COPIES: usize = 48;
const MADE_COPIES: usize = 52;
const TABLE: usize = 64;
/// The most symbols published.
pub const MAX_SYMBOLS: usize = 100_000;

/// A write request's states.
const FREE: u32 = 0;
const ASKED: u32 = 1;
const DONE: u32 = 2;
const REFUSED: u32 = 3;
const CLAIMED: u32 = 4;

/// The PLC's side: the object and the symbols in it.
#[derive(Debug)]
pub struct Publisher {
    memory: ImageMemory,
    /// Per symbol: its offset and type, and whether it is a STRING (no tool writes one).
    symbols: Vec<(u32, Elem, bool)>,
    data: usize,
    words: usize,
    cycles: u64,
    /// The copies asked for that the last copy answered.
    served: u32,
}

fn align8(n: usize) -> usize {
    n.div_ceil(8) * 8
}

impl Publisher {
    /// Creates the object of `instance` for `program`'s variables.
    pub fn create(instance: &str, program: &Program) -> Result<Publisher, String> {
        let name = hli_transport::segment::st_object_name(instance)
            .ok_or_else(|| format!("invalid instance name {instance:?}"))?;
        let symbols = program.symbols(MAX_SYMBOLS);
        let table: String = symbols
            .iter()
            .map(|s| format!("{} {} {}\n", s.path, type_name(s), s.offset))
            .collect();
        let data = align8(TABLE + table.len());
        let words = program.memory().len().div_ceil(8);
        refuse_a_live_owner(&name)?;
        let memory = hli_transport::segment::create_raw_object(&name, data + words * 8)
            .map_err(|e| format!("{name}: {e}"))?;
        memory.place::<u32>(PID).store(std::process::id());
        for (k, b) in table.bytes().enumerate() {
            memory.place::<u8>(TABLE + k).store(b);
        }
        memory.place::<u32>(SYMBOLS).store(symbols.len() as u32);
        memory.place::<u32>(TABLE_BYTES).store(table.len() as u32);
        memory.place::<u32>(DATA_BYTES).store((words * 8) as u32);
        memory.place::<u64>(0).store_release(MAGIC);
        let symbols = symbols
            .iter()
            .map(|s| (s.offset, s.elem, s.text.is_some()))
            .collect();
        Ok(Publisher {
            memory,
            symbols,
            data,
            words,
            cycles: 0,
            served: 0,
        })
    }

    /// Takes a tool's write, if one is asked for (before the cycle): whether it wrote.
    pub fn take_write(&self, program: &mut Program) -> bool {
        if self.memory.place::<u32>(REQUEST).load_acquire() != ASKED {
            return false;
        }
        let index = self.memory.place::<u32>(REQUEST_INDEX).load() as usize;
        let value = f64::from_bits(self.memory.place::<u64>(REQUEST_VALUE).load());
        let done = match self.symbols.get(index) {
            Some(&(offset, elem, false)) => program.write_symbol(offset, elem, value).is_ok(),
            // A STRING is no number: refused, whatever a tool asks.
            Some(&(_, _, true)) => false,
            None => false,
        };
        let state = if done { DONE } else { REFUSED };
        self.memory.place::<u32>(REQUEST).store_release(state);
        done
    }

    /// Counts the cycle, and copies the program's memory into the object if a tool has
    /// asked for a copy since the last (after the cycle).
    pub fn publish(&mut self, program: &Program) {
        self.cycles = self.cycles.wrapping_add(1);
        self.memory.place::<u64>(CYCLES).store_release(self.cycles);
        self.serve(program);
    }

    /// Copies the program's memory into the object if a tool has asked for a copy since the
    /// last (also while the program stands after a fault, so that a tool sees where).
    pub fn serve(&mut self, program: &Program) {
        let asked = self.memory.place::<u32>(ASKED_COPIES).load_acquire();
        if asked == self.served {
            return;
        }
        let bytes = program.memory();
        for k in 0..self.words {
            let mut word = [0u8; 8];
            let part = bytes
                .get(k * 8..(k * 8 + 8).min(bytes.len()))
                .unwrap_or(&[]);
            word[..part.len()].copy_from_slice(part);
            self.memory
                .place::<u64>(self.data + k * 8)
                .store(u64::from_le_bytes(word));
        }
        self.served = asked;
        self.memory.place::<u32>(MADE_COPIES).store_release(asked);
    }
}

/// A tool's side: the variables of a running ST PLC.
pub struct Variables {
    memory: ImageMemory,
    symbols: Vec<Symbol>,
    data: usize,
}

impl Variables {
    /// Opens the variables `instance`'s PLC publishes.
    pub fn open(instance: &str) -> Result<Variables, String> {
        let name = hli_transport::segment::st_object_name(instance)
            .ok_or_else(|| format!("invalid instance name {instance:?}"))?;
        let memory = hli_transport::segment::open_raw_object(&name)
            .map_err(|_| format!("no {name}: is an ST PLC running on instance {instance}?"))?;
        let size = memory.len();
        if size < TABLE || memory.place::<u64>(0).load_acquire() != MAGIC {
            return Err(format!("{name}: not an ST PLC's variables"));
        }
        let table_bytes = memory.place::<u32>(TABLE_BYTES).load() as usize;
        let data = align8(TABLE + table_bytes);
        let data_bytes = memory.place::<u32>(DATA_BYTES).load() as usize;
        if !data_bytes.is_multiple_of(8)
            || data.checked_add(data_bytes).is_none_or(|end| end > size)
        {
            return Err(format!("{name}: its table runs past its end"));
        }
        let text: Vec<u8> = (0..table_bytes)
            .map(|k| memory.place::<u8>(TABLE + k).load())
            .collect();
        let text = String::from_utf8(text).map_err(|_| format!("{name}: a table not UTF-8"))?;
        let mut symbols = Vec::new();
        for line in text.lines() {
            let bad = || format!("{name}: a bad table line {line:?}");
            let mut words = line.split(' ');
            let (Some(path), Some(ty), Some(offset), None) =
                (words.next(), words.next(), words.next(), words.next())
            else {
                return Err(bad());
            };
            let (elem, text) = symbol_type(ty).ok_or_else(bad)?;
            let offset: u32 = offset.parse().map_err(|_| bad())?;
            let size = text.map_or(elem.size(), |n| n as usize);
            if offset as usize + size > data_bytes {
                return Err(bad());
            }
            symbols.push(Symbol {
                path: path.to_string(),
                offset,
                elem,
                text,
            });
        }
        Ok(Variables {
            memory,
            symbols,
            data,
        })
    }

    /// The symbol of `path` (ASCII case ignored): its index.
    pub fn find(&self, path: &str) -> Option<usize> {
        self.symbols
            .iter()
            .position(|s| s.path.eq_ignore_ascii_case(path))
    }

    /// The symbol at `index`.
    pub fn symbol(&self, index: usize) -> &Symbol {
        &self.symbols[index]
    }

    /// Cycles the PLC has published.
    pub fn cycles(&self) -> u64 {
        self.memory.place::<u64>(CYCLES).load()
    }

    /// Asks the PLC for a copy of its variables and waits until its next cycle made it:
    /// `Err` if the PLC does not answer (a watchdog of 2 s, not a timing).
    pub fn refresh(&self) -> Result<(), String> {
        let asked = self.memory.place::<u32>(ASKED_COPIES);
        let wanted = asked.atomic().fetch_add(1, AcqRel).wrapping_add(1);
        let made = self.memory.place::<u32>(MADE_COPIES);
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(2);
        // Another tool's later request answers this one too (the copy is as new).
        while made.load_acquire().wrapping_sub(wanted) > u32::MAX / 2 {
            if std::time::Instant::now() > deadline {
                return Err("the ST PLC did not copy its variables (is it cycling?)".into());
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        Ok(())
    }

    /// The value of symbol `index`, as the copy [`Variables::refresh`] asked for left it (read in the 8-byte words the
    /// PLC writes).
    pub fn read(&self, index: usize) -> f64 {
        let s = &self.symbols[index];
        let (at, n) = (s.offset as usize, s.elem.size());
        let mut bytes = [0u8; 16];
        let first = at / 8 * 8;
        for (k, chunk) in bytes.chunks_exact_mut(8).enumerate() {
            let word = first + k * 8;
            if word < at + n {
                let w = self.memory.place::<u64>(self.data + word).load();
                chunk.copy_from_slice(&w.to_le_bytes());
            }
        }
        decode(&bytes[at - first..at - first + n], s.elem)
    }

    /// The text of STRING symbol `index` (before its NUL) as the copy
    /// [`Variables::refresh`] asked for left it, as ST writes a literal (`'part_1.nc'`, `$'`,
    /// `$$` and `$hh` for the rest); `None` for a symbol that is no STRING.
    pub fn read_text(&self, index: usize) -> Option<String> {
        let s = &self.symbols[index];
        let size = s.text? as usize;
        let mut out = String::from("'");
        for k in 0..size {
            let at = s.offset as usize + k;
            let word = self.memory.place::<u64>(self.data + at / 8 * 8).load();
            let b = word.to_le_bytes()[at % 8];
            match b {
                0 => break,
                b'\'' | b'$' => out.extend(['$', char::from(b)]),
                b' '..=b'~' => out.push(char::from(b)),
                _ => out.push_str(&format!("${b:02X}")),
            }
        }
        out.push('\'');
        Some(out)
    }

    /// Writes `value` to symbol `index` through the PLC (it takes it before its next cycle):
    /// `Err` if the PLC refuses it (a value its type cannot hold) or does not answer.
    pub fn write(&self, index: usize, value: f64) -> Result<(), String> {
        let state = self.memory.place::<u32>(REQUEST);
        let path = &self.symbols[index].path;
        // Claim the slot: another tool's write is not mixed with this one.
        // A slot answered for a tool that did not come back for it may be claimed too.
        let claim = |from| {
            state
                .atomic()
                .compare_exchange(from, CLAIMED, AcqRel, Acquire)
        };
        if claim(FREE)
            .or_else(|_| claim(DONE))
            .or_else(|_| claim(REFUSED))
            .is_err()
        {
            return Err(format!("{path}: another write is on its way"));
        }
        self.memory.place::<u32>(REQUEST_INDEX).store(index as u32);
        self.memory
            .place::<u64>(REQUEST_VALUE)
            .store(value.to_bits());
        state.store_release(ASKED);
        // The PLC answers in its next cycle; a watchdog, not a timing.
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(2);
        let answer = loop {
            match state.load_acquire() {
                DONE => break Ok(()),
                REFUSED => {
                    let ty = type_name(&self.symbols[index]);
                    break Err(format!("{path}: {value} is not a value of {ty}"));
                }
                _ if std::time::Instant::now() > deadline => {
                    // Given back only if still unanswered (a late answer is this tool's too).
                    let _ = state
                        .atomic()
                        .compare_exchange(ASKED, FREE, AcqRel, Acquire);
                    return Err(format!("{path}: the PLC did not take the write"));
                }
                _ => std::thread::sleep(std::time::Duration::from_millis(1)),
            }
        };
        state.store_release(FREE);
        answer
    }
}

/// A symbol's type as the table names it: an elementary type's name, or `STRING(n)`.
fn type_name(s: &Symbol) -> String {
    match s.text {
        Some(size) => format!("STRING({})", size - 1),
        None => s.elem.name().to_string(),
    }
}

/// A symbol's type from the table's name ([`type_name`]): its type (a STRING's BYTE) and a
/// STRING's size with the NUL.
fn symbol_type(ty: &str) -> Option<(Elem, Option<u32>)> {
    match ty.strip_prefix("STRING(").and_then(|r| r.strip_suffix(')')) {
        Some(n) => {
            let n: u32 = n.parse().ok().filter(|n| (1..=255).contains(n))?;
            Some((Elem::Byte, Some(n + 1)))
        }
        None => Elem::named(ty).map(|e| (e, None)),
    }
}

/// Refuses to publish where a live PLC publishes already (an object left by a PLC that is
/// gone is replaced).
fn refuse_a_live_owner(name: &str) -> Result<(), String> {
    let Ok(existing) = hli_transport::segment::open_raw_object(name) else {
        return Ok(());
    };
    if existing.len() < TABLE || existing.place::<u64>(0).load_acquire() != MAGIC {
        return Ok(());
    }
    let pid = existing.place::<u32>(PID).load();
    let alive = pid != std::process::id() && std::path::Path::new(&format!("/proc/{pid}")).exists();
    if alive {
        return Err(format!(
            "{name}: a PLC (pid {pid}) publishes its variables there"
        ));
    }
    Ok(())
}

/// The value of `elem` in its little-endian `bytes`.
fn decode(bytes: &[u8], elem: Elem) -> f64 {
    let mut b = [0u8; 8];
    b[..bytes.len()].copy_from_slice(bytes);
    let unsigned = u64::from_le_bytes(b);
    let bits = 8 * bytes.len() as u32;
    let signed = if bits == 64 {
        unsigned as i64
    } else {
        ((unsigned << (64 - bits)) as i64) >> (64 - bits)
    };
    match elem {
        Elem::Real => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        Elem::LReal => f64::from_le_bytes(b),
        Elem::SInt | Elem::Int | Elem::DInt | Elem::LInt | Elem::Time | Elem::LTime => {
            signed as f64
        }
        _ => unsigned as f64,
    }
}
