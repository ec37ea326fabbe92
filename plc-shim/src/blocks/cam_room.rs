//! Room for the tables a PLC program in Structured Text gives through an `MC_CAM_REF`
//! (seed 000 5.1.16.2): made when the block is made, so that taking a table at the edge of
//! Execute copies it and allocates nothing. Two buffers of each shape: a new table is copied
//! into the one no transfer of the last command still sends from.

use super::cam_data::{CamData, CamRef};
use crate::timeline::registry::CamRefIn;
use hli::calls::cam::McMotionFunctionPoint;
use std::sync::Arc;

/// Bytes of one position-table row: master and slave, two LREALs.
const ROW_BYTES: usize = 16;
/// Bytes of one `MC_MotionFunctionPoint` as a program holds it (the wire's layout).
pub const POINT_BYTES: usize = core::mem::size_of::<McMotionFunctionPoint>();
/// `MC_TableType` of a motion function.
const MOTION_FUNCTION: u32 = 22;

/// The buffers of one block.
#[derive(Debug, Default)]
pub struct CamRoom {
    rows: [Arc<[[f64; 2]]>; 2],
    points: [Arc<[McMotionFunctionPoint]>; 2],
}

/// A buffer of `n` elements no one else holds, of the two: `None` if both are held.
fn free<T>(buffers: &mut [Arc<[T]>; 2]) -> Option<&mut Arc<[T]>> {
    buffers.iter_mut().find(|b| Arc::strong_count(b) == 1)
}

/// `items` copied into a free one of `buffers` (as many as it holds): the buffer, shared,
/// and how many; `None` if an item is not `finite`, or if both buffers are held (a block's
/// `cam_ref` is dropped before, and a block has one transfer at a time: never).
fn fill<T: Copy>(
    buffers: &mut [Arc<[T]>; 2],
    items: impl Iterator<Item = T>,
    finite: fn(&T) -> bool,
) -> Option<(Arc<[T]>, usize)> {
    let buffer = free(buffers)?;
    let slots = Arc::get_mut(buffer)?;
    let mut n = 0;
    for (slot, item) in slots.iter_mut().zip(items) {
        if !finite(&item) {
            return None;
        }
        *slot = item;
        n += 1;
    }
    Some((Arc::clone(buffer), n))
}

impl CamRoom {
    /// Room for rows alone (the compatibility blocks' `AdrDataArray`).
    pub fn rows_only(bytes: usize) -> CamRoom {
        let rows = || Arc::from(vec![[0.0; 2]; bytes / ROW_BYTES]);
        CamRoom {
            rows: [rows(), rows()],
            points: Default::default(),
        }
    }

    /// Room for arrays of up to `bytes` bytes, as rows or as points.
    pub fn new(bytes: usize) -> CamRoom {
        let points = || Arc::from(vec![McMotionFunctionPoint::default(); bytes / POINT_BYTES]);
        CamRoom {
            points: [points(), points()],
            ..CamRoom::rows_only(bytes)
        }
    }

    /// `rows` copied into the room: the rows, shared, and how many (see [`fill`]).
    pub fn rows(
        &mut self,
        rows: impl Iterator<Item = [f64; 2]>,
    ) -> Option<(Arc<[[f64; 2]]>, usize)> {
        fill(&mut self.rows, rows, |r| r.iter().all(|v| v.is_finite()))
    }

    /// `table` as an `MC_CAM_REF` whose array is a copy in this room (as much of its bytes
    /// as the room holds; the block's check refuses a description its array does not
    /// match): `None` as [`fill`] says.
    pub fn take(&mut self, table: &CamRefIn<'_>) -> Option<CamRef> {
        let (data, held) = if table.table_type == MOTION_FUNCTION {
            let points = table.bytes.chunks_exact(POINT_BYTES);
            let finite = |p: &McMotionFunctionPoint| {
                [
                    p.master_pos,
                    p.slave_pos,
                    p.slave_velo,
                    p.slave_acc,
                    p.slave_jerk,
                ]
                .iter()
                .all(|v| v.is_finite())
            };
            let points = points.map(bytemuck::pod_read_unaligned);
            let (buffer, n) = fill(&mut self.points, points, finite)?;
            (CamData::Points(buffer), n)
        } else {
            let rows = table.bytes.chunks_exact(ROW_BYTES);
            let (rows, n) = self.rows(rows.map(bytemuck::pod_read_unaligned))?;
            let data = CamData::Rows {
                rows,
                table_type: 0,
                interpolation: 0,
            };
            (data, n)
        };
        Some(CamRef {
            data,
            array_size: table.array_size,
            table_type: table.table_type,
            rows: table.rows,
            columns: table.columns,
            held: Some(held),
        })
    }
}
