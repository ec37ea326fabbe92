//! The program's own memory: values of elementary types read and written at byte offsets
//! (little-endian, as the image holds them), and where a pointer value points.

use super::{Fault, Run, IMAGE_TAG, V};
use crate::types::Elem;

/// The first `N` bytes of a slice that has them (the caller took exactly `N`).
pub(crate) fn arr<const N: usize>(b: &[u8]) -> [u8; N] {
    let mut out = [0u8; N];
    out.copy_from_slice(&b[..N]);
    out
}

/// Where a place is: in the program's own memory, or in the HLI image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Loc {
    Own(usize),
    Image(usize),
}

impl Loc {
    pub(crate) fn plus(self, n: usize) -> Loc {
        match self {
            Loc::Own(a) => Loc::Own(a + n),
            Loc::Image(a) => Loc::Image(a + n),
        }
    }
}

/// Where pointer value `p` points: NULL (0) and values below it are faults.
#[inline]
pub(crate) fn pointed(p: i64) -> Run<Loc> {
    let image = p & IMAGE_TAG != 0;
    // NULL, and values below it (a word of other bits read as a pointer), are no place.
    let at = (p & !IMAGE_TAG)
        .checked_sub(1)
        .filter(|a| *a >= 0)
        .ok_or(Fault::BadPointer)?;
    Ok(if image {
        Loc::Image(at as usize)
    } else {
        Loc::Own(at as usize)
    })
}

/// The pointer value to a place (what `ADR` gives): [`pointed`]'s inverse.
pub(crate) fn tagged(at: Loc) -> i64 {
    match at {
        Loc::Own(at) => at as i64 + 1,
        Loc::Image(at) => IMAGE_TAG | (at as i64 + 1),
    }
}

/// Sets the value of type `t` at `at` of a program's memory.
#[inline(always)]
pub(crate) fn write_mem(m: &mut [u8], at: usize, t: Elem, v: V) -> Run<()> {
    // Each width copied as a constant number of bytes: no call to `memcpy`.
    fn put<const N: usize>(m: &mut [u8], at: usize, bytes: [u8; N]) -> Run<()> {
        let slot = m.get_mut(at..at + N).ok_or(Fault::BadPointer)?;
        slot.copy_from_slice(&bytes);
        Ok(())
    }
    let i = v.int();
    match t {
        Elem::Real => put(m, at, (v.float() as f32).to_le_bytes()),
        Elem::LReal => put(m, at, v.float().to_le_bytes()),
        _ => match t.size() {
            1 => put(m, at, [i as u8]),
            2 => put(m, at, (i as u16).to_le_bytes()),
            4 => put(m, at, (i as u32).to_le_bytes()),
            _ => put(m, at, i.to_le_bytes()),
        },
    }
}

/// The value of type `t` at `at` of a program's memory.
#[inline(always)]
pub(crate) fn read_mem(m: &[u8], at: usize, t: Elem) -> Run<V> {
    let bytes = |n: usize| m.get(at..at + n).ok_or(Fault::BadPointer);
    Ok(match t {
        Elem::Bool | Elem::Byte | Elem::USInt => V::I(i64::from(bytes(1)?[0])),
        Elem::SInt => V::I(i64::from(bytes(1)?[0] as i8)),
        Elem::Word | Elem::UInt => V::I(i64::from(u16::from_le_bytes(arr(bytes(2)?)))),
        Elem::Int => V::I(i64::from(i16::from_le_bytes(arr(bytes(2)?)))),
        Elem::DWord | Elem::UDInt => V::I(i64::from(u32::from_le_bytes(arr(bytes(4)?)))),
        Elem::DInt | Elem::Time => V::I(i64::from(i32::from_le_bytes(arr(bytes(4)?)))),
        Elem::LWord | Elem::ULInt | Elem::LInt | Elem::LTime => {
            V::I(i64::from_le_bytes(arr(bytes(8)?)))
        }
        Elem::Real => V::F(f64::from(f32::from_le_bytes(arr(bytes(4)?)))),
        Elem::LReal => V::F(f64::from_le_bytes(arr(bytes(8)?))),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn null_and_words_below_it_point_nowhere() {
        for p in [
            0,
            -1,
            i64::MIN,
            i64::MIN + 1,
            IMAGE_TAG,
            IMAGE_TAG | i64::MIN,
        ] {
            assert_eq!(pointed(p), Err(Fault::BadPointer), "{p:#x}");
        }
        assert_eq!(pointed(1), Ok(Loc::Own(0)));
        assert_eq!(pointed(IMAGE_TAG | 9), Ok(Loc::Image(8)));
    }
}
