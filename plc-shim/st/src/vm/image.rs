//! The HLI image as a program's pointers reach it: a pointer into the image carries
//! [`IMAGE_TAG`]; every access is an atomic of the leaf's own size at the leaf's start
//! (anything else is a fault, so the image's rule that a byte range is always accessed with
//! atomics of one size holds), and a write to a leaf the CNC or the drives write is a fault.

use super::{Exec, Fault, V};
use crate::types::Elem;
use hli::desc::SymbolWriter;
use hli::symbols::{SymbolKind, SymbolTable};
use std::sync::OnceLock;

/// The bit a pointer into the image carries (the program's own pointers are below it).
pub const IMAGE_TAG: i64 = 1 << 62;

/// Per byte of the image: the size of the leaf that starts there (0 elsewhere), and whether
/// the PLC may write it.
pub(super) struct ImageMap {
    pub(super) leaf: Vec<u8>,
    pub(super) writable: Vec<bool>,
}

pub(super) fn map() -> &'static ImageMap {
    static MAP: OnceLock<ImageMap> = OnceLock::new();
    MAP.get_or_init(|| {
        let size = hli::image::IMAGE_SIZE;
        let mut m = ImageMap {
            leaf: vec![0; size],
            writable: vec![false; size],
        };
        for s in SymbolTable::global().symbols() {
            if let (SymbolKind::Leaf(_), true) = (&s.kind, s.offset + s.size <= size) {
                m.leaf[s.offset] = s.size as u8;
                let plc = matches!(s.writer, SymbolWriter::Plc | SymbolWriter::Both);
                m.writable[s.offset..s.offset + s.size].fill(plc);
            }
        }
        m
    })
}

/// Builds the image's map now (it allocates), so that the cycle's first image access does not.
pub fn warm() {
    map();
}

/// The tagged pointer to image offset `offset` of the node at `path` (`gpCh[3]^`).
pub fn pointer_to(path: &str) -> Option<i64> {
    let s = SymbolTable::global().lookup(path)?;
    Some(IMAGE_TAG | (s.offset as i64 + 1))
}

impl Exec<'_> {
    /// The leaf of type `t` at image offset `at`, checked.
    #[inline]
    fn image_leaf(&self, at: usize, t: Elem) -> Result<(&hli::ImageMemory, &ImageMap), Fault> {
        let (image, map) = self.image.ok_or(Fault::BadPointer)?;
        let size = map.leaf.get(at).copied().unwrap_or(0);
        if usize::from(size) != t.size() || at + t.size() > image.len() {
            return Err(Fault::BadPointer);
        }
        Ok((image, map))
    }

    pub(super) fn image_read(&self, at: usize, t: Elem) -> Result<V, Fault> {
        let (m, _) = self.image_leaf(at, t)?;
        let v = match t {
            Elem::Bool | Elem::Byte | Elem::USInt => V::I(i64::from(m.place::<u8>(at).load())),
            Elem::SInt => V::I(i64::from(m.place::<i8>(at).load())),
            Elem::Word | Elem::UInt => V::I(i64::from(m.place::<u16>(at).load())),
            Elem::Int => V::I(i64::from(m.place::<i16>(at).load())),
            Elem::DWord | Elem::UDInt => V::I(i64::from(m.place::<u32>(at).load())),
            Elem::DInt | Elem::Time => V::I(i64::from(m.place::<i32>(at).load())),
            Elem::Real => V::F(f64::from(m.place::<f32>(at).load())),
            Elem::LReal => V::F(m.place::<f64>(at).load()),
            Elem::LWord | Elem::ULInt | Elem::LInt | Elem::LTime => V::I(m.place::<i64>(at).load()),
        };
        // The image is the partner's: a real it holds is checked before the program sees it.
        match v {
            V::F(x) if !x.is_finite() => Err(Fault::NotFinite),
            _ => Ok(v),
        }
    }

    pub(super) fn image_write(&mut self, at: usize, t: Elem, v: V) -> Result<(), Fault> {
        let (m, map) = self.image_leaf(at, t)?;
        if !map.writable[at] {
            return Err(Fault::ReadOnly);
        }
        let finite = match t {
            Elem::Real => (v.float() as f32).is_finite(),
            Elem::LReal => v.float().is_finite(),
            _ => true,
        };
        if !finite {
            return Err(Fault::NotFinite);
        }
        match t {
            Elem::Bool | Elem::Byte | Elem::USInt => m.place::<u8>(at).store(v.int() as u8),
            Elem::SInt => m.place::<i8>(at).store(v.int() as i8),
            Elem::Word | Elem::UInt => m.place::<u16>(at).store(v.int() as u16),
            Elem::Int => m.place::<i16>(at).store(v.int() as i16),
            Elem::DWord | Elem::UDInt => m.place::<u32>(at).store(v.int() as u32),
            Elem::DInt | Elem::Time => m.place::<i32>(at).store(v.int() as i32),
            Elem::Real => m.place::<f32>(at).store(v.float() as f32),
            Elem::LReal => m.place::<f64>(at).store(v.float()),
            Elem::LWord | Elem::ULInt | Elem::LInt | Elem::LTime => {
                m.place::<i64>(at).store(v.int())
            }
        }
        Ok(())
    }
}
