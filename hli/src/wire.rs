//! The frames of the acyclic service: what travels between the processes, fixed
//! `#[repr(C)]` plain data of 256 bytes each, and the encoding of a typed body into a frame.
//! No transport, no call kinds, no handlers.

use bytemuck::{Pod, Zeroable};

/// Bytes available for a request or reply body.
pub const ACYCLIC_BODY_SIZE: usize = 240;

/// The request frame.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct AcyclicRequest {
    /// Caller's running id, echoed in the response.
    pub invoke_id: u32,
    /// Raw [`crate::calls::CallKind`].
    pub kind: u32,
    /// Addressed object (axis, channel, table id), kind-specific.
    pub target: u32,
    /// Valid bytes in `body`.
    pub body_len: u32,
    /// Kind-specific request body.
    pub body: [u8; ACYCLIC_BODY_SIZE],
}

/// The response frame.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct AcyclicResponse {
    /// Echo of the request's id.
    pub invoke_id: u32,
    /// Echo of the request's kind.
    pub kind: u32,
    /// 0 on success, else an [`crate::calls::ErrorCode`].
    pub error_code: u32,
    /// Valid bytes in `body`.
    pub body_len: u32,
    /// Kind-specific reply body.
    pub body: [u8; ACYCLIC_BODY_SIZE],
}

const _: () = assert!(core::mem::size_of::<AcyclicRequest>() == 256);
const _: () = assert!(core::mem::size_of::<AcyclicResponse>() == 256);

impl Default for AcyclicRequest {
    fn default() -> Self {
        Zeroable::zeroed()
    }
}
impl Default for AcyclicResponse {
    fn default() -> Self {
        Zeroable::zeroed()
    }
}

/// Values one bulk call may carry: 64 KiB of `f64` (the buffer size of the FIFO seed's sample
/// program).
pub const BULK_MAX_VALUES: usize = 8192;

/// The header of a bulk call: a call whose payload is `rows x columns` numbers written
/// straight into the shared memory the CNC reads (not copied into a frame), such as a FIFO row
/// block. The kind routes it like any call; the reply is an [`AcyclicResponse`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct BulkHeader {
    /// The call kind ([`crate::calls::CallKind`] raw).
    pub kind: u32,
    /// What it addresses (a FIFO group's index, ...).
    pub target: u32,
    /// Values per row.
    pub columns: u32,
    /// Rows.
    pub rows: u32,
}

const _: () = assert!(core::mem::size_of::<BulkHeader>() == 16);

/// A body encoded for a frame: the bytes and their count.
pub fn encode_body<T: Pod>(value: &T) -> ([u8; ACYCLIC_BODY_SIZE], u32) {
    let bytes = bytemuck::bytes_of(value);
    let mut body = [0u8; ACYCLIC_BODY_SIZE];
    body[..bytes.len()].copy_from_slice(bytes);
    (body, bytes.len() as u32)
}
