//! Position files for FIFO groups, and the double-buffered reader a PLC program fills its
//! FIFO from.
//!
//! Three formats, one row of N positions per FIFO entry:
//! * CSV (`.csv`, any other name): one row per line, values separated by commas, an optional
//!   header line (a first line that is not all numbers), blank lines and `#` comments
//!   skipped;
//! * binary (`.fifo`): the 8 bytes `CNCFIFO1`, columns (u32), reserved (u32), rows (u64),
//!   then the rows' `f64`s, all little-endian. [`write_binary`] writes it;
//! * the seed's table layout (`.tab`), as the seed's FIFO sample program reads its position
//!   file: a header of rows and columns, each an unsigned short, then the rows' doubles
//!   without separators (little-endian). [`write_seed_table`] writes it.
//!
//! A bad value is refused with its place (`FILE:LINE:COL` for CSV, row and column for
//! binary), never passed on. [`Feeder`] reads the file on a thread of its own into two
//! buffers that it hands to the PLC cycle and takes back over wait-free rings, so the cycle
//! never waits for the disk, allocates or locks (the seed's sample program reads its file
//! into two alternating buffers in the same way).

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};

/// The binary format's magic.
pub const BINARY_MAGIC: &[u8; 8] = b"CNCFIFO1";

/// Values per buffer of a [`Feeder`] (64 KiB, the size the seed's sample uses).
pub const FEEDER_BUFFER_VALUES: usize = 8192;

/// Why a position file cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FileError {
    /// The OS refused.
    #[error("{file}: {message}")]
    Io {
        /// The file.
        file: String,
        /// The OS error.
        message: String,
    },
    /// A CSV value that is not a finite number, or a row of the wrong length.
    #[error("{file}:{line}:{column}: {message}")]
    Csv {
        /// The file.
        file: String,
        /// Line, 1-based.
        line: usize,
        /// Column (character), 1-based.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A binary file whose header or values are wrong.
    #[error("{file}: {message}")]
    Binary {
        /// The file.
        file: String,
        /// What is wrong (with the row and column of a bad value).
        message: String,
    },
    /// No rows.
    #[error("{0}: no rows")]
    Empty(String),
}

enum Source {
    Csv {
        lines: std::io::Lines<BufReader<std::fs::File>>,
        line: usize,
        pending: Option<Vec<f64>>,
    },
    Binary {
        reader: BufReader<std::fs::File>,
        rows_left: u64,
        row: u64,
    },
}

/// A position file read row by row.
pub struct RowReader {
    file: String,
    columns: usize,
    source: Source,
}

impl core::fmt::Debug for RowReader {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "RowReader({}, {} columns)", self.file, self.columns)
    }
}

fn csv_row(file: &str, line: usize, text: &str) -> Result<Option<Vec<f64>>, FileError> {
    let text = text.split('#').next().unwrap_or("");
    if text.trim().is_empty() {
        return Ok(None);
    }
    let mut row = Vec::new();
    let mut column = 1;
    for field in text.split(',') {
        let value: f64 = field.trim().parse().map_err(|_| FileError::Csv {
            file: file.to_string(),
            line,
            column: column + field.len() - field.trim_start().len(),
            message: format!("{:?} is not a number", field.trim()),
        })?;
        if !value.is_finite() {
            return Err(FileError::Csv {
                file: file.to_string(),
                line,
                column,
                message: format!("{value} is not a finite position"),
            });
        }
        row.push(value);
        column += field.len() + 1;
    }
    Ok(Some(row))
}

/// The `.fifo` header: magic, columns (u32), reserved (u32), rows (u64).
fn fifo_header(reader: &mut impl Read, file: &str) -> Result<(usize, u64), FileError> {
    let mut header = [0u8; 24];
    reader.read_exact(&mut header).map_err(|e| FileError::Io {
        file: file.to_string(),
        message: e.to_string(),
    })?;
    if &header[..8] != BINARY_MAGIC {
        return Err(FileError::Binary {
            file: file.to_string(),
            message: "not a FIFO position file (no CNCFIFO1 header)".into(),
        });
    }
    let columns = u32::from_le_bytes(header[8..12].try_into().unwrap_or_default());
    let rows = u64::from_le_bytes(header[16..24].try_into().unwrap_or_default());
    Ok((columns as usize, rows))
}

/// The seed's table header (`.tab`, seed 000 4.6.2, as the FIFO sample program reads its
/// position file): rows and columns, each an unsigned short, then the rows' doubles with no
/// separators (little-endian here).
fn table_header(reader: &mut impl Read, file: &str) -> Result<(usize, u64), FileError> {
    let mut header = [0u8; 4];
    reader.read_exact(&mut header).map_err(|e| FileError::Io {
        file: file.to_string(),
        message: e.to_string(),
    })?;
    let rows = u16::from_le_bytes([header[0], header[1]]);
    let columns = u16::from_le_bytes([header[2], header[3]]);
    Ok((usize::from(columns), u64::from(rows)))
}

impl RowReader {
    /// A binary file of `columns` x `rows` after its header, checked.
    fn binary(
        file: String,
        reader: BufReader<std::fs::File>,
        (columns, rows): (usize, u64),
    ) -> Result<RowReader, FileError> {
        if columns == 0 || columns > hli::calls::fifo::FIFO_MAX_DIMENSION as usize {
            return Err(FileError::Binary {
                file,
                message: format!("{columns} columns: 1 to 16"),
            });
        }
        if rows == 0 {
            return Err(FileError::Empty(file));
        }
        Ok(RowReader {
            file,
            columns,
            source: Source::Binary {
                reader,
                rows_left: rows,
                row: 0,
            },
        })
    }

    /// Opens `path`: binary when it ends in `.fifo` or `.tab`, else CSV (its first row sets
    /// the columns).
    pub fn open(path: &Path) -> Result<RowReader, FileError> {
        let file = path.display().to_string();
        let io = |e: std::io::Error| FileError::Io {
            file: file.clone(),
            message: e.to_string(),
        };
        let handle = std::fs::File::open(path).map_err(io)?;
        let mut reader = BufReader::with_capacity(1 << 16, handle);
        let extension = path.extension().and_then(|e| e.to_str());
        match extension {
            Some("fifo") => {
                let shape = fifo_header(&mut reader, &file)?;
                return RowReader::binary(file, reader, shape);
            }
            Some("tab") => {
                let shape = table_header(&mut reader, &file)?;
                return RowReader::binary(file, reader, shape);
            }
            _ => {}
        }
        let mut lines = reader.lines();
        let mut line = 0;
        let mut first = None;
        while first.is_none() {
            let Some(text) = lines.next() else {
                return Err(FileError::Empty(file));
            };
            let text = text.map_err(io)?;
            line += 1;
            match csv_row(&file, line, &text) {
                Ok(row) => first = row,
                // A first line that does not parse is a header.
                Err(_) if line == 1 => {}
                Err(e) => return Err(e),
            }
        }
        let columns = first.as_ref().map_or(0, Vec::len);
        if columns > hli::calls::fifo::FIFO_MAX_DIMENSION as usize {
            return Err(FileError::Csv {
                file,
                line,
                column: 1,
                message: format!("{columns} columns: 1 to 16"),
            });
        }
        Ok(RowReader {
            file,
            columns,
            source: Source::Csv {
                lines,
                line,
                pending: first,
            },
        })
    }

    /// Values per row.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Fills `out` with whole rows; the number of values read (0 at the end of the file).
    pub fn read_rows(&mut self, out: &mut [f64]) -> Result<usize, FileError> {
        let n = self.columns;
        let room = out.len() / n * n;
        let mut filled = 0;
        let file = &self.file;
        let io = |e: std::io::Error| FileError::Io {
            file: file.clone(),
            message: e.to_string(),
        };
        match &mut self.source {
            Source::Csv {
                lines,
                line,
                pending,
            } => {
                while filled < room {
                    let row = match pending.take() {
                        Some(row) => row,
                        None => {
                            let Some(text) = lines.next() else { break };
                            *line += 1;
                            match csv_row(file, *line, &text.map_err(io)?)? {
                                Some(row) => row,
                                None => continue,
                            }
                        }
                    };
                    if row.len() != n {
                        return Err(FileError::Csv {
                            file: file.clone(),
                            line: *line,
                            column: 1,
                            message: format!("{} values, the file's rows have {n}", row.len()),
                        });
                    }
                    out[filled..filled + n].copy_from_slice(&row);
                    filled += n;
                }
            }
            Source::Binary {
                reader,
                rows_left,
                row,
            } => {
                let mut bytes = [0u8; 8];
                while filled < room && *rows_left > 0 {
                    for c in 0..n {
                        reader.read_exact(&mut bytes).map_err(io)?;
                        let v = f64::from_le_bytes(bytes);
                        if !v.is_finite() {
                            return Err(FileError::Binary {
                                file: file.clone(),
                                message: format!("row {row}, column {c}: {v} is not finite"),
                            });
                        }
                        out[filled + c] = v;
                    }
                    filled += n;
                    *rows_left -= 1;
                    *row += 1;
                }
            }
        }
        Ok(filled)
    }

    /// Every row (tools and tests; a PLC uses a [`Feeder`]).
    pub fn read_all(mut self) -> Result<(usize, Vec<f64>), FileError> {
        let mut all = Vec::new();
        let mut chunk = vec![0.0; FEEDER_BUFFER_VALUES.max(self.columns)];
        loop {
            let n = self.read_rows(&mut chunk)?;
            if n == 0 {
                break;
            }
            all.extend_from_slice(&chunk[..n]);
        }
        if all.is_empty() {
            return Err(FileError::Empty(self.file));
        }
        Ok((self.columns, all))
    }
}

/// Writes `values` (rows of `columns`) as a binary position file.
pub fn write_binary(path: &Path, columns: usize, values: &[f64]) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    out.write_all(BINARY_MAGIC)?;
    out.write_all(&(columns as u32).to_le_bytes())?;
    out.write_all(&0u32.to_le_bytes())?;
    out.write_all(&((values.len() / columns) as u64).to_le_bytes())?;
    for v in values {
        out.write_all(&v.to_le_bytes())?;
    }
    out.flush()
}

/// Writes `values` (rows of `columns`) in the seed's table layout (`.tab`): rows and columns
/// as unsigned shorts, then the doubles. `InvalidInput` beyond 65,535 rows or columns.
pub fn write_seed_table(path: &Path, columns: usize, values: &[f64]) -> std::io::Result<()> {
    let rows = values.len() / columns.max(1);
    let (Ok(r), Ok(c)) = (u16::try_from(rows), u16::try_from(columns)) else {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{rows} rows x {columns} columns: the header holds up to 65,535 each"),
        ));
    };
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    out.write_all(&r.to_le_bytes())?;
    out.write_all(&c.to_le_bytes())?;
    for v in values {
        out.write_all(&v.to_le_bytes())?;
    }
    out.flush()
}

/// A buffer of whole rows handed from the reader thread to the cycle.
#[derive(Debug)]
pub struct Buffer {
    /// The values; the first `len` are rows.
    pub values: Vec<f64>,
    /// Values in use.
    pub len: usize,
}

/// What the cycle gets from the feeder.
#[derive(Debug)]
pub enum Fed {
    /// A buffer of rows (give it back with [`Feeder::give_back`]).
    Rows(Buffer),
    /// The file is read to its end.
    End,
    /// Not read yet.
    NotYet,
    /// The file is bad (the reader stopped).
    Failed(FileError),
}

enum Message {
    Rows(Buffer),
    End,
    Failed(FileError),
}

/// How long the reader thread sleeps when both buffers are with the cycle.
const READER_NAP: std::time::Duration = std::time::Duration::from_micros(500);

/// Reads a position file on its own thread into two alternating buffers. The buffers go to
/// the cycle and back through two wait-free rings (`rtrb`): the cycle never waits, locks or
/// allocates; the reader naps while both buffers are with the cycle.
pub struct Feeder {
    path: PathBuf,
    columns: usize,
    full: rtrb::Consumer<Message>,
    empty: rtrb::Producer<Buffer>,
    ended: bool,
    _thread: std::thread::JoinHandle<()>,
}

impl core::fmt::Debug for Feeder {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "Feeder({})", self.path.display())
    }
}

impl Feeder {
    /// Opens `path` (checking its header or first row now) and starts reading it.
    pub fn start(path: &Path) -> Result<Feeder, FileError> {
        let mut reader = RowReader::open(path)?;
        let columns = reader.columns();
        // Two buffers full at most, then the end or a failure.
        let (mut full_tx, full) = rtrb::RingBuffer::<Message>::new(3);
        let (mut empty, mut empty_rx) = rtrb::RingBuffer::<Buffer>::new(2);
        for _ in 0..2 {
            let _ = empty.push(Buffer {
                values: vec![0.0; FEEDER_BUFFER_VALUES],
                len: 0,
            });
        }
        let thread = std::thread::Builder::new()
            .name("fifo-feeder".into())
            .spawn(move || loop {
                // Fill each buffer that comes back until the file ends or fails, or the
                // feeder is dropped.
                let mut buffer = match empty_rx.pop() {
                    Ok(b) => b,
                    Err(_) if empty_rx.is_abandoned() => return,
                    Err(_) => {
                        std::thread::sleep(READER_NAP);
                        continue;
                    }
                };
                let message = match reader.read_rows(&mut buffer.values) {
                    Ok(0) => Message::End,
                    Ok(n) => {
                        buffer.len = n;
                        Message::Rows(buffer)
                    }
                    Err(e) => Message::Failed(e),
                };
                let last = !matches!(message, Message::Rows(_));
                if full_tx.push(message).is_err() || last {
                    return;
                }
            })
            .map_err(|e| FileError::Io {
                file: path.display().to_string(),
                message: e.to_string(),
            })?;
        Ok(Feeder {
            path: path.to_path_buf(),
            columns,
            full,
            empty,
            ended: false,
            _thread: thread,
        })
    }

    /// Values per row of the file.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// The next buffer if the reader has one ready (never waits).
    pub fn try_next(&mut self) -> Fed {
        if self.ended {
            return Fed::End;
        }
        match self.full.pop() {
            Ok(Message::Rows(b)) => Fed::Rows(b),
            Ok(Message::End) => {
                self.ended = true;
                Fed::End
            }
            Ok(Message::Failed(e)) => {
                self.ended = true;
                Fed::Failed(e)
            }
            Err(_) if self.full.is_abandoned() => {
                self.ended = true;
                Fed::End
            }
            Err(_) => Fed::NotYet,
        }
    }

    /// Hands a drained buffer back for the reader to fill.
    pub fn give_back(&mut self, mut buffer: Buffer) {
        buffer.len = 0;
        // Room for both buffers: never refused.
        let _ = self.empty.push(buffer);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("fifo-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn csv_with_header_and_errors_with_their_place() {
        let path = temp("a.csv", "x,y\n0,0\n# comment\n\n1.5, -2\n");
        let (columns, values) = RowReader::open(&path).unwrap().read_all().unwrap();
        assert_eq!((columns, values), (2, vec![0.0, 0.0, 1.5, -2.0]));
        let path = temp("b.csv", "0,0\n1,zwei\n");
        let e = RowReader::open(&path).unwrap().read_all().unwrap_err();
        assert!(
            matches!(
                e,
                FileError::Csv {
                    line: 2,
                    column: 3,
                    ..
                }
            ),
            "{e}"
        );
        let path = temp("c.csv", "0,0\n1,2,3\n");
        let e = RowReader::open(&path).unwrap().read_all().unwrap_err();
        assert!(matches!(e, FileError::Csv { line: 2, .. }), "{e}");
        let path = temp("d.csv", "0,0\n1,NaN\n");
        assert!(RowReader::open(&path).unwrap().read_all().is_err());
    }

    #[test]
    fn binary_round_trip_and_feeder_order() {
        let dir = std::env::temp_dir().join(format!("fifo-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("big.fifo");
        let values: Vec<f64> = (0..30_000).map(|i| i as f64).collect();
        write_binary(&path, 3, &values).unwrap();
        let mut feeder = Feeder::start(&path).unwrap();
        assert_eq!(feeder.columns(), 3);
        let mut got = Vec::new();
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
        loop {
            match feeder.try_next() {
                Fed::Rows(b) => {
                    got.extend_from_slice(&b.values[..b.len]);
                    feeder.give_back(b);
                }
                Fed::End => break,
                Fed::NotYet => {
                    assert!(std::time::Instant::now() < deadline, "watchdog");
                    std::thread::yield_now()
                }
                Fed::Failed(e) => panic!("{e}"),
            }
        }
        assert_eq!(got, values);
    }

    #[test]
    fn the_seeds_table_layout_reads_back_and_bad_headers_are_refused() {
        let dir = std::env::temp_dir().join(format!("fifo-tab-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("contour.tab");
        let values: Vec<f64> = (0..3000).map(|i| f64::from(i) * 0.5).collect();
        write_seed_table(&path, 3, &values).unwrap();
        // 4 header bytes, then 1000 rows of 3 doubles.
        assert_eq!(std::fs::metadata(&path).unwrap().len(), 4 + 3000 * 8);
        let (columns, got) = RowReader::open(&path).unwrap().read_all().unwrap();
        assert_eq!((columns, got), (3, values));
        let bad = dir.join("bad.tab");
        std::fs::write(&bad, [2u8, 0, 17, 0]).unwrap();
        let e = RowReader::open(&bad).unwrap_err().to_string();
        assert!(e.contains("17 columns: 1 to 16"), "{e}");
        std::fs::write(&bad, [0u8, 0, 2, 0]).unwrap();
        assert!(matches!(RowReader::open(&bad), Err(FileError::Empty(_))));
        // Fewer values than the header says: refused with the OS's word, not padded.
        std::fs::write(&bad, [2u8, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0]).unwrap();
        assert!(RowReader::open(&bad).unwrap().read_all().is_err());
        assert!(write_seed_table(&bad, 1, &vec![0.0; 70_000]).is_err());
    }
}
