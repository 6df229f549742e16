//! ParaView collection (`.pvd`) writer: strings VTU frames into a time
//! series, with several parts per time step (particles as part 0, cracks as
//! part 1, ...).
//!
//! The whole file is rewritten (atomically) after every append, so a run
//! that dies at any point still leaves a valid series of the frames written
//! so far.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::{format_real, write_atomically, xml_escape, IoError, BYTE_ORDER};

/// One data set of the collection.
#[derive(Clone, Debug, PartialEq)]
pub struct PvdEntry {
    /// Simulation time (s).
    pub time: f64,
    /// File name as written into the collection: relative to the `.pvd`
    /// file's directory (or absolute).
    pub file: String,
    /// Part number: data sets with the same time and different parts are
    /// shown together as blocks of one multiblock data set.
    pub part: u32,
}

/// A `.pvd` time series being built during a run.
#[derive(Debug)]
pub struct PvdSeries {
    path: PathBuf,
    entries: Vec<PvdEntry>,
}

impl PvdSeries {
    /// Starts a new, empty series at `path` and writes it immediately
    /// (replacing any existing file), so a bad path fails before the run.
    pub fn create(path: &Path) -> Result<Self, IoError> {
        let series = Self { path: path.to_path_buf(), entries: Vec::new() };
        series.write()?;
        Ok(series)
    }

    /// A series that continues with `entries` already in it (a resumed
    /// run), written immediately (replacing any existing file).
    pub fn with_entries(path: &Path, entries: Vec<PvdEntry>) -> Result<Self, IoError> {
        let series = Self { path: path.to_path_buf(), entries };
        series.write()?;
        Ok(series)
    }

    /// Adds the data set `file` (relative to the `.pvd` file's directory)
    /// as part `part` at time `time` (s), then rewrites the collection.
    ///
    /// Entries are kept sorted by time, then part; an entry equal in both to
    /// an existing one goes after it. Backslashes in `file` are written as
    /// `/`. If the rewrite fails the entry stays recorded and appears in the
    /// file at the next successful append.
    pub fn append(&mut self, time: f64, file: &str, part: u32) -> Result<(), IoError> {
        if !time.is_finite() {
            return Err(IoError::NonFiniteTime { path: self.path.clone(), time });
        }
        let at = self.entries.partition_point(|e| (e.time, e.part) <= (time, part));
        self.entries.insert(at, PvdEntry { time, file: file.replace('\\', "/"), part });
        self.write()
    }

    /// The entries written so far, in file order.
    pub fn entries(&self) -> &[PvdEntry] {
        &self.entries
    }

    /// Where the collection is written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn write(&self) -> Result<(), IoError> {
        let mut xml = format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" \
             byte_order=\"{BYTE_ORDER}\">\n  <Collection>\n"
        );
        for entry in &self.entries {
            xml.push_str(&format!(
                "    <DataSet timestep=\"{}\" group=\"\" part=\"{}\" file=\"{}\"/>\n",
                format_real(entry.time),
                entry.part,
                xml_escape(&entry.file)
            ));
        }
        xml.push_str("  </Collection>\n</VTKFile>\n");
        write_atomically(&self.path, |w| w.write_all(xml.as_bytes()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::{attribute, check_xml_well_formed, scratch_dir, unwritable_path};

    /// `(timestep, part, file)` of every `<DataSet>`, parsed independently.
    fn read_pvd(path: &Path) -> Vec<(f64, u32, String)> {
        let xml = std::fs::read_to_string(path).unwrap();
        let names = check_xml_well_formed(&xml);
        assert_eq!(names[..2], ["VTKFile", "Collection"]);
        assert!(names[2..].iter().all(|n| n == "DataSet"));
        assert!(xml.starts_with("<?xml version=\"1.0\"?>\n"));
        let root = &xml[xml.find("<VTKFile").unwrap()..];
        assert_eq!(attribute(root, "type"), Some("Collection"));
        assert_eq!(attribute(root, "version"), Some("1.0"));
        xml.split("<DataSet")
            .skip(1)
            .map(|tag| {
                let tag = format!(" {}", &tag[..tag.find("/>").unwrap()]);
                (
                    attribute(&tag, "timestep").unwrap().parse().unwrap(),
                    attribute(&tag, "part").unwrap().parse().unwrap(),
                    attribute(&tag, "file").unwrap().to_string(),
                )
            })
            .collect()
    }

    #[test]
    fn series_is_valid_after_every_append_and_time_ordered() {
        let dir = scratch_dir("pvd");
        let path = dir.join("run.pvd");
        let mut series = PvdSeries::create(&path).unwrap();
        assert!(read_pvd(&path).is_empty());

        let dt = 1.25e-7;
        let mut expected = Vec::new();
        for step in 0..4 {
            let time = step as f64 * dt;
            let particles = format!("frames/particles_{step:06}.vtu");
            series.append(time, &particles, 0).unwrap();
            expected.push((time, 0, particles));
            assert_eq!(read_pvd(&path), expected);
            let cracks = format!("frames/cracks_{step:06}.vtu");
            series.append(time, &cracks, 1).unwrap();
            expected.push((time, 1, cracks));
            assert_eq!(read_pvd(&path), expected);
        }
        assert_eq!(series.entries().len(), 8);

        // A late entry for an earlier time lands in time order.
        series.append(0.5 * dt, "frames/extra.vtu", 0).unwrap();
        expected.insert(2, (0.5 * dt, 0, "frames/extra.vtu".to_string()));
        assert_eq!(read_pvd(&path), expected);
        // Times survive the text round trip exactly.
        for ((t, _, _), entry) in read_pvd(&path).iter().zip(series.entries()) {
            assert_eq!(t.to_bits(), entry.time.to_bits());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn file_names_are_escaped_and_use_forward_slashes() {
        let dir = scratch_dir("pvd-escape");
        let path = dir.join("run.pvd");
        let mut series = PvdSeries::create(&path).unwrap();
        series.append(0.0, "a&b\\\"c\".vtu", 0).unwrap();
        let xml = std::fs::read_to_string(&path).unwrap();
        check_xml_well_formed(&xml);
        assert!(xml.contains("file=\"a&amp;b/&quot;c&quot;.vtu\""), "{xml}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_time_and_bad_path_are_errors() {
        let path = unwritable_path("run.pvd");
        let err = PvdSeries::create(&path).unwrap_err();
        assert!(matches!(&err, IoError::Write { path: p, .. } if *p == path));

        let dir = scratch_dir("pvd-nan");
        let mut series = PvdSeries::create(&dir.join("run.pvd")).unwrap();
        assert!(matches!(series.append(f64::NAN, "x.vtu", 0), Err(IoError::NonFiniteTime { .. })));
        assert!(series.entries().is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
