//! Output: VTU/PVD for ParaView, CSV time histories, PNG plots.
//!
//! - [`vtu`]: VTK XML `UnstructuredGrid` files (particles as vertex cells,
//!   crack paths as poly-lines) with raw appended binary data.
//! - [`pvd`]: the `.pvd` collection that strings the frames into a time
//!   series, rewritten after every frame.
//! - [`history`]: CSV time histories, one flushed row per call, and a small
//!   reader for tests and plots.
//! - [`plot`]: PNG line plots and 2D scatter field plots.
//!
//! Files that are written whole (VTU, PVD, PNG) go through a temporary file
//! in the same directory and a rename, so a run that dies mid-write leaves
//! either the old file or the new one, never half of one.

pub mod history;
pub mod plot;
pub mod pvd;
pub mod vtu;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

pub use history::{HistoryTable, HistoryWriter};
pub use plot::{save_field_plot, save_line_plot, short_number, FieldPlot, LinePlot, PlotError, Series};
pub use pvd::{PvdEntry, PvdSeries};
pub use vtu::{write_vtu, ArrayData, Cells, DataArray, VtuPiece};

/// Errors of the file writers and readers in this module; each names the
/// file it concerns.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// Creating, writing or renaming the file failed (missing or read-only
    /// directory, full disk, ...).
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file that was being written.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// Opening or reading the file failed.
    #[error("cannot read {}: {source}", path.display())]
    Read {
        /// The file that was being read.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A data array's length is not its component count times the number
    /// of points (point data) or cells (cell data).
    #[error(
        "{}: array `{array}` has {found} values, expected {expected}",
        path.display()
    )]
    ArrayLength {
        /// The file that was being written.
        path: PathBuf,
        /// Name of the offending array.
        array: String,
        /// Number of values required.
        expected: usize,
        /// Number of values given.
        found: usize,
    },
    /// A data array declares zero components.
    #[error("{}: array `{array}` declares 0 components", path.display())]
    ZeroComponents {
        /// The file that was being written.
        path: PathBuf,
        /// Name of the offending array.
        array: String,
    },
    /// A cell refers to a point that does not exist.
    #[error(
        "{}: cell {cell} refers to point {index}, but there are {points} points",
        path.display()
    )]
    CellIndex {
        /// The file that was being written.
        path: PathBuf,
        /// Index of the offending cell.
        cell: usize,
        /// The out-of-range point index.
        index: u32,
        /// Number of points in the piece.
        points: usize,
    },
    /// A poly-line cell has no points.
    #[error("{}: cell {cell} has no points", path.display())]
    EmptyCell {
        /// The file that was being written.
        path: PathBuf,
        /// Index of the offending cell.
        cell: usize,
    },
    /// An array or column name is empty, duplicated or contains characters
    /// the format cannot hold.
    #[error("{}: invalid name `{name}`: {reason}", path.display())]
    InvalidName {
        /// The file that was being written.
        path: PathBuf,
        /// The offending name.
        name: String,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// A history row has a different number of values than the file has
    /// columns.
    #[error(
        "{}: row has {found} values, but the file has {expected} columns",
        path.display()
    )]
    RowLength {
        /// The history file.
        path: PathBuf,
        /// Number of columns.
        expected: usize,
        /// Number of values given.
        found: usize,
    },
    /// A time-series entry has a time that is NaN or infinite.
    #[error("{}: time {time} is not finite", path.display())]
    NonFiniteTime {
        /// The collection file.
        path: PathBuf,
        /// The offending time.
        time: f64,
    },
    /// A file being read is malformed.
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        /// The file being read.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// Value of the `byte_order` attribute matching the native byte order, in
/// which all binary data are written (`bytemuck` casts, no byte swapping).
pub(crate) const BYTE_ORDER: &str = if cfg!(target_endian = "big") { "BigEndian" } else { "LittleEndian" };

/// Writes `path` as a whole: `write` fills a temporary file next to it,
/// which is then renamed over `path`.
///
/// A process that dies inside this function leaves at most a stray
/// `.NAME.tmp*` file, never a truncated `path`. The file is not `fsync`ed:
/// that would cost a disk flush per frame and only matters on power loss.
pub(crate) fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<(), IoError> {
    let fail = |source| IoError::Write { path: path.to_path_buf(), source };
    let tmp = temporary_sibling(path, "").map_err(fail)?;
    let result = File::create(&tmp).and_then(|file| {
        let mut writer = BufWriter::new(file);
        write(&mut writer)?;
        writer.flush()?;
        drop(writer);
        std::fs::rename(&tmp, path)
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(fail)
}

/// A path in the same directory as `path` (so a rename is atomic), hidden,
/// unique within this process, and ending in `suffix`.
pub(crate) fn temporary_sibling(path: &Path, suffix: &str) -> std::io::Result<PathBuf> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "path has no file name"))?;
    let unique = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp{}-{unique}{suffix}", std::process::id()));
    Ok(path.with_file_name(tmp_name))
}

/// Whether `name` is one of [`temporary_sibling`]'s names: `.NAME.tmpP-N`
/// (optionally with a suffix), P a process id and N a counter.
fn is_temporary_name(name: &str) -> bool {
    let Some(rest) = name.strip_prefix('.') else { return false };
    rest.rmatch_indices(".tmp").any(|(at, _)| {
        let tail = &rest[at + 4..];
        let (pid, after) = tail.split_at(tail.find(|c: char| !c.is_ascii_digit()).unwrap_or(tail.len()));
        let counter = after.strip_prefix('-').unwrap_or("");
        let digits = counter.len() - counter.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        at > 0 && !pid.is_empty() && digits > 0
    })
}

/// Removes from `dir` every temporary file a process killed inside
/// [`write_atomically`] (or another writer using [`temporary_sibling`]) left
/// behind. A resumed run calls it, so that its directory ends as an
/// uninterrupted run's would. Best effort: a file that cannot be removed
/// is left.
pub(crate) fn remove_temporaries(dir: &Path) {
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            if is_temporary_name(&e.file_name().to_string_lossy()) && e.path().is_file() {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// Shortest text that parses back to exactly `value`: plain decimals for
/// moderate magnitudes, exponent notation otherwise (`1.5e-5`), `NaN`,
/// `inf`, `-inf` for non-finite values.
pub(crate) fn format_real(value: f64) -> String {
    let magnitude = value.abs();
    if value == 0.0 || (1e-4..1e15).contains(&magnitude) || !value.is_finite() {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

/// Escapes the five XML special characters for use in an attribute value.
pub(crate) fn xml_escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod test_util {
    use std::path::PathBuf;

    /// A fresh, empty scratch directory for one test.
    pub fn scratch_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("plugsim-io-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch dir");
        dir
    }

    /// A path whose parent directory does not exist, so writing fails.
    pub fn unwritable_path(file: &str) -> PathBuf {
        std::env::temp_dir().join(format!("plugsim-io-missing-{}", std::process::id())).join("no-such-dir").join(file)
    }

    /// Checks that `xml` is well formed at the level the writers use:
    /// balanced start/end tags, every tag closed, one root element.
    /// Returns the element names in document order.
    pub fn check_xml_well_formed(xml: &str) -> Vec<String> {
        let mut stack: Vec<String> = Vec::new();
        let mut names = Vec::new();
        let mut roots = 0;
        let mut rest = xml;
        while let Some(start) = rest.find('<') {
            let end = rest[start..].find('>').expect("unterminated tag") + start;
            let tag = &rest[start + 1..end];
            rest = &rest[end + 1..];
            if tag.starts_with('?') {
                assert!(tag.ends_with('?'), "bad declaration <{tag}>");
                assert!(stack.is_empty() && names.is_empty(), "declaration not first");
                continue;
            }
            if let Some(name) = tag.strip_prefix('/') {
                let open = stack.pop().unwrap_or_else(|| panic!("stray </{name}>"));
                assert_eq!(open, name.trim(), "mismatched end tag");
                continue;
            }
            let self_closing = tag.ends_with('/');
            let name: String = tag.trim_end_matches('/').split_whitespace().next().expect("empty tag").to_string();
            assert_eq!(tag.matches('"').count() % 2, 0, "unbalanced quotes in <{tag}>");
            if stack.is_empty() {
                roots += 1;
            }
            names.push(name.clone());
            if !self_closing {
                stack.push(name);
            }
        }
        assert!(stack.is_empty(), "unclosed tags {stack:?}");
        assert_eq!(roots, 1, "expected exactly one root element");
        names
    }

    /// Value of attribute `name` in the first tag (text between `<` and
    /// `>`) of `tag`.
    pub fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
        let key = format!(" {name}=\"");
        let start = tag.find(&key)? + key.len();
        let len = tag[start..].find('"')?;
        Some(&tag[start..start + len])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_real_round_trips() {
        for v in [
            0.0,
            -0.0,
            1.0,
            -2.5,
            1e-4,
            9.99e-5,
            1.25e-5,
            1e15,
            123456.789,
            1e-300,
            1e300,
            f64::MIN_POSITIVE,
            f64::MAX,
            0.1 + 0.2,
        ] {
            let text = format_real(v);
            assert_eq!(text.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{text}");
        }
        assert_eq!(format_real(1.25e-5), "1.25e-5");
        assert_eq!(format_real(0.5), "0.5");
        assert!(format_real(f64::NAN).parse::<f64>().unwrap().is_nan());
        assert_eq!(format_real(f64::NEG_INFINITY).parse::<f64>().unwrap(), f64::NEG_INFINITY);
    }

    #[test]
    fn atomic_write_to_missing_directory_names_the_path() {
        let path = test_util::unwritable_path("x.vtu");
        let err = write_atomically(&path, |w| w.write_all(b"x")).unwrap_err();
        assert!(matches!(&err, IoError::Write { path: p, .. } if *p == path));
        assert!(err.to_string().contains("no-such-dir"), "{err}");
    }

    #[test]
    fn atomic_write_failure_keeps_old_file_and_no_temporary() {
        let dir = test_util::scratch_dir("atomic");
        let path = dir.join("frame.vtu");
        std::fs::write(&path, b"old").unwrap();
        let err = write_atomically(&path, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("simulated failure"))
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        let entries: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(entries.len(), 1, "temporary file left behind");
        write_atomically(&path, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_killed_writers_temporaries_are_removed_and_nothing_else() {
        let dir = std::env::temp_dir().join(format!("plugsim-io-temporaries-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let strays = [
            temporary_sibling(&dir.join("results.pvd"), "").unwrap(),
            temporary_sibling(&dir.join("energy.png"), ".png").unwrap(),
            dir.join(".checkpoint-000000000001.ckpt.tmp1-0"),
        ];
        let kept = ["results.pvd", "history.csv", ".tmp1-0", ".x.tmp", ".x.tmpA-1", "y.tmp1-0", ".plot.tmp12-"];
        for path in strays.iter().cloned().chain(kept.iter().map(|n| dir.join(n))) {
            std::fs::write(path, b"x").unwrap();
        }
        remove_temporaries(&dir);
        for stray in &strays {
            assert!(!stray.exists(), "{} left", stray.display());
        }
        for name in kept {
            assert!(dir.join(name).exists(), "{name} removed");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
