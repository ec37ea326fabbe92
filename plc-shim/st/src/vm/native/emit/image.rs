//! Reads and writes through a pointer variable (`p^.field`): into the program's own memory
//! as a variable's, into the HLI image by the image's rules ([`super::super::super::image`]):
//! a leaf of the access's size must start there, a write must be to a leaf the PLC writes,
//! a real must be finite. The image's leaves are read and written with one machine load or
//! store of the leaf's size, which is what the image's relaxed atomics are on the machines
//! Cranelift compiles for.

use super::super::super::{Fault, IMAGE_TAG};
use super::super::at;
use super::{Emit, Val, F};
use crate::types::Elem;
use cranelift_codegen::ir::condcodes::{FloatCC, IntCC};
use cranelift_codegen::ir::{types, Block, InstBuilder, Value};

impl Emit<'_, '_> {
    /// Where the pointer variable at `(ptr, relative)` points, `plus` bytes on: the offset,
    /// and the blocks to go on in for the program's memory and for the image (switched to
    /// neither).
    fn via(&mut self, ptr: u32, relative: bool, plus: u32) -> (Value, Block, Block) {
        let off = self.own(ptr, relative);
        let p = self.mem(off, 8);
        let p = self.b.ins().load(types::I64, F, p, 0);
        let place = self.b.ins().band_imm_s(p, !IMAGE_TAG);
        // NULL, and words below it, point nowhere (`pointed`).
        let nowhere = self.b.ins().icmp_imm_s(IntCC::SignedLessThan, place, 1);
        self.fault_if(nowhere, Fault::BadPointer);
        let at = self.b.ins().iadd_imm_s(place, i64::from(plus) - 1);
        let tag = self.b.ins().band_imm_s(p, IMAGE_TAG);
        let (own, image) = (self.b.create_block(), self.b.create_block());
        self.b.ins().brif(tag, image, &[], own, &[]);
        (at, own, image)
    }

    /// The image's leaf of type `t` at offset `at`: its address, or the body stopped with
    /// [`Fault::BadPointer`] (no image, no leaf of that size starting there).
    fn leaf(&mut self, at: Value, t: Elem) -> Value {
        let image = self.b.ins().load(types::I64, F, self.cx, at::IMAGE);
        let none = self.b.ins().icmp_imm_s(IntCC::Equal, image, 0);
        self.fault_if(none, Fault::BadPointer);
        let n = t.size() as i64;
        let leaves = self.b.ins().load(types::I64, F, self.cx, at::LEAVES);
        let beyond = self
            .b
            .ins()
            .icmp(IntCC::UnsignedGreaterThanOrEqual, at, leaves);
        self.fault_if(beyond, Fault::BadPointer);
        let map = self.b.ins().load(types::I64, F, self.cx, at::LEAF);
        let size_at = self.b.ins().iadd(map, at);
        let size = self.b.ins().uload8(types::I64, F, size_at, 0);
        let other = self.b.ins().icmp_imm_s(IntCC::NotEqual, size, n);
        self.fault_if(other, Fault::BadPointer);
        let len = self.b.ins().load(types::I64, F, self.cx, at::IMAGE_LEN);
        let end = self.b.ins().iadd_imm_s(at, n);
        let past = self.b.ins().icmp(IntCC::UnsignedGreaterThan, end, len);
        self.fault_if(past, Fault::BadPointer);
        self.b.ins().iadd(image, at)
    }

    /// A real read from or written to the image, the body stopped with
    /// [`Fault::NotFinite`] when it is not finite.
    fn image_finite(&mut self, f: Value) {
        let abs = self.b.ins().fabs(f);
        let inf = match self.b.func.dfg.value_type(f) {
            types::F32 => self.b.ins().f32const(f32::INFINITY),
            _ => self.b.ins().f64const(f64::INFINITY),
        };
        let bad = self
            .b
            .ins()
            .fcmp(FloatCC::UnorderedOrGreaterThanOrEqual, abs, inf);
        self.fault_if(bad, Fault::NotFinite);
    }

    /// [`super::Op::LoadVia`].
    pub(super) fn load_via(
        &mut self,
        d: u16,
        (ptr, relative, plus): (u32, bool, u32),
        t: Elem,
        next: u64,
    ) {
        let (at, own, image) = self.via(ptr, relative, plus);
        self.b.switch_to_block(own);
        let v = self.read(at, t);
        self.put(d, v);
        self.goto(next);
        self.b.switch_to_block(image);
        let p = self.leaf(at, t);
        let v = match t {
            Elem::Real => {
                let f = self.b.ins().load(types::F32, F, p, 0);
                self.image_finite(f);
                Val::Real(self.b.ins().fpromote(types::F64, f))
            }
            Elem::LReal => {
                let f = self.b.ins().load(types::F64, F, p, 0);
                self.image_finite(f);
                Val::Real(f)
            }
            _ => Val::Int(self.load_int(p, t)),
        };
        self.put(d, v);
        self.goto(next);
    }

    /// [`super::Op::Store`] through a pointer variable: the value first, then the place.
    pub(super) fn store_via(
        &mut self,
        (ptr, relative, plus): (u32, bool, u32),
        t: Elem,
        v: Val,
        next: u64,
    ) {
        let (at, own, image) = self.via(ptr, relative, plus);
        self.b.switch_to_block(own);
        self.write(at, t, v);
        self.goto(next);
        self.b.switch_to_block(image);
        let p = self.leaf(at, t);
        let writable = self.b.ins().load(types::I64, F, self.cx, at::WRITABLE);
        let flag_at = self.b.ins().iadd(writable, at);
        let flag = self.b.ins().uload8(types::I64, F, flag_at, 0);
        let read_only = self.b.ins().icmp_imm_s(IntCC::Equal, flag, 0);
        self.fault_if(read_only, Fault::ReadOnly);
        let x = match t {
            Elem::Real => {
                let f = self.float(v);
                let f = self.b.ins().fdemote(types::F32, f);
                self.image_finite(f);
                f
            }
            Elem::LReal => {
                let f = self.float(v);
                self.image_finite(f);
                f
            }
            _ => {
                let i = self.int(v);
                match t.size() {
                    n @ (1 | 2 | 4) => self.b.ins().ireduce(super::int_type(n), i),
                    _ => i,
                }
            }
        };
        self.b.ins().store(F, x, p, 0);
        self.goto(next);
    }
}
