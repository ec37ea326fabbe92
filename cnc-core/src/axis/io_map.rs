//! A signal-by-signal mapping of an external drive's process image, for hardware whose bytes
//! the fixed codings do not know (seed 004: unknown hardware is linked by hand).
//!
//! Without a map the four blocks of an axis's image (`enc_in`, `drive_in`, `enc_out`,
//! `drive_out`) hold the signals at our byte layout. With one, a block any entry names holds
//! the hardware's own bytes, which a field-bus task copies verbatim: each entry says where one
//! signal lies in them (a bit offset and width, signed or not) and its scaling (signal value =
//! raw value x `scale`). Every tick the axis layer decodes a mapped input block into the
//! signals it evaluates, and encodes its output signals into a mapped output block (rounded,
//! saturated to the width). Signals a mapped block does not carry read as 0 (an input's
//! `nStatus4` 0: valid) and are not written.
//!
//! Resolved once when the configuration is read; the tick only shifts bits (no allocation).

use hli::desc::{HliType, Kind, Scalar};
use hli::layout::{NcDriveIn, NcDriveOut, NcEncoderIn, NcEncoderOut};
use serde::{Deserialize, Serialize};

/// The most entries of one axis's map.
pub const MAX_SIGNALS: usize = 32;

/// A block of an axis's process image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Block {
    /// `enc_in` (the encoder's inputs).
    EncIn,
    /// `drive_in`.
    DriveIn,
    /// `enc_out`.
    EncOut,
    /// `drive_out`.
    DriveOut,
}

impl Block {
    fn of(name: &str) -> Option<Block> {
        Some(match name {
            "enc_in" => Block::EncIn,
            "drive_in" => Block::DriveIn,
            "enc_out" => Block::EncOut,
            "drive_out" => Block::DriveOut,
            _ => return None,
        })
    }

    fn desc(self) -> hli::desc::TypeDesc {
        match self {
            Block::EncIn => NcEncoderIn::desc(),
            Block::DriveIn => NcDriveIn::desc(),
            Block::EncOut => NcEncoderOut::desc(),
            Block::DriveOut => NcDriveOut::desc(),
        }
    }

    /// The block's size in bits.
    pub fn bits(self) -> u32 {
        self.desc().size as u32 * 8
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// One entry as a configuration writes it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct Entry {
    /// `block.signal`, e.g. `enc_in.nInData1`.
    signal: String,
    /// First bit of the signal in the block's bytes (little-endian, bit 0 of byte 0 is 0).
    bit: u32,
    /// Width in bits, 1..=32.
    width: u32,
    /// Two's complement (else unsigned).
    #[serde(default)]
    signed: bool,
    /// Signal value per raw unit (default 1).
    #[serde(default = "one")]
    scale: f64,
}

fn one() -> f64 {
    1.0
}

/// One signal's place: where it lies in the hardware's bytes and in our layout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SignalMap {
    /// The block.
    pub block: Block,
    /// `block.signal` as configured.
    block_name: &'static str,
    name: &'static str,
    /// The signal's field in our layout: offset and type.
    field_offset: u16,
    field: Scalar,
    /// Bit offset and width in the hardware's bytes.
    pub bit: u32,
    /// Width in bits.
    pub width: u32,
    /// Two's complement.
    pub signed: bool,
    /// Signal value per raw unit.
    pub scale: f64,
}

/// Why a map was refused: the entry (0-based) and the reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("io.map[{entry}]: {reason}")]
pub struct MapError {
    /// The entry.
    pub entry: usize,
    /// Why.
    pub reason: String,
}

/// An axis's map (empty: our layout everywhere).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(try_from = "Vec<Entry>")]
pub struct ImageMap {
    entries: [Option<SignalMap>; MAX_SIGNALS],
    /// Blocks some entry names (by [`Block`] index).
    mapped: [bool; 4],
}

impl Serialize for ImageMap {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Out {
            signal: String,
            bit: u32,
            width: u32,
            signed: bool,
            scale: f64,
        }
        s.collect_seq(self.entries.iter().flatten().map(|e| Out {
            signal: format!("{}.{}", e.block_name, e.name),
            bit: e.bit,
            width: e.width,
            signed: e.signed,
            scale: e.scale,
        }))
    }
}

impl TryFrom<Vec<Entry>> for ImageMap {
    type Error = MapError;

    fn try_from(list: Vec<Entry>) -> Result<Self, MapError> {
        if list.len() > MAX_SIGNALS {
            return Err(MapError {
                entry: MAX_SIGNALS,
                reason: format!("at most {MAX_SIGNALS} signals"),
            });
        }
        let mut map = ImageMap::default();
        for (k, entry) in list.iter().enumerate() {
            let refuse = |reason: String| MapError { entry: k, reason };
            let signal = resolve(entry).map_err(refuse)?;
            for (j, other) in map.entries.iter().take(k).flatten().enumerate() {
                if other.block != signal.block {
                    continue;
                }
                if other.field_offset == signal.field_offset {
                    return Err(refuse(format!(
                        "{} is mapped twice (entry {j})",
                        entry.signal
                    )));
                }
                let overlap =
                    signal.bit < other.bit + other.width && other.bit < signal.bit + signal.width;
                if overlap {
                    return Err(refuse(format!(
                        "bits {}..{} overlap entry {j}'s",
                        signal.bit,
                        signal.bit + signal.width
                    )));
                }
            }
            map.mapped[signal.block.index()] = true;
            map.entries[k] = Some(signal);
        }
        // A mapped encoder input whose count is not mapped would read a count of 0 for ever.
        let count = |e: &SignalMap| e.block == Block::EncIn && e.name == "nInData1";
        if map.mapped[Block::EncIn.index()] && !map.entries.iter().flatten().any(count) {
            return Err(MapError {
                entry: list.len() - 1,
                reason: "enc_in is mapped without enc_in.nInData1, the encoder's count".into(),
            });
        }
        Ok(map)
    }
}

/// An entry's signal resolved against our layout, its place checked against the block.
fn resolve(entry: &Entry) -> Result<SignalMap, String> {
    let (block_name, field_name) = entry
        .signal
        .split_once('.')
        .ok_or_else(|| format!("signal \"{}\" is not BLOCK.SIGNAL", entry.signal))?;
    let block = Block::of(block_name).ok_or_else(|| {
        format!("block \"{block_name}\": one of enc_in, drive_in, enc_out, drive_out")
    })?;
    let Kind::Struct { fields, .. } = block.desc().kind else {
        return Err("not a struct".into());
    };
    let block_name: &'static str = match block {
        Block::EncIn => "enc_in",
        Block::DriveIn => "drive_in",
        Block::EncOut => "enc_out",
        Block::DriveOut => "drive_out",
    };
    let found = fields
        .iter()
        .find(|f| f.name == field_name && !f.name.starts_with("fill_up"));
    let (field_offset, field, name) = match found.map(|f| ((f.ty)().kind, f.offset, f.name)) {
        Some((Kind::Scalar(s), offset, name)) => (offset as u16, s, name),
        _ => return Err(format!("{block_name} has no signal \"{field_name}\"")),
    };
    if !(1..=32).contains(&entry.width) {
        return Err(format!("width {} must be 1..=32", entry.width));
    }
    if u64::from(entry.bit) + u64::from(entry.width) > u64::from(block.bits()) {
        return Err(format!(
            "bits {}..{} leave the {} bytes of {block_name}",
            entry.bit,
            u64::from(entry.bit) + u64::from(entry.width),
            block.bits() / 8
        ));
    }
    if !(entry.scale.is_finite() && entry.scale != 0.0) {
        return Err(format!("scale {} must be finite and not 0", entry.scale));
    }
    Ok(SignalMap {
        block,
        block_name,
        name,
        field_offset,
        field,
        bit: entry.bit,
        width: entry.width,
        signed: entry.signed,
        scale: entry.scale,
    })
}

impl ImageMap {
    /// Whether any signal is mapped.
    pub fn is_empty(&self) -> bool {
        !self.mapped.iter().any(|m| *m)
    }

    /// The entry mapping `block`'s signal `name`, if any.
    pub fn signal(&self, block: Block, name: &str) -> Option<&SignalMap> {
        self.signals(block).find(|s| s.name == name)
    }

    /// Whether `block` holds the hardware's bytes.
    pub fn maps(&self, block: Block) -> bool {
        self.mapped[block.index()]
    }

    fn signals(&self, block: Block) -> impl Iterator<Item = &SignalMap> {
        self.entries
            .iter()
            .flatten()
            .filter(move |s| s.block == block)
    }

    /// Decodes an input block in place: the hardware's bytes become our layout.
    pub fn decode<T: HliType>(&self, block: Block, raw: &mut T) {
        if !self.maps(block) {
            return;
        }
        let bytes = bytemuck::bytes_of_mut(raw);
        let hardware: [u8; 40] = copy40(bytes);
        bytes.fill(0);
        for s in self.signals(block) {
            let value = s.raw_value(&hardware) as f64 * s.scale;
            s.store_field(bytes, value);
        }
    }

    /// Encodes an output block in place: our layout becomes the hardware's bytes.
    pub fn encode<T: HliType>(&self, block: Block, ours: &mut T) {
        if !self.maps(block) {
            return;
        }
        let bytes = bytemuck::bytes_of_mut(ours);
        let canonical: [u8; 40] = copy40(bytes);
        bytes.fill(0);
        for s in self.signals(block) {
            let raw = s.load_field(&canonical) / s.scale;
            s.store_raw(bytes, raw);
        }
    }
}

/// The first 40 bytes of a block (the largest is 40).
fn copy40(bytes: &[u8]) -> [u8; 40] {
    let mut out = [0u8; 40];
    let n = bytes.len().min(40);
    out[..n].copy_from_slice(&bytes[..n]);
    out
}

impl SignalMap {
    /// The signal's raw value in the hardware's bytes (sign-extended when signed).
    fn raw_value(&self, bytes: &[u8]) -> i64 {
        let mut word = 0u64;
        for k in 0..self.width {
            let bit = self.bit + k;
            let set = bytes[(bit / 8) as usize] >> (bit % 8) & 1;
            word |= u64::from(set) << k;
        }
        if self.signed && word >> (self.width - 1) & 1 == 1 {
            (word | !((1u64 << self.width) - 1)) as i64
        } else {
            word as i64
        }
    }

    /// Writes `raw` (rounded, saturated to the width) into the hardware's bytes.
    fn store_raw(&self, bytes: &mut [u8], raw: f64) {
        let (min, max) = if self.signed {
            (-(1i64 << (self.width - 1)), (1i64 << (self.width - 1)) - 1)
        } else {
            (0, (1i64 << self.width) - 1)
        };
        let value = if raw.is_nan() {
            0
        } else {
            (raw.round().clamp(min as f64, max as f64)) as i64
        };
        let word = value as u64;
        for k in 0..self.width {
            let bit = self.bit + k;
            let at = &mut bytes[(bit / 8) as usize];
            let mask = 1u8 << (bit % 8);
            if word >> k & 1 == 1 {
                *at |= mask;
            } else {
                *at &= !mask;
            }
        }
    }

    /// Our field's value as a number.
    fn load_field(&self, bytes: &[u8]) -> f64 {
        let at = self.field_offset as usize;
        let n = self.field.size();
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(&bytes[at..at + n]);
        match self.field {
            Scalar::Bool | Scalar::Usint => f64::from(b[0]),
            Scalar::Sint => f64::from(b[0] as i8),
            Scalar::Uint => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Scalar::Int => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Scalar::Udint => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::Dint => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::Real => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::Ulint => u64::from_le_bytes(b) as f64,
            Scalar::Lint => i64::from_le_bytes(b) as f64,
            Scalar::Lreal => f64::from_le_bytes(b),
        }
    }

    /// Stores `value` (rounded, saturated to the field's type) into our field.
    fn store_field(&self, bytes: &mut [u8], value: f64) {
        let at = self.field_offset as usize;
        let whole = |min: f64, max: f64| value.round().clamp(min, max);
        let encoded: [u8; 8] = match self.field {
            Scalar::Bool | Scalar::Usint => pad(&[whole(0.0, 255.0) as u8]),
            Scalar::Sint => pad(&(whole(-128.0, 127.0) as i8).to_le_bytes()),
            Scalar::Uint => pad(&(whole(0.0, 65535.0) as u16).to_le_bytes()),
            Scalar::Int => pad(&(whole(-32768.0, 32767.0) as i16).to_le_bytes()),
            Scalar::Udint => pad(&(whole(0.0, u32::MAX as f64) as u32).to_le_bytes()),
            Scalar::Dint => pad(&(whole(i32::MIN as f64, i32::MAX as f64) as i32).to_le_bytes()),
            Scalar::Real => pad(&(value as f32).to_le_bytes()),
            Scalar::Ulint => (whole(0.0, u64::MAX as f64) as u64).to_le_bytes(),
            Scalar::Lint => (whole(i64::MIN as f64, i64::MAX as f64) as i64).to_le_bytes(),
            Scalar::Lreal => value.to_le_bytes(),
        };
        let n = self.field.size();
        bytes[at..at + n].copy_from_slice(&encoded[..n]);
    }
}

fn pad(bytes: &[u8]) -> [u8; 8] {
    let mut out = [0u8; 8];
    out[..bytes.len()].copy_from_slice(bytes);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(toml: &str) -> Result<ImageMap, String> {
        #[derive(Deserialize)]
        struct Holder {
            map: ImageMap,
        }
        toml::from_str::<Holder>(toml)
            .map(|h| h.map)
            .map_err(|e| e.to_string())
    }

    /// A 16-bit signed position at byte 2 scaled by 4, and a status bit at byte 0 bit 3:
    /// decoded into our layout; everything else reads 0.
    #[test]
    fn inputs_are_decoded_from_their_bits_and_scaled() {
        let m = map(r#"map = [
                { signal = "enc_in.nInData1", bit = 16, width = 16, signed = true, scale = 4.0 },
                { signal = "enc_in.nStatus1", bit = 3, width = 1 },
            ]"#)
        .unwrap();
        let mut raw: NcEncoderIn = bytemuck::Zeroable::zeroed();
        let bytes = bytemuck::bytes_of_mut(&mut raw);
        bytes[0] = 0b1000 | 0b0001; // the status bit and a bit nobody maps
        bytes[2..4].copy_from_slice(&(-1234i16).to_le_bytes());
        bytes[11] = 1; // where our nStatus4 lies: not mapped, so not read
        m.decode(Block::EncIn, &mut raw);
        assert_eq!(raw.nInData1, -4936);
        assert_eq!(raw.nStatus1, 1);
        assert_eq!(raw.nStatus4, 0);
        assert_eq!(raw.nInData2, 0);
    }

    /// An output velocity of 100,000 increments at a scale of 10 is 10,000 raw in 16 bits at
    /// byte 4; 1,000,000 saturates at 32767; blocks not named pass unchanged.
    #[test]
    fn outputs_are_encoded_rounded_and_saturated() {
        let m = map(r#"map = [{ signal = "drive_out.nOutData1", bit = 32, width = 16, signed = true, scale = 10.0 }]"#)
            .unwrap();
        for (ours, raw) in [
            (100_000, 10_000i16),
            (1_000_000, 32767),
            (-1_000_000, -32768),
        ] {
            let mut out: NcDriveOut = bytemuck::Zeroable::zeroed();
            out.nOutData1 = ours;
            out.nCtrl1 = 1;
            m.encode(Block::DriveOut, &mut out);
            let bytes = bytemuck::bytes_of(&out);
            assert_eq!(i16::from_le_bytes([bytes[4], bytes[5]]), raw);
            assert!(
                bytes[..4].iter().chain(&bytes[6..]).all(|b| *b == 0),
                "{bytes:?}"
            );
        }
        let mut enc: NcEncoderOut = bytemuck::Zeroable::zeroed();
        enc.nOutData1 = 7;
        m.encode(Block::EncOut, &mut enc);
        assert_eq!(enc.nOutData1, 7, "an unmapped block is ours");
    }

    #[test]
    fn a_map_that_overlaps_leaves_its_block_or_names_no_signal_is_refused() {
        for (entries, expect) in [
            (
                r#"{ signal = "enc_in.nInData1", bit = 0, width = 16 }, { signal = "enc_in.nStatus1", bit = 15, width = 1 }"#,
                "io.map[1]: bits 15..16 overlap entry 0's",
            ),
            (
                r#"{ signal = "enc_in.nInData1", bit = 310, width = 16 }"#,
                "leave the 40 bytes",
            ),
            (
                r#"{ signal = "drive_out.nCtrl1", bit = 250, width = 8 }"#,
                "leave the 32 bytes",
            ),
            (
                r#"{ signal = "drive_out.nCtrl1", bit = 4294967295, width = 8 }"#,
                "bits 4294967295..4294967303 leave the 32 bytes",
            ),
            (
                r#"{ signal = "enc_in.nStatus1", bit = 0, width = 8 }"#,
                "enc_in is mapped without enc_in.nInData1",
            ),
            (
                r#"{ signal = "enc_in.nPosition", bit = 0, width = 16 }"#,
                "no signal \"nPosition\"",
            ),
            (
                r#"{ signal = "enc_in.fill_up_1", bit = 0, width = 16 }"#,
                "no signal",
            ),
            (
                r#"{ signal = "motor.nInData1", bit = 0, width = 16 }"#,
                "block \"motor\"",
            ),
            (
                r#"{ signal = "enc_in.nInData1", bit = 0, width = 33 }"#,
                "width 33",
            ),
            (
                r#"{ signal = "enc_in.nInData1", bit = 0, width = 8, scale = 0.0 }"#,
                "scale 0",
            ),
            (
                r#"{ signal = "enc_in.nInData1", bit = 0, width = 8 }, { signal = "enc_in.nInData1", bit = 8, width = 8 }"#,
                "mapped twice",
            ),
            (
                r#"{ signal = "enc_in.nInData1", bit = 0 }"#,
                "missing field `width`",
            ),
        ] {
            let e = map(&format!("map = [{entries}]")).unwrap_err();
            assert!(e.contains(expect), "{entries}: {e}");
        }
    }
}
