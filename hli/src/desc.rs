//! Type descriptions of the image, generated next to each struct by [`crate::hli_struct!`].
//!
//! One description drives four things, so they can never disagree: the symbol table (ST paths,
//! offsets, writers), the layout hash in the segment header, the generated C header, and the
//! leaf-by-leaf atomic copies between shared memory and process-local values.

use crate::raw::{AtomicLeaf, Place};
use bytemuck::Pod;

/// Which side of the HLI writes a value. Everything else only reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SymbolWriter {
    /// The CNC process writes (`*_r` elements, state images).
    Cnc,
    /// The PLC process writes (`*_w` elements, commands).
    Plc,
    /// Both sides write, following a semaphore protocol (`*_semaphore_rw`).
    Both,
    /// The drive/encoder side of the axis process image (field bus, or the simulated drive).
    Io,
    /// The field takes the writer of its parent node; a struct whose leaves differ says so.
    Parent,
}

impl SymbolWriter {
    /// Name printed in the symbol table.
    pub fn label(self) -> &'static str {
        match self {
            SymbolWriter::Cnc => "CNC",
            SymbolWriter::Plc => "PLC",
            SymbolWriter::Both => "CNC+PLC",
            SymbolWriter::Io => "IO",
            SymbolWriter::Parent => "MIXED",
        }
    }
}

/// IEC 61131-3 elementary types that appear in the image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalar {
    /// BOOL: one byte, 0 = FALSE, 1 = TRUE.
    Bool,
    /// USINT / BYTE.
    Usint,
    /// SINT.
    Sint,
    /// UINT.
    Uint,
    /// INT.
    Int,
    /// UDINT.
    Udint,
    /// DINT.
    Dint,
    /// ULINT.
    Ulint,
    /// LINT.
    Lint,
    /// REAL.
    Real,
    /// LREAL.
    Lreal,
}

impl Scalar {
    /// The ST type name.
    pub fn st_name(self) -> &'static str {
        match self {
            Scalar::Bool => "BOOL",
            Scalar::Usint => "USINT",
            Scalar::Sint => "SINT",
            Scalar::Uint => "UINT",
            Scalar::Int => "INT",
            Scalar::Udint => "UDINT",
            Scalar::Dint => "DINT",
            Scalar::Ulint => "ULINT",
            Scalar::Lint => "LINT",
            Scalar::Real => "REAL",
            Scalar::Lreal => "LREAL",
        }
    }

    /// The C type used in the generated header.
    pub fn c_name(self) -> &'static str {
        match self {
            Scalar::Bool | Scalar::Usint => "uint8_t",
            Scalar::Sint => "int8_t",
            Scalar::Uint => "uint16_t",
            Scalar::Int => "int16_t",
            Scalar::Udint => "uint32_t",
            Scalar::Dint => "int32_t",
            Scalar::Ulint => "uint64_t",
            Scalar::Lint => "int64_t",
            Scalar::Real => "float",
            Scalar::Lreal => "double",
        }
    }

    /// Size in bytes.
    pub fn size(self) -> usize {
        match self {
            Scalar::Bool | Scalar::Usint | Scalar::Sint => 1,
            Scalar::Uint | Scalar::Int => 2,
            Scalar::Udint | Scalar::Dint | Scalar::Real => 4,
            Scalar::Ulint | Scalar::Lint | Scalar::Lreal => 8,
        }
    }
}

/// What a type is made of.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    /// An elementary value.
    Scalar(Scalar),
    /// A struct with named fields.
    Struct {
        /// ST type name, also the C typedef name.
        name: &'static str,
        /// Fields in memory order.
        fields: &'static [FieldDesc],
    },
    /// `ARRAY [0..len-1] OF elem`.
    Array {
        /// Element type.
        elem: fn() -> TypeDesc,
        /// Number of elements.
        len: usize,
    },
}

/// Description of one type of the image.
#[derive(Debug, Clone, Copy)]
pub struct TypeDesc {
    /// Size in bytes (`size_of`).
    pub size: usize,
    /// Alignment in bytes (`align_of`).
    pub align: usize,
    /// Structure.
    pub kind: Kind,
}

impl TypeDesc {
    /// The ST spelling of the type, e.g. `DINT`, `HLI_COORDINATE_SYSTEM_INT`,
    /// `ARRAY [0..2] OF DINT`.
    pub fn st_name(&self) -> String {
        match self.kind {
            Kind::Scalar(s) => s.st_name().to_string(),
            Kind::Struct { name, .. } => name.to_string(),
            Kind::Array { elem, len } => {
                format!(
                    "ARRAY[0..{}]OF({})",
                    len.saturating_sub(1),
                    elem().st_name()
                )
            }
        }
    }
}

/// Description of one struct field.
#[derive(Debug, Clone, Copy)]
pub struct FieldDesc {
    /// Field name as in the ST path.
    pub name: &'static str,
    /// Offset within the parent struct.
    pub offset: usize,
    /// The field's type.
    pub ty: fn() -> TypeDesc,
    /// Who writes it.
    pub writer: SymbolWriter,
}

/// A type that can live in the HLI image: plain old data with a description, copied to and
/// from shared memory leaf by leaf with atomics of the leaf's own size.
pub trait HliType: Pod {
    /// The type's description.
    fn desc() -> TypeDesc;
    /// Copies the value at `place` out of the image.
    fn load(place: Place<'_, Self>) -> Self;
    /// Copies `value` into the image at `place`.
    fn store(place: Place<'_, Self>, value: &Self);
}

macro_rules! scalar_types {
    ($($t:ty => $s:ident),* $(,)?) => {$(
        impl HliType for $t {
            fn desc() -> TypeDesc {
                TypeDesc { size: core::mem::size_of::<$t>(), align: core::mem::align_of::<$t>(),
                           kind: Kind::Scalar(Scalar::$s) }
            }
            #[inline]
            fn load(place: Place<'_, Self>) -> Self { AtomicLeaf::load_at(place, core::sync::atomic::Ordering::Relaxed) }
            #[inline]
            fn store(place: Place<'_, Self>, value: &Self) {
                AtomicLeaf::store_at(place, *value, core::sync::atomic::Ordering::Relaxed)
            }
        }
    )*};
}

scalar_types!(
    i8 => Sint, u16 => Uint, i16 => Int, u32 => Udint, i32 => Dint,
    u64 => Ulint, i64 => Lint, f32 => Real, f64 => Lreal,
);

/// `u8` is USINT; BOOL fields use [`Bool`], a distinct one-byte type.
impl HliType for u8 {
    fn desc() -> TypeDesc {
        TypeDesc {
            size: 1,
            align: 1,
            kind: Kind::Scalar(Scalar::Usint),
        }
    }
    #[inline]
    fn load(place: Place<'_, Self>) -> Self {
        place.load()
    }
    #[inline]
    fn store(place: Place<'_, Self>, value: &Self) {
        place.store(*value)
    }
}

/// An ST `BOOL`: one byte where 0 is FALSE and 1 is TRUE. Any other byte written by a foreign
/// process is representable (so reading it is sound) and is reported by [`Bool::get`].
#[repr(transparent)]
#[derive(Clone, Copy, PartialEq, Eq, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Bool(pub u8);

impl Bool {
    /// TRUE.
    pub const TRUE: Bool = Bool(1);
    /// FALSE.
    pub const FALSE: Bool = Bool(0);

    /// Decodes the byte; `Err(raw)` when it is neither 0 nor 1.
    pub fn get(self) -> Result<bool, u8> {
        match self.0 {
            0 => Ok(false),
            1 => Ok(true),
            raw => Err(raw),
        }
    }
}

impl From<bool> for Bool {
    fn from(value: bool) -> Self {
        Bool(u8::from(value))
    }
}

impl core::fmt::Debug for Bool {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.get() {
            Ok(v) => write!(f, "{v}"),
            Err(raw) => write!(f, "Bool(invalid {raw})"),
        }
    }
}

impl HliType for Bool {
    fn desc() -> TypeDesc {
        TypeDesc {
            size: 1,
            align: 1,
            kind: Kind::Scalar(Scalar::Bool),
        }
    }
    #[inline]
    fn load(place: Place<'_, Self>) -> Self {
        Bool(place.cast::<u8>().load())
    }
    #[inline]
    fn store(place: Place<'_, Self>, value: &Self) {
        place.cast::<u8>().store(value.0)
    }
}

impl<T: HliType, const N: usize> HliType for [T; N]
where
    [T; N]: Pod,
{
    fn desc() -> TypeDesc {
        TypeDesc {
            size: core::mem::size_of::<Self>(),
            align: core::mem::align_of::<Self>(),
            kind: Kind::Array {
                elem: T::desc,
                len: N,
            },
        }
    }
    #[inline]
    fn load(place: Place<'_, Self>) -> Self {
        core::array::from_fn(|i| T::load(place.at(i)))
    }
    #[inline]
    fn store(place: Place<'_, Self>, value: &Self) {
        for (i, v) in value.iter().enumerate() {
            T::store(place.at(i), v);
        }
    }
}

/// Copies a value out of / into the image; shorthand over [`HliType`].
pub trait PlaceExt<T> {
    /// Loads the whole value, leaf by leaf.
    fn read(self) -> T;
    /// Stores the whole value, leaf by leaf.
    fn write(self, value: &T);
}

impl<T: HliType> PlaceExt<T> for Place<'_, T> {
    #[inline]
    fn read(self) -> T {
        T::load(self)
    }
    #[inline]
    fn write(self, value: &T) {
        T::store(self, value)
    }
}

/// Defines an image struct: `#[repr(C)]`, Pod/Zeroable, a description for the symbol table and
/// C header, field-wise atomic copies, and compile-time asserts of its size and every field
/// offset (the `[N, SymbolWriter]` after each field).
#[macro_export]
macro_rules! hli_struct {
    (
        $(#[doc = $doc:literal])*
        #[st = $st:literal, size = $size:literal]
        pub struct $name:ident {
            $(
                $(#[doc = $fdoc:literal])*
                pub $field:ident : $fty:ty => [$off:literal, $writer:ident]
            ),* $(,)?
        }
    ) => {
        $(#[doc = $doc])*
        #[doc = concat!("\n\nST type `", $st, "`, ", stringify!($size), " bytes.")]
        #[repr(C)]
        #[allow(non_snake_case)]
        #[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        pub struct $name {
            $(
                $(#[doc = $fdoc])*
                #[doc = concat!("\n\nOffset ", stringify!($off), ", written by ", stringify!($writer), ".")]
                pub $field: $fty,
            )*
        }

        const _: () = {
            assert!(core::mem::size_of::<$name>() == $size, concat!("size of ", $st));
            $( assert!(core::mem::offset_of!($name, $field) == $off,
                       concat!("offset of ", $st, ".", stringify!($field))); )*
        };

        impl $crate::desc::HliType for $name {
            fn desc() -> $crate::desc::TypeDesc {
                static FIELDS: &[$crate::desc::FieldDesc] = &[
                    $( $crate::desc::FieldDesc {
                        name: stringify!($field),
                        offset: core::mem::offset_of!($name, $field),
                        ty: <$fty as $crate::desc::HliType>::desc,
                        writer: $crate::desc::SymbolWriter::$writer,
                    }, )*
                ];
                $crate::desc::TypeDesc {
                    size: core::mem::size_of::<$name>(),
                    align: core::mem::align_of::<$name>(),
                    kind: $crate::desc::Kind::Struct { name: $st, fields: FIELDS },
                }
            }
            #[inline]
            fn load(place: $crate::raw::Place<'_, Self>) -> Self {
                Self { $( $field: <$fty as $crate::desc::HliType>::load(
                    place.field(core::mem::offset_of!($name, $field))), )* }
            }
            #[inline]
            fn store(place: $crate::raw::Place<'_, Self>, value: &Self) {
                $( <$fty as $crate::desc::HliType>::store(
                    place.field(core::mem::offset_of!($name, $field)), &value.$field); )*
            }
        }
    };
}
