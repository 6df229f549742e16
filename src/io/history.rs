//! CSV time histories: named columns fixed at creation, one row per call,
//! each row handed to the operating system before the call returns, so a
//! run that crashes keeps every completed row. Plus a small reader that
//! reads such files back as `f64` columns (tests, plots, reports).
//!
//! Format: a header line of comma-separated column names, then one line per
//! row of values in Rust's shortest round-trip notation (`0.5`, `1.25e-5`,
//! `NaN`, `inf`), so reading a value back gives the same `f64`. No quoting:
//! column names may not contain commas, quotes or line breaks.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use super::{format_real, IoError};

/// Writes one CSV time-history file.
#[derive(Debug)]
pub struct HistoryWriter {
    path: PathBuf,
    file: File,
    columns: Vec<String>,
    /// Reused row buffer.
    line: String,
    /// Bytes in the file: header and every row written.
    bytes: u64,
}

impl HistoryWriter {
    /// Creates (or truncates) `path` and writes the header line.
    ///
    /// Column names must be non-empty, unique, and free of `,`, `"`, `\r`
    /// and `\n`; surrounding spaces are not allowed either (readers trim
    /// them), so a name reads back exactly as given.
    pub fn create(path: &Path, columns: &[&str]) -> Result<Self, IoError> {
        for (i, name) in columns.iter().enumerate() {
            let reason = if name.is_empty() {
                Some("empty name")
            } else if name.contains([',', '"', '\r', '\n']) {
                Some("contains a comma, quote or line break")
            } else if name.trim() != *name {
                Some("leading or trailing whitespace")
            } else if columns[..i].contains(name) {
                Some("duplicate column")
            } else {
                None
            };
            if let Some(reason) = reason {
                return Err(IoError::InvalidName { path: path.to_path_buf(), name: name.to_string(), reason });
            }
        }
        let write_error = |source| IoError::Write { path: path.to_path_buf(), source };
        let mut file = File::create(path).map_err(write_error)?;
        let header = format!("{}\n", columns.join(","));
        file.write_all(header.as_bytes()).map_err(write_error)?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            columns: columns.iter().map(|c| c.to_string()).collect(),
            line: String::new(),
            bytes: header.len() as u64,
        })
    }

    /// Continues an existing file (a resumed run): checks that its header
    /// names `columns`, cuts it to its first `keep` bytes (the rows written
    /// up to the checkpoint; later rows are dropped) and appends from there.
    /// `keep` must end at a line break and leave the header.
    pub fn continue_at(path: &Path, columns: &[&str], keep: u64) -> Result<Self, IoError> {
        let read_error = |source| IoError::Read { path: path.to_path_buf(), source };
        let parse_error = |message: String| IoError::Parse { path: path.to_path_buf(), line: 1, message };
        let mut file = std::fs::OpenOptions::new().read(true).write(true).open(path).map_err(read_error)?;
        let header = format!("{}\n", columns.join(","));
        let mut head = vec![0u8; header.len()];
        std::io::Read::read_exact(&mut file, &mut head).map_err(|_| parse_error("shorter than its header".into()))?;
        if head != header.as_bytes() {
            return Err(parse_error(format!("header differs from the run's columns `{}`", columns.join(","))));
        }
        let len = file.metadata().map_err(read_error)?.len();
        if keep < header.len() as u64 || keep > len {
            return Err(parse_error(format!(
                "has {len} bytes, but {keep} were written up to the checkpoint (the file was cut or replaced)"
            )));
        }
        let mut last = [0u8; 1];
        std::io::Seek::seek(&mut file, std::io::SeekFrom::Start(keep - 1)).map_err(read_error)?;
        std::io::Read::read_exact(&mut file, &mut last).map_err(read_error)?;
        if last[0] != b'\n' {
            return Err(parse_error(format!("byte {keep} is not the end of a row (the file was changed)")));
        }
        let write_error = |source| IoError::Write { path: path.to_path_buf(), source };
        file.set_len(keep).map_err(write_error)?;
        std::io::Seek::seek(&mut file, std::io::SeekFrom::End(0)).map_err(write_error)?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            columns: columns.iter().map(|c| c.to_string()).collect(),
            line: String::new(),
            bytes: keep,
        })
    }

    /// Bytes in the file so far (header and rows).
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Hands the rows written so far to the disk (`fsync`), so that they
    /// survive a power loss, not only a crash of the process.
    pub fn sync(&self) -> Result<(), IoError> {
        self.file.sync_data().map_err(|source| IoError::Write { path: self.path.clone(), source })
    }

    /// Appends one row; `values` are in column order, one per column.
    ///
    /// The line is passed to the operating system in a single write, so a
    /// crash of the process afterwards cannot lose it (there is no
    /// user-space buffer; no `fsync`).
    pub fn write_row(&mut self, values: &[f64]) -> Result<(), IoError> {
        if values.len() != self.columns.len() {
            return Err(IoError::RowLength {
                path: self.path.clone(),
                expected: self.columns.len(),
                found: values.len(),
            });
        }
        self.line.clear();
        for (i, &value) in values.iter().enumerate() {
            if i > 0 {
                self.line.push(',');
            }
            self.line.push_str(&format_real(value));
        }
        self.line.push('\n');
        self.file
            .write_all(self.line.as_bytes())
            .map_err(|source| IoError::Write { path: self.path.clone(), source })?;
        self.bytes += self.line.len() as u64;
        Ok(())
    }

    /// The column names, in order.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// A CSV history read back into memory, column by column.
#[derive(Clone, Debug, PartialEq)]
pub struct HistoryTable {
    columns: Vec<String>,
    /// `values[c][r]`: column `c`, row `r`.
    values: Vec<Vec<f64>>,
}

impl HistoryTable {
    /// Reads a CSV file with a header line and numeric rows.
    ///
    /// Fields are trimmed of spaces; blank lines are skipped; every other
    /// line must have as many fields as the header, each parsing as `f64`
    /// (`NaN`, `inf` included). Errors name the file and the 1-based line.
    pub fn read(path: &Path) -> Result<Self, IoError> {
        let text =
            std::fs::read_to_string(path).map_err(|source| IoError::Read { path: path.to_path_buf(), source })?;
        let parse_error = |line: usize, message: String| IoError::Parse { path: path.to_path_buf(), line, message };
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim())).filter(|(_, l)| !l.is_empty());
        let Some((_, header)) = lines.next() else {
            return Err(parse_error(1, "no header line".into()));
        };
        let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
        let mut values = vec![Vec::new(); columns.len()];
        for (number, line) in lines {
            let fields: Vec<&str> = line.split(',').collect();
            if fields.len() != columns.len() {
                return Err(parse_error(number, format!("{} fields, expected {}", fields.len(), columns.len())));
            }
            for ((field, column), name) in fields.iter().zip(&mut values).zip(&columns) {
                let value = field
                    .trim()
                    .parse::<f64>()
                    .map_err(|_| parse_error(number, format!("column `{name}`: `{field}` is not a number")))?;
                column.push(value);
            }
        }
        Ok(Self { columns, values })
    }

    /// The column names, in file order.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// The values of column `name`, one per row, or `None` if there is no
    /// such column.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        let index = self.columns.iter().position(|c| c == name)?;
        Some(&self.values[index])
    }

    /// Number of data rows.
    pub fn rows(&self) -> usize {
        self.values.first().map_or(0, Vec::len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::{scratch_dir, unwritable_path};

    #[test]
    fn rows_and_columns_round_trip_exactly() {
        let dir = scratch_dir("csv-roundtrip");
        let path = dir.join("history.csv");
        let columns = ["time", "kinetic_energy", "plug_velocity", "cracks"];
        let mut writer = HistoryWriter::create(&path, &columns).unwrap();
        assert_eq!(writer.columns(), columns);
        let rows: Vec<[f64; 4]> = (0..50)
            .map(|i| {
                let t = i as f64 * 2.5e-8;
                [t, 0.5 * 1e3 * (i as f64).sin().powi(2), -312.7 / (i + 1) as f64, i as f64]
            })
            .chain([[1e-300, f64::MAX, -0.0, 0.1 + 0.2], [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 7.0]])
            .collect();
        for row in &rows {
            writer.write_row(row).unwrap();
        }
        drop(writer);

        let table = HistoryTable::read(&path).unwrap();
        assert_eq!(table.columns(), columns);
        assert_eq!(table.rows(), rows.len());
        for (c, name) in columns.iter().enumerate() {
            let column = table.column(name).unwrap();
            for (r, row) in rows.iter().enumerate() {
                let (found, expected) = (column[r], row[c]);
                assert!(
                    found.to_bits() == expected.to_bits() || (found.is_nan() && expected.is_nan()),
                    "row {r} column {name}: {found} != {expected}"
                );
            }
        }
        assert!(table.column("missing").is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn writer_lost_mid_run_leaves_complete_lines() {
        let dir = scratch_dir("csv-crash");
        let path = dir.join("history.csv");
        let mut writer = HistoryWriter::create(&path, &["t", "e"]).unwrap();
        for i in 0..10 {
            writer.write_row(&[i as f64, 2.0 * i as f64]).unwrap();
            // Read while the writer is still alive, as after a crash.
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text.ends_with('\n'));
            assert_eq!(text.lines().count(), i + 2);
        }
        // Simulate a crash: no destructor runs.
        std::mem::forget(writer);
        let table = HistoryTable::read(&path).unwrap();
        assert_eq!(table.rows(), 10);
        assert_eq!(table.column("e").unwrap()[9], 18.0);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_rows_names_and_paths_are_errors() {
        let dir = scratch_dir("csv-errors");
        let path = dir.join("h.csv");
        let mut writer = HistoryWriter::create(&path, &["a", "b"]).unwrap();
        assert!(matches!(writer.write_row(&[1.0]), Err(IoError::RowLength { expected: 2, found: 1, .. })));
        for bad in [["a", "a"], ["a", ""], ["a,b", "c"], [" a", "b"]] {
            assert!(matches!(HistoryWriter::create(&path, &bad), Err(IoError::InvalidName { .. })), "{bad:?}");
        }
        let missing = unwritable_path("h.csv");
        let err = HistoryWriter::create(&missing, &["a"]).unwrap_err();
        assert!(matches!(&err, IoError::Write { path: p, .. } if *p == missing));
        assert!(matches!(HistoryTable::read(&missing), Err(IoError::Read { .. })));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn reader_reports_malformed_lines() {
        let dir = scratch_dir("csv-malformed");
        let path = dir.join("h.csv");
        std::fs::write(&path, "t, x\n0, 1\n\n1, 2, 3\n").unwrap();
        assert!(matches!(HistoryTable::read(&path), Err(IoError::Parse { line: 4, .. })));
        std::fs::write(&path, "t,x\n0,abc\n").unwrap();
        assert!(matches!(HistoryTable::read(&path), Err(IoError::Parse { line: 2, .. })));
        std::fs::write(&path, "").unwrap();
        assert!(matches!(HistoryTable::read(&path), Err(IoError::Parse { .. })));
        std::fs::write(&path, " t , x \r\n 0.5 , -1e-3 \r\n").unwrap();
        let table = HistoryTable::read(&path).unwrap();
        assert_eq!(table.column("x").unwrap(), [-1e-3]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
