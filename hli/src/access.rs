//! Reading and writing single leaves of the image by their ST path, for tools that are driven
//! by text: the scenario runner's trace (`gpAx[6]^lr_state.current_position_acs_r`) and the
//! PLC timeline (`gpCh[0]^channel_mc_control.dyn_cs.enable_w := TRUE`).
//!
//! A path is resolved once into a [`Leaf`] (offset, type, writer); reading and writing a
//! resolved leaf does not allocate and goes through the atomic accessors of [`crate::raw`].

use crate::desc::{Scalar, SymbolWriter};
use crate::raw::ImageMemory;
use crate::symbols::{SymbolKind, SymbolTable};

/// A resolved leaf of the image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Leaf {
    /// Offset from the start of the image.
    pub offset: usize,
    /// Elementary type.
    pub scalar: Scalar,
    /// Who writes it.
    pub writer: SymbolWriter,
}

/// A raw value of a leaf, widened without loss.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    /// BOOL and the signed integers.
    Int(i64),
    /// The unsigned integers.
    Unsigned(u64),
    /// REAL and LREAL.
    Real(f64),
}

impl Value {
    /// The value as a float (for comparisons across types).
    pub fn as_f64(self) -> f64 {
        match self {
            Value::Int(v) => v as f64,
            Value::Unsigned(v) => v as f64,
            Value::Real(v) => v,
        }
    }
}

impl core::fmt::Display for Value {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Value::Int(v) => write!(f, "{v}"),
            Value::Unsigned(v) => write!(f, "{v}"),
            // Shortest text that reads back to the same bits.
            Value::Real(v) => write!(f, "{v:?}"),
        }
    }
}

/// Why a path or a value was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AccessError {
    /// No symbol has this path.
    #[error("no symbol `{0}` (see `cnc hli symbols`)")]
    UnknownPath(String),
    /// The path names a struct or array, not a leaf.
    #[error("`{0}` is a struct or array, not a leaf")]
    NotALeaf(String),
    /// The value does not fit the leaf's type.
    #[error("{value} does not fit `{path}` of type {ty}")]
    OutOfRange {
        /// The path.
        path: String,
        /// The value.
        value: String,
        /// The leaf's ST type.
        ty: &'static str,
    },
}

impl Leaf {
    /// Resolves `path` in this build's symbol table.
    pub fn resolve(path: &str) -> Result<Leaf, AccessError> {
        let symbol = SymbolTable::global()
            .lookup(path)
            .ok_or_else(|| AccessError::UnknownPath(path.to_string()))?;
        match symbol.kind {
            SymbolKind::Leaf(scalar) => Ok(Leaf {
                offset: symbol.offset,
                scalar,
                writer: symbol.writer,
            }),
            _ => Err(AccessError::NotALeaf(path.to_string())),
        }
    }

    /// Whether the PLC may write this leaf (PLC-owned or a shared semaphore/command word).
    pub fn plc_writable(&self) -> bool {
        matches!(self.writer, SymbolWriter::Plc | SymbolWriter::Both)
    }

    /// Reads the leaf (acquire: a semaphore read orders the payload reads after it).
    pub fn read(&self, memory: &ImageMemory) -> Value {
        let o = self.offset;
        match self.scalar {
            Scalar::Bool | Scalar::Usint => {
                Value::Unsigned(u64::from(memory.place::<u8>(o).load_acquire()))
            }
            Scalar::Sint => Value::Int(i64::from(memory.place::<i8>(o).load_acquire())),
            Scalar::Uint => Value::Unsigned(u64::from(memory.place::<u16>(o).load_acquire())),
            Scalar::Int => Value::Int(i64::from(memory.place::<i16>(o).load_acquire())),
            Scalar::Udint => Value::Unsigned(u64::from(memory.place::<u32>(o).load_acquire())),
            Scalar::Dint => Value::Int(i64::from(memory.place::<i32>(o).load_acquire())),
            Scalar::Ulint => Value::Unsigned(memory.place::<u64>(o).load_acquire()),
            Scalar::Lint => Value::Int(memory.place::<i64>(o).load_acquire()),
            Scalar::Real => Value::Real(f64::from(memory.place::<f32>(o).load_acquire())),
            Scalar::Lreal => Value::Real(memory.place::<f64>(o).load_acquire()),
        }
    }

    /// Converts `value` to this leaf's type: integers must fit, floats go to integer leaves
    /// only when they are whole; BOOL takes 0 or 1.
    pub fn check(&self, path: &str, value: Value) -> Result<Value, AccessError> {
        let refuse = || AccessError::OutOfRange {
            path: path.to_string(),
            value: value.to_string(),
            ty: self.scalar.st_name(),
        };
        let (lo, hi): (f64, f64) = match self.scalar {
            Scalar::Real | Scalar::Lreal => {
                let v = value.as_f64();
                return if v.is_finite() {
                    Ok(Value::Real(v))
                } else {
                    Err(refuse())
                };
            }
            Scalar::Bool => (0.0, 1.0),
            Scalar::Usint => (0.0, u8::MAX as f64),
            Scalar::Sint => (i8::MIN as f64, i8::MAX as f64),
            Scalar::Uint => (0.0, u16::MAX as f64),
            Scalar::Int => (i16::MIN as f64, i16::MAX as f64),
            Scalar::Udint => (0.0, u32::MAX as f64),
            Scalar::Dint => (i32::MIN as f64, i32::MAX as f64),
            Scalar::Ulint | Scalar::Lint => (i64::MIN as f64, u64::MAX as f64),
        };
        let whole = match value {
            Value::Real(v) if v.fract() != 0.0 || !v.is_finite() => return Err(refuse()),
            Value::Real(v) => v as i128,
            Value::Int(v) => i128::from(v),
            Value::Unsigned(v) => i128::from(v),
        };
        let fits = match self.scalar {
            Scalar::Ulint => (0..=i128::from(u64::MAX)).contains(&whole),
            Scalar::Lint => (i128::from(i64::MIN)..=i128::from(i64::MAX)).contains(&whole),
            _ => (lo..=hi).contains(&(whole as f64)),
        };
        if !fits {
            return Err(refuse());
        }
        Ok(if whole < 0 {
            Value::Int(whole as i64)
        } else {
            Value::Unsigned(whole as u64)
        })
    }

    /// Writes `value` with release ordering (so writes made in order are seen in order, and a
    /// semaphore written last publishes everything before it). `value` must have passed
    /// [`Leaf::check`]; other values are truncated like an `as` cast.
    pub fn write(&self, memory: &ImageMemory, value: Value) {
        let o = self.offset;
        let int = match value {
            Value::Int(v) => v,
            Value::Unsigned(v) => v as i64,
            Value::Real(v) => v as i64,
        };
        match self.scalar {
            Scalar::Bool | Scalar::Usint => memory.place::<u8>(o).store_release(int as u8),
            Scalar::Sint => memory.place::<i8>(o).store_release(int as i8),
            Scalar::Uint => memory.place::<u16>(o).store_release(int as u16),
            Scalar::Int => memory.place::<i16>(o).store_release(int as i16),
            Scalar::Udint => memory.place::<u32>(o).store_release(int as u32),
            Scalar::Dint => memory.place::<i32>(o).store_release(int as i32),
            Scalar::Ulint => memory.place::<u64>(o).store_release(int as u64),
            Scalar::Lint => memory.place::<i64>(o).store_release(int),
            Scalar::Real => memory.place::<f32>(o).store_release(value.as_f64() as f32),
            Scalar::Lreal => memory.place::<f64>(o).store_release(value.as_f64()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::heap_image;

    const STATE: &str = "gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state";
    const ROTATION: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[2]";

    #[test]
    fn paths_resolve_to_leaves_with_their_writer() {
        let state = Leaf::resolve(STATE).unwrap();
        assert_eq!(state.scalar, Scalar::Udint);
        assert!(!state.plc_writable());
        assert!(Leaf::resolve(ROTATION).unwrap().plc_writable());
        assert!(matches!(
            Leaf::resolve("gpCh[0]^channel_mc_control.dyn_cs"),
            Err(AccessError::NotALeaf(_))
        ));
        assert!(matches!(
            Leaf::resolve("gpCh[99]^x"),
            Err(AccessError::UnknownPath(_))
        ));
    }

    #[test]
    fn values_round_trip_and_out_of_range_values_are_refused() {
        let memory = heap_image(1, 1);
        let rotation = Leaf::resolve(ROTATION).unwrap();
        let v = rotation.check(ROTATION, Value::Int(-900_000)).unwrap();
        rotation.write(&memory, v);
        assert_eq!(rotation.read(&memory), Value::Int(-900_000));
        assert!(rotation.check(ROTATION, Value::Real(0.5)).is_err());
        assert!(rotation.check(ROTATION, Value::Int(1 << 40)).is_err());
        let enable = Leaf::resolve("gpCh[0]^channel_mc_control.dyn_cs.enable_w").unwrap();
        assert!(enable.check("enable", Value::Int(2)).is_err());
        let v = enable.check("enable", Value::Int(1)).unwrap();
        enable.write(&memory, v);
        assert_eq!(enable.read(&memory), Value::Unsigned(1));
    }
}
