//! Where every value lives in a program's memory: sizes and alignments of the types, offsets
//! of fields and of a function block's variables in its instance, and the static places of
//! the globals, of each program's variables and of each function's frame (a function has one
//! frame: recursion is refused, so no call needs a second).

use crate::ast::PouKind;
use crate::check::std_lib::StdFb;
use crate::check::{Checked, Type};
use crate::types::Elem;

/// The layout of a checked program.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Layout {
    /// Per structure: size, alignment, field offsets.
    pub structs: Vec<(u32, u32, Vec<u32>)>,
    /// Per POU: the size and alignment of an instance (a frame for a function) and each
    /// variable's offset in it.
    pub pous: Vec<(u32, u32, Vec<u32>)>,
    /// Per POU: where its one static instance starts (programs and functions; 0 for
    /// function blocks, which live inside their owners).
    pub statics: Vec<u32>,
    /// Per global: its offset.
    pub globals: Vec<u32>,
    /// Bytes of memory the program needs.
    pub size: u32,
}

/// The most memory a program may take: 64 MiB.
pub const MAX_MEMORY: u64 = 64 << 20;

/// A standard function block's member offsets, size and alignment: the members first (inputs
/// and outputs by name), then its own state.
pub fn std_fb(fb: StdFb) -> (&'static [(&'static str, u32)], u32, u32) {
    match fb {
        // IN, Q, (running @2), PT (ms), ET (ms), (start ns @16).
        StdFb::Ton | StdFb::Tof | StdFb::Tp => {
            (&[("IN", 0), ("Q", 1), ("PT", 4), ("ET", 8)], 24, 8)
        }
        // CLK, Q, (the last CLK @2).
        StdFb::RTrig | StdFb::FTrig => (&[("CLK", 0), ("Q", 1)], 3, 1),
        // CU/CD, RESET/LOAD, Q, (the last CU/CD @3), PV, CV.
        StdFb::Ctu => (
            &[("CU", 0), ("RESET", 1), ("Q", 2), ("PV", 4), ("CV", 6)],
            8,
            2,
        ),
        StdFb::Ctd => (
            &[("CD", 0), ("LOAD", 1), ("Q", 2), ("PV", 4), ("CV", 6)],
            8,
            2,
        ),
        // CU, CD, RESET, LOAD, QU, QD, (the last CU @6 and CD @7), PV, CV.
        StdFb::Ctud => (
            &[
                ("CU", 0),
                ("CD", 1),
                ("RESET", 2),
                ("LOAD", 3),
                ("QU", 4),
                ("QD", 5),
                ("PV", 8),
                ("CV", 10),
            ],
            12,
            2,
        ),
        StdFb::Rs => (&[("SET", 0), ("RESET1", 1), ("Q1", 2)], 3, 1),
        StdFb::Sr => (&[("SET1", 0), ("RESET", 1), ("Q1", 2)], 3, 1),
    }
}

/// The offset of standard block member `name` (ASCII case ignored).
pub fn std_member(fb: StdFb, name: &str) -> Option<u32> {
    std_fb(fb)
        .0
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, o)| *o)
}

fn align_to(offset: u64, align: u32) -> u64 {
    offset.div_ceil(u64::from(align)) * u64::from(align)
}

impl Layout {
    /// The layout of `c`, or why it has none (too large, or a function block that contains
    /// itself).
    pub fn of(c: &Checked) -> Result<Layout, String> {
        let mut l = Layout {
            structs: vec![(0, 0, Vec::new()); c.structs.len()],
            pous: vec![(0, 0, Vec::new()); c.pous.len()],
            statics: vec![0; c.pous.len()],
            ..Layout::default()
        };
        let mut state = vec![0u8; c.structs.len() + c.pous.len()];
        for i in 0..c.structs.len() {
            l.struct_layout(c, i, &mut state)?;
        }
        for i in 0..c.pous.len() {
            l.pou_layout(c, i, &mut state)?;
        }
        let mut at = 0u64;
        for g in &c.globals {
            let (size, align) = l.size_align(c, &g.ty);
            at = align_to(at, align);
            l.globals.push(at as u32);
            at += u64::from(size);
        }
        for (i, pou) in c.pous.iter().enumerate() {
            // A method's frame is its instance (its program's memory).
            if !matches!(pou.kind, PouKind::FunctionBlock | PouKind::Method) {
                let (size, align, _) = &l.pous[i];
                at = align_to(at, *align);
                l.statics[i] = at as u32;
                at += u64::from(*size);
            }
        }
        if at > MAX_MEMORY {
            return Err(format!(
                "the program needs {at} bytes of memory: at most {MAX_MEMORY}"
            ));
        }
        l.size = at as u32;
        Ok(l)
    }

    /// Size and alignment of a value of `ty` (structures and POUs laid out already).
    pub fn size_align(&self, c: &Checked, ty: &Type) -> (u32, u32) {
        match ty {
            Type::Elem(e) => (e.size() as u32, e.size() as u32),
            Type::Str(n) => (n + 1, 1),
            Type::Pointer(_) => (8, 8),
            Type::Array(dims, element) => {
                let (size, align) = self.size_align(c, element);
                let count = dims
                    .iter()
                    .fold(1u64, |n, (lo, hi)| n.saturating_mul(hi.abs_diff(*lo) + 1));
                let stride = align_to(u64::from(size), align);
                (
                    stride.saturating_mul(count).min(u64::from(u32::MAX)) as u32,
                    align,
                )
            }
            Type::Struct(i) => (self.structs[*i].0, self.structs[*i].1),
            Type::Fb(i) => (self.pous[*i].0, self.pous[*i].1),
            Type::StdFb(fb) => {
                let (_, size, align) = std_fb(*fb);
                (size, align)
            }
            Type::Enum(i) => {
                let base: Elem = c.enums[*i].base;
                (base.size() as u32, base.size() as u32)
            }
            Type::Error => (0, 1),
        }
    }

    /// Lays out the types `ty` contains before it; `state` marks those in progress (1) and
    /// done (2), so a type that contains itself is refused.
    fn needs(&mut self, c: &Checked, ty: &Type, state: &mut [u8]) -> Result<(), String> {
        match ty {
            Type::Struct(i) => self.struct_layout(c, *i, state),
            Type::Fb(i) => self.pou_layout(c, *i, state),
            Type::Array(_, element) => self.needs(c, element, state),
            _ => Ok(()),
        }
    }

    fn struct_layout(&mut self, c: &Checked, i: usize, state: &mut [u8]) -> Result<(), String> {
        match state[i] {
            2 => return Ok(()),
            1 => return Err(format!("{} contains itself", c.structs[i].name)),
            _ => state[i] = 1,
        }
        let types: Vec<Type> = c.structs[i].fields.iter().map(|(_, t)| t.clone()).collect();
        self.structs[i] = self.record(c, &types, state)?;
        if c.structs[i].union {
            // Every field at offset 0; the size the largest's, aligned to the strictest.
            let (mut size, mut align) = (0, 1);
            for t in &types {
                let (s, a) = self.size_align(c, t);
                (size, align) = (size.max(s), align.max(a));
            }
            let offsets = vec![0; types.len()];
            self.structs[i] = (size.div_ceil(align) * align, align, offsets);
        }
        state[i] = 2;
        Ok(())
    }

    fn pou_layout(&mut self, c: &Checked, i: usize, state: &mut [u8]) -> Result<(), String> {
        let k = c.structs.len() + i;
        match state[k] {
            2 => return Ok(()),
            1 => return Err(format!("{} contains an instance of itself", c.pous[i].name)),
            _ => state[k] = 1,
        }
        let mut types: Vec<Type> = c.pous[i].vars.iter().map(|v| v.ty.clone()).collect();
        // A function's value goes last in its frame.
        types.extend(c.pous[i].returns.clone());
        self.pous[i] = self.record(c, &types, state)?;
        state[k] = 2;
        Ok(())
    }

    /// Members of `types` one after the other, each aligned: size, alignment, offsets.
    fn record(
        &mut self,
        c: &Checked,
        types: &[Type],
        state: &mut [u8],
    ) -> Result<(u32, u32, Vec<u32>), String> {
        let (mut at, mut align, mut offsets) = (0u64, 1u32, Vec::with_capacity(types.len()));
        for ty in types {
            self.needs(c, ty, state)?;
            let (size, a) = self.size_align(c, ty);
            at = align_to(at, a);
            offsets.push(at as u32);
            at += u64::from(size);
            align = align.max(a);
        }
        if at > MAX_MEMORY {
            return Err(format!("a structure of {at} bytes: at most {MAX_MEMORY}"));
        }
        Ok((align_to(at, align) as u32, align, offsets))
    }
}
