//! The names of the tree, stored inline: [`Name`] (words and variables) and [`AxisName`].

/// A word or variable name of at most [`Name::CAPACITY`] bytes, stored inline so tokens
/// need no heap allocation.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct Name {
    len: u8,
    bytes: [u8; Name::CAPACITY],
}

impl Name {
    /// Longest name the lexer keeps whole.
    pub const CAPACITY: usize = 23;

    /// An empty name.
    pub fn new() -> Self {
        Self {
            len: 0,
            bytes: [0; Self::CAPACITY],
        }
    }

    /// Appends an ASCII byte; `false` when full.
    pub fn push(&mut self, b: u8) -> bool {
        if (self.len as usize) < Self::CAPACITY {
            self.bytes[self.len as usize] = b;
            self.len += 1;
            true
        } else {
            false
        }
    }

    /// The bytes (ASCII), without the UTF-8 check of [`Name::as_str`].
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes[..self.len as usize]
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        // Only ASCII bytes are ever pushed.
        core::str::from_utf8(&self.bytes[..self.len as usize]).unwrap_or("")
    }
}

impl core::fmt::Debug for Name {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

impl core::fmt::Display for Name {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl PartialEq<str> for Name {
    fn eq(&self, other: &str) -> bool {
        &self.bytes[..self.len as usize] == other.as_bytes()
    }
}
impl PartialEq<&str> for Name {
    fn eq(&self, other: &&str) -> bool {
        &self.bytes[..self.len as usize] == other.as_bytes()
    }
}

impl Default for Name {
    fn default() -> Self {
        Self::new()
    }
}

impl Name {
    /// The name of `text` (upper-cased ASCII), `None` when it is longer than the capacity or
    /// not ASCII.
    pub fn parse(text: &str) -> Option<Self> {
        let mut name = Self::new();
        for b in text.bytes() {
            if !b.is_ascii() || !name.push(b.to_ascii_uppercase()) {
                return None;
            }
        }
        Some(name)
    }
}

impl From<&str> for Name {
    /// For names known to fit (constants, tests); longer text is cut at the capacity.
    fn from(text: &str) -> Self {
        let mut name = Self::new();
        for b in text.bytes().filter(u8::is_ascii) {
            if !name.push(b.to_ascii_uppercase()) {
                break;
            }
        }
        name
    }
}

impl core::ops::Deref for Name {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

/// An axis name (`X`, `AB`, `X1`): at most [`AxisName::CAPACITY`] ASCII bytes in one machine
/// word, so that axis words, by far the most common items, stay small and compare in one step.
#[derive(Clone, Copy, PartialEq, Eq, Default)]
pub struct AxisName {
    /// Upper-case ASCII bytes, zero padded (a name never contains a zero byte).
    bytes: [u8; AxisName::CAPACITY],
}

impl AxisName {
    /// Longest axis name.
    pub const CAPACITY: usize = 8;

    /// The name of `text` (upper-cased), `None` when it is longer than
    /// [`AxisName::CAPACITY`] or not ASCII.
    pub fn parse(text: &str) -> Option<Self> {
        let fits = text.len() <= Self::CAPACITY && text.bytes().all(|b| b.is_ascii() && b != 0);
        fits.then(|| Self::from(text))
    }

    /// The name packed by the fast lane: its bytes in `packed`, first byte lowest, the unused
    /// high bytes zero.
    pub(crate) fn from_packed(packed: u64) -> Self {
        Self {
            bytes: packed.to_le_bytes(),
        }
    }

    /// The bytes as one word, first byte lowest (for comparisons and matching).
    pub fn packed(self) -> u64 {
        u64::from_le_bytes(self.bytes)
    }

    /// The bytes (ASCII).
    pub fn as_bytes(&self) -> &[u8] {
        let len = self
            .bytes
            .iter()
            .position(|&b| b == 0)
            .unwrap_or(Self::CAPACITY);
        &self.bytes[..len]
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        // Only ASCII bytes are ever stored.
        core::str::from_utf8(self.as_bytes()).unwrap_or("")
    }
}

impl core::fmt::Debug for AxisName {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

impl core::fmt::Display for AxisName {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl PartialEq<str> for AxisName {
    fn eq(&self, other: &str) -> bool {
        self.as_bytes() == other.as_bytes()
    }
}

impl From<&str> for AxisName {
    /// For names known to fit (constants, tests); longer text is cut at the capacity.
    fn from(text: &str) -> Self {
        let mut bytes = [0; Self::CAPACITY];
        let ascii = text.bytes().filter(|&b| b.is_ascii() && b != 0);
        for (slot, b) in bytes.iter_mut().zip(ascii) {
            *slot = b.to_ascii_uppercase();
        }
        Self { bytes }
    }
}
