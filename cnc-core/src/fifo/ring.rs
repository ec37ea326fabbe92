//! The FIFO itself: Z rows of N positions in one buffer made at configuration, used as a
//! ring. A block of rows is checked whole before a single value is stored, so it is queued
//! whole or not at all (seed 002, chapter 5: a block that does not fit is refused as a whole
//! and offered again).

/// Why a block was not queued; the ring is unchanged.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum BlockError {
    /// More rows than are free.
    #[error("{rows} rows do not fit: {free} are free")]
    Full {
        /// Rows of the block.
        rows: usize,
        /// Rows free.
        free: usize,
    },
    /// Values that are not `rows x N`.
    #[error("{values} values are not whole rows of {columns}")]
    Columns {
        /// Values given.
        values: usize,
        /// N.
        columns: usize,
    },
    /// A block without rows.
    #[error("a block without rows")]
    Empty,
    /// NaN or an infinity.
    #[error("row {row}, column {column}: {value} is not a finite position")]
    NonFinite {
        /// Row in the block, 0-based.
        row: usize,
        /// Column, 0-based.
        column: usize,
        /// The value.
        value: f64,
    },
}

/// Z rows of N values.
#[derive(Debug, Clone)]
pub struct RowRing {
    values: Vec<f64>,
    columns: usize,
    capacity: usize,
    head: usize,
    len: usize,
}

impl RowRing {
    /// An empty ring of `capacity` rows of `columns` values (allocates here, never later).
    pub fn new(columns: usize, capacity: usize) -> RowRing {
        RowRing {
            values: vec![0.0; columns * capacity],
            columns,
            capacity,
            head: 0,
            len: 0,
        }
    }

    /// N.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Z.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Rows queued.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no row is queued.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Rows a block may bring.
    pub fn free(&self) -> usize {
        self.capacity - self.len
    }

    /// Row `i` counted from the front (`None` past the end).
    pub fn row(&self, i: usize) -> Option<&[f64]> {
        if i >= self.len {
            return None;
        }
        let at = (self.head + i) % self.capacity * self.columns;
        Some(&self.values[at..at + self.columns])
    }

    /// Drops the front row.
    pub fn pop_front(&mut self) {
        if self.len > 0 {
            self.head = (self.head + 1) % self.capacity;
            self.len -= 1;
        }
    }

    /// Drops every row.
    pub fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    /// Checks a block of `values` (rows of N, row after row) against `free` rows: the number
    /// of rows it brings.
    fn check(&self, values: &[f64], free: usize) -> Result<usize, BlockError> {
        let columns = self.columns;
        if values.is_empty() {
            return Err(BlockError::Empty);
        }
        if !values.len().is_multiple_of(columns) {
            return Err(BlockError::Columns {
                values: values.len(),
                columns,
            });
        }
        let rows = values.len() / columns;
        if rows > free {
            return Err(BlockError::Full { rows, free });
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(BlockError::NonFinite {
                row: i / columns,
                column: i % columns,
                value: values[i],
            });
        }
        Ok(rows)
    }

    /// FiFoWrite: appends the block whole, or refuses it and changes nothing.
    pub fn push_block(&mut self, values: &[f64]) -> Result<usize, BlockError> {
        let rows = self.check(values, self.free())?;
        self.append(values, rows);
        Ok(rows)
    }

    /// FiFoOverwrite: keeps the first `keep` rows (the pair in use), replaces every row behind
    /// them with the block; refused whole (nothing dropped) when the block does not fit.
    pub fn replace_after(&mut self, keep: usize, values: &[f64]) -> Result<usize, BlockError> {
        let keep = keep.min(self.len);
        let rows = self.check(values, self.capacity - keep)?;
        self.len = keep;
        self.append(values, rows);
        Ok(rows)
    }

    fn append(&mut self, values: &[f64], rows: usize) {
        for r in 0..rows {
            let at = (self.head + self.len) % self.capacity * self.columns;
            self.values[at..at + self.columns]
                .copy_from_slice(&values[r * self.columns..(r + 1) * self.columns]);
            self.len += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn whole_block_or_nothing() {
        let mut ring = RowRing::new(2, 3);
        assert_eq!(ring.push_block(&[1.0, 2.0, 3.0, 4.0]), Ok(2));
        assert_eq!(
            ring.push_block(&[5.0, 6.0, 7.0, 8.0]),
            Err(BlockError::Full { rows: 2, free: 1 })
        );
        assert_eq!(ring.len(), 2);
        assert!(matches!(
            ring.push_block(&[5.0, 6.0, 7.0, f64::NAN]),
            Err(BlockError::Full { .. })
        ));
        assert!(matches!(
            ring.push_block(&[5.0, f64::NAN]),
            Err(BlockError::NonFinite {
                row: 0,
                column: 1,
                ..
            })
        ));
        assert_eq!(ring.len(), 2, "a NaN block queues nothing");
        assert_eq!(
            ring.push_block(&[5.0, 6.0, 7.0]),
            Err(BlockError::Columns {
                values: 3,
                columns: 2
            })
        );
        assert_eq!(ring.push_block(&[]), Err(BlockError::Empty));
        assert_eq!(ring.row(1), Some(&[3.0, 4.0][..]));
    }

    #[test]
    fn overwrite_keeps_the_pair_in_use() {
        let mut ring = RowRing::new(1, 4);
        ring.push_block(&[0.0, 1.0, 2.0, 3.0]).unwrap();
        ring.pop_front();
        // Rows 1 and 2 are the pair in use; 3 is replaced by 9, 10.
        assert_eq!(ring.replace_after(2, &[9.0, 10.0]), Ok(2));
        let rows: Vec<f64> = (0..ring.len()).map(|i| ring.row(i).unwrap()[0]).collect();
        assert_eq!(rows, [1.0, 2.0, 9.0, 10.0]);
        // Too large for the room behind the pair: nothing changes.
        assert_eq!(
            ring.replace_after(2, &[7.0, 7.0, 7.0]),
            Err(BlockError::Full { rows: 3, free: 2 })
        );
        assert_eq!(ring.len(), 4);
        assert_eq!(ring.row(3), Some(&[10.0][..]));
    }

    proptest! {
        /// Rows come out in the order they went in, each once, whatever the block sizes and
        /// however reading interleaves with writing; refused blocks leave no trace.
        #[test]
        fn order_is_kept(blocks in proptest::collection::vec((1usize..7, 0usize..5), 1..60)) {
            let mut ring = RowRing::new(2, 8);
            let mut next = 0.0;
            let mut expected = std::collections::VecDeque::new();
            for (rows, pops) in blocks {
                let values: Vec<f64> =
                    (0..rows).flat_map(|r| [next + r as f64, -(next + r as f64)]).collect();
                match ring.push_block(&values) {
                    Ok(n) => {
                        prop_assert_eq!(n, rows);
                        for r in 0..rows {
                            expected.push_back(next + r as f64);
                        }
                        next += rows as f64;
                    }
                    Err(BlockError::Full { free, .. }) => prop_assert!(rows > free),
                    Err(e) => prop_assert!(false, "{e}"),
                }
                for _ in 0..pops {
                    let front = ring.row(0).map(|r| r[0]);
                    prop_assert_eq!(front, expected.front().copied());
                    ring.pop_front();
                    expected.pop_front();
                }
                prop_assert_eq!(ring.len(), expected.len());
                prop_assert_eq!(ring.free(), 8 - expected.len());
            }
        }
    }
}
