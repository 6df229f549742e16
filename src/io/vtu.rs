//! VTK XML `UnstructuredGrid` (`.vtu`) writer for particle clouds and crack
//! poly-lines.
//!
//! One file holds one [`VtuPiece`]. The XML header declares `version="1.0"`,
//! `header_type="UInt64"` and the native byte order (`LittleEndian` on every
//! platform plugsim targets); all arrays are stored as raw binary in a single
//! `<AppendedData encoding="raw">` block, each preceded by its byte count as
//! a `u64`, with each `DataArray`'s `offset` counted from the byte after the
//! `_` marker. This is the layout ParaView and VTK >= 9 read natively.

use std::collections::HashSet;
use std::io::Write;
use std::path::Path;

use super::{write_atomically, xml_escape, IoError, BYTE_ORDER};

/// VTK cell type id of a single-point cell (`VTK_VERTEX`).
pub const VTK_VERTEX: u8 = 1;
/// VTK cell type id of an open poly-line (`VTK_POLY_LINE`).
pub const VTK_POLY_LINE: u8 = 4;

/// The cells of a piece.
#[derive(Clone, Debug, PartialEq)]
pub enum Cells {
    /// One `VTK_VERTEX` cell per point, in point order: a particle cloud.
    /// Cell data then has one tuple per point.
    Vertices,
    /// `VTK_POLY_LINE` cells, each the list of its point indices in order
    /// (e.g. one crack path per cell). Every cell needs at least one point.
    PolyLines(Vec<Vec<u32>>),
}

impl Cells {
    /// Number of cells, given the number of points in the piece.
    pub fn count(&self, points: usize) -> usize {
        match self {
            Cells::Vertices => points,
            Cells::PolyLines(lines) => lines.len(),
        }
    }
}

/// Values of a data array, stored tuple after tuple
/// (`[x0, y0, z0, x1, y1, z1, ...]` for a 3-component array).
#[derive(Clone, Debug, PartialEq)]
pub enum ArrayData {
    /// Written as VTK `Float64`.
    F64(Vec<f64>),
    /// Written as VTK `Int32` (flags, ids, material numbers).
    I32(Vec<i32>),
}

impl ArrayData {
    /// Number of values (tuples times components).
    pub fn len(&self) -> usize {
        match self {
            ArrayData::F64(v) => v.len(),
            ArrayData::I32(v) => v.len(),
        }
    }

    /// Whether there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn vtk_type(&self) -> &'static str {
        match self {
            ArrayData::F64(_) => "Float64",
            ArrayData::I32(_) => "Int32",
        }
    }

    fn bytes(&self) -> &[u8] {
        match self {
            ArrayData::F64(v) => bytemuck::cast_slice(v),
            ArrayData::I32(v) => bytemuck::cast_slice(v),
        }
    }
}

/// A named point- or cell-data array.
///
/// ParaView interprets the component count: 1 scalar, 3 vector,
/// 6 symmetric tensor in VTK order `XX, YY, ZZ, XY, YZ, XZ`,
/// 9 full tensor in row-major order `XX, XY, XZ, YX, ..., ZZ`.
/// Other counts are written as plain multi-component arrays.
#[derive(Clone, Debug, PartialEq)]
pub struct DataArray {
    /// Array name shown in ParaView; non-empty, unique within its section.
    pub name: String,
    /// Number of components per tuple (at least 1).
    pub components: usize,
    /// The values, `components` per point or cell.
    pub data: ArrayData,
}

impl DataArray {
    /// A scalar `Float64` array.
    pub fn scalars(name: impl Into<String>, values: Vec<f64>) -> Self {
        Self { name: name.into(), components: 1, data: ArrayData::F64(values) }
    }

    /// A 3-component `Float64` vector array (velocity, displacement, ...).
    pub fn vectors(name: impl Into<String>, values: &[[f64; 3]]) -> Self {
        Self { name: name.into(), components: 3, data: ArrayData::F64(values.as_flattened().to_vec()) }
    }

    /// A symmetric tensor array, components in VTK order
    /// `XX, YY, ZZ, XY, YZ, XZ`.
    pub fn symmetric_tensors(name: impl Into<String>, values: &[[f64; 6]]) -> Self {
        Self { name: name.into(), components: 6, data: ArrayData::F64(values.as_flattened().to_vec()) }
    }

    /// A full tensor array, each tensor row-major
    /// (`XX, XY, XZ, YX, YY, YZ, ZX, ZY, ZZ`).
    pub fn tensors(name: impl Into<String>, values: &[[f64; 9]]) -> Self {
        Self { name: name.into(), components: 9, data: ArrayData::F64(values.as_flattened().to_vec()) }
    }

    /// A scalar `Int32` array.
    pub fn integers(name: impl Into<String>, values: Vec<i32>) -> Self {
        Self { name: name.into(), components: 1, data: ArrayData::I32(values) }
    }
}

/// One unstructured-grid piece: points, cells and their data.
#[derive(Clone, Debug, PartialEq)]
pub struct VtuPiece {
    /// Point coordinates (2D data: set z = 0).
    pub points: Vec<[f64; 3]>,
    /// The cells over the points.
    pub cells: Cells,
    /// Arrays with one tuple per point.
    pub point_data: Vec<DataArray>,
    /// Arrays with one tuple per cell.
    pub cell_data: Vec<DataArray>,
}

impl VtuPiece {
    /// A particle cloud: one vertex cell per point, no data yet.
    pub fn point_cloud(points: Vec<[f64; 3]>) -> Self {
        Self { points, cells: Cells::Vertices, point_data: Vec::new(), cell_data: Vec::new() }
    }

    /// Poly-lines over `points` (each line a list of point indices), no data
    /// yet.
    pub fn poly_lines(points: Vec<[f64; 3]>, lines: Vec<Vec<u32>>) -> Self {
        Self { points, cells: Cells::PolyLines(lines), point_data: Vec::new(), cell_data: Vec::new() }
    }

    /// Adds a point-data array (builder style).
    pub fn with_point_data(mut self, array: DataArray) -> Self {
        self.point_data.push(array);
        self
    }

    /// Adds a cell-data array (builder style).
    pub fn with_cell_data(mut self, array: DataArray) -> Self {
        self.cell_data.push(array);
        self
    }
}

/// Writes `piece` to `path` as a VTK XML unstructured grid with raw
/// appended binary data (see the module docs for the layout).
///
/// The piece is checked first: array lengths against the point and cell
/// counts, non-zero component counts, non-empty unique names per section,
/// poly-line indices in range. The file is written through a temporary file
/// and a rename, so `path` is never left half written.
pub fn write_vtu(path: &Path, piece: &VtuPiece) -> Result<(), IoError> {
    validate(path, piece)?;
    let n_points = piece.points.len();
    let n_cells = piece.cells.count(n_points);

    let (connectivity, offsets, types): (Vec<i64>, Vec<i64>, Vec<u8>) = match &piece.cells {
        Cells::Vertices => {
            ((0..n_points as i64).collect(), (1..=n_points as i64).collect(), vec![VTK_VERTEX; n_points])
        }
        Cells::PolyLines(lines) => {
            let connectivity = lines.iter().flatten().map(|&i| i64::from(i)).collect();
            let offsets = lines
                .iter()
                .scan(0i64, |end, line| {
                    *end += line.len() as i64;
                    Some(*end)
                })
                .collect();
            (connectivity, offsets, vec![VTK_POLY_LINE; lines.len()])
        }
    };

    // Every appended array, in the order of the blocks in the file; the
    // XML below lists them section by section in this same order.
    #[derive(PartialEq, Clone, Copy)]
    enum Section {
        PointData,
        CellData,
        Points,
        Cells,
    }
    struct Block<'a> {
        section: Section,
        vtk_type: &'static str,
        name: &'a str,
        components: usize,
        bytes: &'a [u8],
        /// Start of the block's byte-count header, counted from the byte
        /// after the `_` marker.
        offset: usize,
    }
    let block =
        |section, vtk_type, name, components, bytes| Block { section, vtk_type, name, components, bytes, offset: 0 };
    let mut blocks: Vec<Block> = Vec::new();
    for (section, arrays) in [(Section::PointData, &piece.point_data), (Section::CellData, &piece.cell_data)] {
        blocks.extend(arrays.iter().map(|a| block(section, a.data.vtk_type(), &a.name, a.components, a.data.bytes())));
    }
    let point_bytes = bytemuck::cast_slice(&piece.points);
    blocks.push(block(Section::Points, "Float64", "Points", 3, point_bytes));
    blocks.push(block(Section::Cells, "Int64", "connectivity", 1, bytemuck::cast_slice(&connectivity)));
    blocks.push(block(Section::Cells, "Int64", "offsets", 1, bytemuck::cast_slice(&offsets)));
    blocks.push(block(Section::Cells, "UInt8", "types", 1, &types));
    let mut offset = 0;
    for block in &mut blocks {
        block.offset = offset;
        offset += HEADER_BYTES + block.bytes.len();
    }

    let mut xml = String::new();
    xml.push_str("<?xml version=\"1.0\"?>\n");
    xml.push_str(&format!(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"{BYTE_ORDER}\" \
         header_type=\"UInt64\">\n  <UnstructuredGrid>\n    \
         <Piece NumberOfPoints=\"{n_points}\" NumberOfCells=\"{n_cells}\">\n"
    ));
    for (section, tag) in [
        (Section::PointData, "PointData"),
        (Section::CellData, "CellData"),
        (Section::Points, "Points"),
        (Section::Cells, "Cells"),
    ] {
        xml.push_str(&format!("      <{tag}>\n"));
        for block in blocks.iter().filter(|b| b.section == section) {
            xml.push_str(&format!(
                "        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" \
                 format=\"appended\" offset=\"{}\"/>\n",
                block.vtk_type,
                xml_escape(block.name),
                block.components,
                block.offset,
            ));
        }
        xml.push_str(&format!("      </{tag}>\n"));
    }
    xml.push_str("    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");

    write_atomically(path, |w| {
        w.write_all(xml.as_bytes())?;
        for block in &blocks {
            w.write_all(&(block.bytes.len() as u64).to_ne_bytes())?;
            w.write_all(block.bytes)?;
        }
        w.write_all(b"\n  </AppendedData>\n</VTKFile>\n")
    })
}

/// Size of the per-array byte-count header (`header_type="UInt64"`).
const HEADER_BYTES: usize = std::mem::size_of::<u64>();

fn validate(path: &Path, piece: &VtuPiece) -> Result<(), IoError> {
    let n_points = piece.points.len();
    let n_cells = piece.cells.count(n_points);
    if let Cells::PolyLines(lines) = &piece.cells {
        for (cell, line) in lines.iter().enumerate() {
            if line.is_empty() {
                return Err(IoError::EmptyCell { path: path.to_path_buf(), cell });
            }
            if let Some(&index) = line.iter().find(|&&i| i as usize >= n_points) {
                return Err(IoError::CellIndex { path: path.to_path_buf(), cell, index, points: n_points });
            }
        }
    }
    for (arrays, tuples) in [(&piece.point_data, n_points), (&piece.cell_data, n_cells)] {
        let mut seen = HashSet::new();
        for array in arrays {
            let invalid = |reason| IoError::InvalidName { path: path.to_path_buf(), name: array.name.clone(), reason };
            if array.name.trim().is_empty() {
                return Err(invalid("empty name"));
            }
            if !seen.insert(array.name.as_str()) {
                return Err(invalid("duplicate name in the same data section"));
            }
            if array.components == 0 {
                return Err(IoError::ZeroComponents { path: path.to_path_buf(), array: array.name.clone() });
            }
            let expected = tuples * array.components;
            if array.data.len() != expected {
                return Err(IoError::ArrayLength {
                    path: path.to_path_buf(),
                    array: array.name.clone(),
                    expected,
                    found: array.data.len(),
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    //! The files are read back by an independent minimal parser (string
    //! search for the XML attributes, manual little-endian decoding of the
    //! appended block), not by the writer's own code.

    use super::*;
    use crate::io::test_util::{attribute, check_xml_well_formed, scratch_dir, unwritable_path};

    /// One `<DataArray>` as the reader sees it.
    #[derive(Debug)]
    struct ReadArray {
        section: String,
        name: String,
        vtk_type: String,
        components: usize,
        raw: Vec<u8>,
    }

    impl ReadArray {
        fn f64s(&self) -> Vec<f64> {
            assert_eq!(self.vtk_type, "Float64", "{}", self.name);
            self.raw.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect()
        }
        fn i64s(&self) -> Vec<i64> {
            assert_eq!(self.vtk_type, "Int64", "{}", self.name);
            self.raw.chunks_exact(8).map(|c| i64::from_le_bytes(c.try_into().unwrap())).collect()
        }
        fn i32s(&self) -> Vec<i32> {
            assert_eq!(self.vtk_type, "Int32", "{}", self.name);
            self.raw.chunks_exact(4).map(|c| i32::from_le_bytes(c.try_into().unwrap())).collect()
        }
    }

    struct ReadVtu {
        header: String,
        n_points: usize,
        n_cells: usize,
        arrays: Vec<ReadArray>,
    }

    impl ReadVtu {
        fn get(&self, section: &str, name: &str) -> &ReadArray {
            self.arrays
                .iter()
                .find(|a| a.section == section && a.name == name)
                .unwrap_or_else(|| panic!("no {section}/{name}"))
        }
    }

    fn read_vtu(path: &Path) -> ReadVtu {
        let bytes = std::fs::read(path).unwrap();
        let marker = b"<AppendedData encoding=\"raw\">";
        let start = bytes.windows(marker.len()).position(|w| w == marker).expect("AppendedData");
        let underscore = start + bytes[start..].iter().position(|&b| b == b'_').unwrap();
        let data = &bytes[underscore + 1..];
        let header = String::from_utf8(bytes[..start + marker.len()].to_vec()).unwrap();
        let tail = b"\n  </AppendedData>\n</VTKFile>\n";
        assert!(bytes.ends_with(tail), "file does not end with the closing tags");

        let piece_tag = &header[header.find("<Piece ").unwrap()..];
        let n_points = attribute(piece_tag, "NumberOfPoints").unwrap().parse().unwrap();
        let n_cells = attribute(piece_tag, "NumberOfCells").unwrap().parse().unwrap();

        let mut arrays = Vec::new();
        let mut section = String::new();
        let mut covered = 0usize;
        for tag in header.split('<').skip(1) {
            let tag = &tag[..tag.find('>').unwrap()];
            let name = tag.split_whitespace().next().unwrap();
            if ["PointData", "CellData", "Points", "Cells"].contains(&name) {
                section = name.to_string();
            }
            if name != "DataArray" {
                continue;
            }
            let tag = format!(" {tag}");
            assert_eq!(attribute(&tag, "format"), Some("appended"));
            let offset: usize = attribute(&tag, "offset").unwrap().parse().unwrap();
            let len = u64::from_le_bytes(data[offset..offset + 8].try_into().unwrap()) as usize;
            covered += 8 + len;
            arrays.push(ReadArray {
                section: section.clone(),
                name: attribute(&tag, "Name").unwrap().to_string(),
                vtk_type: attribute(&tag, "type").unwrap().to_string(),
                components: attribute(&tag, "NumberOfComponents").unwrap().parse().unwrap(),
                raw: data[offset + 8..offset + 8 + len].to_vec(),
            });
        }
        // The blocks exactly fill the appended section: no gaps, no overlap.
        assert_eq!(covered + tail.len(), data.len());
        ReadVtu { header, n_points, n_cells, arrays }
    }

    fn assert_bits_eq(found: &[f64], expected: &[f64]) {
        assert_eq!(found.len(), expected.len());
        for (i, (f, e)) in found.iter().zip(expected).enumerate() {
            assert_eq!(f.to_bits(), e.to_bits(), "value {i}: {f} != {e}");
        }
    }

    /// Awkward values: signed zero, subnormal, extremes, non-finite.
    fn awkward(i: usize) -> f64 {
        const SPECIAL: [f64; 8] = [
            -0.0,
            f64::MIN_POSITIVE / 8.0,
            f64::MAX,
            -f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1.0 / 3.0,
            -1e-300,
        ];
        SPECIAL[i % SPECIAL.len()] * if i >= SPECIAL.len() { 0.5 } else { 1.0 }
    }

    #[test]
    fn vertex_piece_round_trips_bit_for_bit() {
        let dir = scratch_dir("vtu-vertices");
        let n = 11;
        let points: Vec<[f64; 3]> = (0..n).map(|i| [i as f64 * 0.1, awkward(i), -(i as f64).sqrt()]).collect();
        let pressure: Vec<f64> = (0..n).map(|i| awkward(i + 3)).collect();
        let velocity: Vec<[f64; 3]> =
            (0..n).map(|i| [i as f64, -2.0 * i as f64, std::f64::consts::PI * i as f64]).collect();
        let stress: Vec<[f64; 6]> = (0..n).map(|i| std::array::from_fn(|k| (10 * i + k) as f64 * 1.5e8)).collect();
        let deformation: Vec<[f64; 9]> =
            (0..n).map(|i| std::array::from_fn(|k| if k % 4 == 0 { 1.0 } else { i as f64 * 1e-3 })).collect();
        let material: Vec<i32> = (0..n as i32).map(|i| i * 7 - 20).collect();
        let flags: Vec<i32> = (0..n as i32).map(|i| i32::MIN + i).collect();
        let piece = VtuPiece::point_cloud(points.clone())
            .with_point_data(DataArray::scalars("pressure", pressure.clone()))
            .with_point_data(DataArray::vectors("velocity", &velocity))
            .with_point_data(DataArray::symmetric_tensors("stress", &stress))
            .with_point_data(DataArray::tensors("F", &deformation))
            .with_point_data(DataArray::integers("material", material.clone()))
            .with_cell_data(DataArray::integers("flags", flags.clone()));
        let path = dir.join("particles.vtu");
        write_vtu(&path, &piece).unwrap();

        let vtu = read_vtu(&path);
        assert_eq!((vtu.n_points, vtu.n_cells), (n, n));
        assert_eq!(vtu.arrays.len(), 6 + 1 + 3);
        assert_bits_eq(&vtu.get("Points", "Points").f64s(), points.as_flattened());
        assert_eq!(vtu.get("Points", "Points").components, 3);
        assert_bits_eq(&vtu.get("PointData", "pressure").f64s(), &pressure);
        assert_eq!(vtu.get("PointData", "pressure").components, 1);
        assert_bits_eq(&vtu.get("PointData", "velocity").f64s(), velocity.as_flattened());
        assert_eq!(vtu.get("PointData", "velocity").components, 3);
        assert_bits_eq(&vtu.get("PointData", "stress").f64s(), stress.as_flattened());
        assert_eq!(vtu.get("PointData", "stress").components, 6);
        assert_bits_eq(&vtu.get("PointData", "F").f64s(), deformation.as_flattened());
        assert_eq!(vtu.get("PointData", "F").components, 9);
        assert_eq!(vtu.get("PointData", "material").i32s(), material);
        assert_eq!(vtu.get("CellData", "flags").i32s(), flags);

        let expected_ids: Vec<i64> = (0..n as i64).collect();
        assert_eq!(vtu.get("Cells", "connectivity").i64s(), expected_ids);
        let expected_offsets: Vec<i64> = (1..=n as i64).collect();
        assert_eq!(vtu.get("Cells", "offsets").i64s(), expected_offsets);
        let types = vtu.get("Cells", "types");
        assert_eq!(types.vtk_type, "UInt8");
        assert_eq!(types.raw, vec![1u8; n]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn poly_line_piece_round_trips() {
        let dir = scratch_dir("vtu-lines");
        let points: Vec<[f64; 3]> = (0..7).map(|i| [i as f64, (i * i) as f64, 0.0]).collect();
        let lines = vec![vec![0, 1, 2, 3], vec![6, 5], vec![4]];
        let opening = vec![1e-6, 2.5e-6, 0.0];
        let tip_speed: Vec<[f64; 3]> = vec![[1.0, 2.0, 0.0], [-3.0, 0.5, 0.0], [0.0; 3]];
        let piece = VtuPiece::poly_lines(points.clone(), lines)
            .with_point_data(DataArray::integers("crack_id", vec![0, 0, 0, 0, 2, 1, 1]))
            .with_cell_data(DataArray::scalars("opening", opening.clone()))
            .with_cell_data(DataArray::vectors("tip_speed", &tip_speed));
        let path = dir.join("cracks.vtu");
        write_vtu(&path, &piece).unwrap();

        let vtu = read_vtu(&path);
        assert_eq!((vtu.n_points, vtu.n_cells), (7, 3));
        assert_bits_eq(&vtu.get("Points", "Points").f64s(), points.as_flattened());
        assert_eq!(vtu.get("Cells", "connectivity").i64s(), vec![0, 1, 2, 3, 6, 5, 4]);
        assert_eq!(vtu.get("Cells", "offsets").i64s(), vec![4, 6, 7]);
        assert_eq!(vtu.get("Cells", "types").raw, vec![4u8; 3]);
        assert_eq!(vtu.get("PointData", "crack_id").i32s(), vec![0, 0, 0, 0, 2, 1, 1]);
        assert_bits_eq(&vtu.get("CellData", "opening").f64s(), &opening);
        assert_bits_eq(&vtu.get("CellData", "tip_speed").f64s(), tip_speed.as_flattened());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn xml_is_well_formed_and_declares_format() {
        let dir = scratch_dir("vtu-xml");
        let path = dir.join("a.vtu");
        let piece = VtuPiece::point_cloud(vec![[0.0; 3]; 3])
            .with_point_data(DataArray::scalars("a<&\"b'>", vec![1.0, 2.0, 3.0]));
        write_vtu(&path, &piece).unwrap();
        let vtu = read_vtu(&path);
        // Close the appended element the way the file does, without the binary.
        let xml = format!("{}</AppendedData></VTKFile>", vtu.header);
        let names = check_xml_well_formed(&xml);
        assert_eq!(
            names,
            [
                "VTKFile",
                "UnstructuredGrid",
                "Piece",
                "PointData",
                "DataArray",
                "CellData",
                "Points",
                "DataArray",
                "Cells",
                "DataArray",
                "DataArray",
                "DataArray",
                "AppendedData"
            ]
        );
        assert!(vtu.header.starts_with("<?xml version=\"1.0\"?>\n"));
        let root = &vtu.header[vtu.header.find("<VTKFile").unwrap()..];
        assert_eq!(attribute(root, "type"), Some("UnstructuredGrid"));
        assert_eq!(attribute(root, "version"), Some("1.0"));
        assert_eq!(attribute(root, "byte_order"), Some("LittleEndian"));
        assert_eq!(attribute(root, "header_type"), Some("UInt64"));
        assert!(vtu.header.contains("Name=\"a&lt;&amp;&quot;b&apos;&gt;\""));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn empty_piece_is_valid() {
        let dir = scratch_dir("vtu-empty");
        let path = dir.join("empty.vtu");
        let piece = VtuPiece::point_cloud(Vec::new()).with_point_data(DataArray::scalars("p", vec![]));
        write_vtu(&path, &piece).unwrap();
        let vtu = read_vtu(&path);
        assert_eq!((vtu.n_points, vtu.n_cells), (0, 0));
        assert!(vtu.get("PointData", "p").raw.is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn inconsistent_pieces_are_rejected_and_nothing_is_written() {
        let dir = scratch_dir("vtu-invalid");
        let path = dir.join("bad.vtu");
        let cloud = || VtuPiece::point_cloud(vec![[0.0; 3]; 4]);

        let short = cloud().with_point_data(DataArray::scalars("p", vec![0.0; 3]));
        assert!(matches!(write_vtu(&path, &short), Err(IoError::ArrayLength { expected: 4, found: 3, .. })));
        let cell_short = VtuPiece::poly_lines(vec![[0.0; 3]; 4], vec![vec![0, 1], vec![2, 3]])
            .with_cell_data(DataArray::scalars("c", vec![0.0; 4]));
        assert!(matches!(write_vtu(&path, &cell_short), Err(IoError::ArrayLength { expected: 2, found: 4, .. })));
        let zero = cloud().with_point_data(DataArray { name: "z".into(), components: 0, data: ArrayData::F64(vec![]) });
        assert!(matches!(write_vtu(&path, &zero), Err(IoError::ZeroComponents { .. })));
        let duplicate = cloud()
            .with_point_data(DataArray::scalars("p", vec![0.0; 4]))
            .with_point_data(DataArray::integers("p", vec![0; 4]));
        assert!(matches!(write_vtu(&path, &duplicate), Err(IoError::InvalidName { .. })));
        let unnamed = cloud().with_point_data(DataArray::scalars(" ", vec![0.0; 4]));
        assert!(matches!(write_vtu(&path, &unnamed), Err(IoError::InvalidName { .. })));
        let out_of_range = VtuPiece::poly_lines(vec![[0.0; 3]; 2], vec![vec![0, 1], vec![1, 2]]);
        assert!(matches!(
            write_vtu(&path, &out_of_range),
            Err(IoError::CellIndex { cell: 1, index: 2, points: 2, .. })
        ));
        let empty = VtuPiece::poly_lines(vec![[0.0; 3]; 2], vec![vec![]]);
        assert!(matches!(write_vtu(&path, &empty), Err(IoError::EmptyCell { cell: 0, .. })));
        assert!(!path.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unwritable_path_gives_error_naming_it() {
        let path = unwritable_path("particles.vtu");
        let err = write_vtu(&path, &VtuPiece::point_cloud(vec![[0.0; 3]])).unwrap_err();
        assert!(matches!(&err, IoError::Write { path: p, .. } if *p == path));
        assert!(err.to_string().contains("particles.vtu"), "{err}");
    }
}
