//! VTK XML UnstructuredGrid (`.vtu`) writer for ParaView, written atomically.
//!
//! Data are stored once, uncompressed, in an `<AppendedData encoding="raw">` block
//! (little-endian, `header_type="UInt64"`): every array is an 8-byte byte count followed by
//! the raw values. Points and fields are `Float64`, connectivity and offsets `Int64`, cell
//! types `UInt8`.
//!
//! Supported cells and node order (VTK's order):
//! - [`VTK_TRIANGLE`] (5): 3 corners.
//! - [`VTK_TETRA`] (10): 4 corners.
//! - [`VTK_QUADRATIC_TRIANGLE`] (22): corners 0,1,2 then mid-edge nodes of edges
//!   (0,1), (1,2), (2,0): see [`QUADRATIC_TRIANGLE_EDGES`].
//! - [`VTK_QUADRATIC_TETRA`] (24): corners 0..3 then mid-edge nodes of edges
//!   (0,1), (1,2), (0,2), (0,3), (1,3), (2,3): see [`QUADRATIC_TETRA_EDGES`].
use std::io;
use std::path::Path;

pub const VTK_TRIANGLE: u8 = 5;
pub const VTK_TETRA: u8 = 10;
pub const VTK_QUADRATIC_TRIANGLE: u8 = 22;
pub const VTK_QUADRATIC_TETRA: u8 = 24;

/// Corner pairs of the mid-edge nodes 3, 4, 5 of a VTK quadratic triangle.
pub const QUADRATIC_TRIANGLE_EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];
/// Corner pairs of the mid-edge nodes 4..9 of a VTK quadratic tetrahedron.
pub const QUADRATIC_TETRA_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]];

/// Number of nodes of a supported VTK cell type, `None` for any other type.
pub fn nodes_per_cell(cell_type: u8) -> Option<usize> {
    match cell_type {
        VTK_TRIANGLE => Some(3),
        VTK_TETRA => Some(4),
        VTK_QUADRATIC_TRIANGLE => Some(6),
        VTK_QUADRATIC_TETRA => Some(10),
        _ => None,
    }
}

/// One named data array. Point data: `values.len() == components * npoints`; cell data:
/// `values.len() == components * ncells`; values of one point (cell) are contiguous.
/// Use `components = 3` for vectors (ParaView then offers glyphs and magnitude).
#[derive(Clone, Copy, Debug)]
pub struct Field<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: &'a [f64],
}

fn invalid(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, msg)
}

/// Writes a mesh whose cells may be of mixed types: each cell is `(VTK cell type, node ids)`.
pub fn write_vtu(
    path: &Path,
    points: &[[f64; 3]],
    cells: &[(u8, &[u32])],
    point_fields: &[Field],
    cell_fields: &[Field],
) -> io::Result<()> {
    let mut conn = Vec::with_capacity(cells.iter().map(|c| c.1.len()).sum());
    let mut types = Vec::with_capacity(cells.len());
    for (t, nodes) in cells {
        types.push(*t);
        conn.extend_from_slice(nodes);
    }
    let mut offsets = Vec::with_capacity(cells.len());
    let mut end = 0i64;
    for (_, nodes) in cells {
        end += nodes.len() as i64;
        offsets.push(end);
    }
    write_raw(path, points, &conn, &offsets, &types, point_fields, cell_fields)
}

/// Writes a mesh of one cell type from a flat connectivity array (`nodes_per_cell(cell_type)`
/// node ids per cell, cell after cell), the usual layout of a FEM mesh.
pub fn write_vtu_single_type(
    path: &Path,
    points: &[[f64; 3]],
    cell_type: u8,
    connectivity: &[u32],
    point_fields: &[Field],
    cell_fields: &[Field],
) -> io::Result<()> {
    let npc = nodes_per_cell(cell_type).ok_or_else(|| invalid(format!("vtu: unsupported VTK cell type {cell_type}")))?;
    if connectivity.len() % npc != 0 {
        return Err(invalid(format!("vtu: connectivity length {} is not a multiple of {npc} (cell type {cell_type})", connectivity.len())));
    }
    let ncells = connectivity.len() / npc;
    let offsets: Vec<i64> = (1..=ncells).map(|i| (i * npc) as i64).collect();
    let types = vec![cell_type; ncells];
    write_raw(path, points, connectivity, &offsets, &types, point_fields, cell_fields)
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Appended-data accumulator: each array is an 8-byte little-endian byte count and the bytes.
struct Appended {
    bytes: Vec<u8>,
}
impl Appended {
    fn push(&mut self, data: impl Iterator<Item = [u8; 8]>, nbytes: usize) -> usize {
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(&(nbytes as u64).to_le_bytes());
        for b in data {
            self.bytes.extend_from_slice(&b);
        }
        offset
    }
    fn push_f64(&mut self, v: &[f64]) -> usize {
        self.push(v.iter().map(|x| x.to_le_bytes()), 8 * v.len())
    }
    fn push_i64(&mut self, v: impl ExactSizeIterator<Item = i64>) -> usize {
        let n = v.len();
        self.push(v.map(|x| x.to_le_bytes()), 8 * n)
    }
    fn push_u8(&mut self, v: &[u8]) -> usize {
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(&(v.len() as u64).to_le_bytes());
        self.bytes.extend_from_slice(v);
        offset
    }
}

fn check_field(f: &Field, n: usize, what: &str) -> io::Result<()> {
    if f.components == 0 || f.values.len() != f.components * n {
        return Err(invalid(format!(
            "vtu: {what} field '{}' has {} values, expected {} components x {n} {what}s",
            f.name,
            f.values.len(),
            f.components
        )));
    }
    Ok(())
}

fn write_raw(
    path: &Path,
    points: &[[f64; 3]],
    conn: &[u32],
    offsets: &[i64],
    types: &[u8],
    point_fields: &[Field],
    cell_fields: &[Field],
) -> io::Result<()> {
    let npoints = points.len();
    let ncells = types.len();
    // validation
    let mut start = 0usize;
    for (i, (&t, &end)) in types.iter().zip(offsets).enumerate() {
        let npc = nodes_per_cell(t).ok_or_else(|| invalid(format!("vtu: cell {i} has unsupported VTK cell type {t}")))?;
        let end = end as usize;
        if end - start != npc {
            return Err(invalid(format!("vtu: cell {i} of type {t} has {} nodes, expected {npc}", end - start)));
        }
        if let Some(&bad) = conn[start..end].iter().find(|&&n| n as usize >= npoints) {
            return Err(invalid(format!("vtu: cell {i} refers to node {bad}, but there are {npoints} points")));
        }
        start = end;
    }
    for f in point_fields {
        check_field(f, npoints, "point")?;
    }
    for f in cell_fields {
        check_field(f, ncells, "cell")?;
    }

    let mut app = Appended { bytes: Vec::with_capacity(8 * (3 * npoints + conn.len() + 2 * ncells) + 64) };
    let mut xml = String::new();
    xml.push_str("<?xml version=\"1.0\"?>\n");
    xml.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    xml.push_str("  <UnstructuredGrid>\n");
    xml.push_str(&format!("    <Piece NumberOfPoints=\"{npoints}\" NumberOfCells=\"{ncells}\">\n"));

    let data_array = |xml: &mut String, ty: &str, name: &str, comps: usize, offset: usize| {
        let name_attr = if name.is_empty() { String::new() } else { format!(" Name=\"{}\"", xml_escape(name)) };
        xml.push_str(&format!(
            "        <DataArray type=\"{ty}\"{name_attr} NumberOfComponents=\"{comps}\" format=\"appended\" offset=\"{offset}\"/>\n"
        ));
    };

    for (tag, fields) in [("PointData", point_fields), ("CellData", cell_fields)] {
        let scalars = fields.iter().find(|f| f.components == 1).map(|f| f.name);
        let vectors = fields.iter().find(|f| f.components == 3).map(|f| f.name);
        let mut attrs = String::new();
        if let Some(s) = scalars {
            attrs.push_str(&format!(" Scalars=\"{}\"", xml_escape(s)));
        }
        if let Some(v) = vectors {
            attrs.push_str(&format!(" Vectors=\"{}\"", xml_escape(v)));
        }
        xml.push_str(&format!("      <{tag}{attrs}>\n"));
        for f in fields {
            let off = app.push_f64(f.values);
            data_array(&mut xml, "Float64", f.name, f.components, off);
        }
        xml.push_str(&format!("      </{tag}>\n"));
    }

    xml.push_str("      <Points>\n");
    let flat: Vec<f64> = points.iter().flatten().copied().collect();
    let off = app.push_f64(&flat);
    data_array(&mut xml, "Float64", "Points", 3, off);
    xml.push_str("      </Points>\n");

    xml.push_str("      <Cells>\n");
    let off = app.push_i64(conn.iter().map(|&n| n as i64));
    data_array(&mut xml, "Int64", "connectivity", 1, off);
    let off = app.push_i64(offsets.iter().copied());
    data_array(&mut xml, "Int64", "offsets", 1, off);
    let off = app.push_u8(types);
    data_array(&mut xml, "UInt8", "types", 1, off);
    xml.push_str("      </Cells>\n");

    xml.push_str("    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");
    let mut bytes = xml.into_bytes();
    bytes.extend_from_slice(&app.bytes);
    bytes.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
    super::write_atomic(path, &bytes)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Minimal reader of what [`write_vtu`] writes, for tests.
    pub(crate) struct Parsed {
        pub xml: String,
        pub data: Vec<u8>,
    }
    impl Parsed {
        pub fn read(path: &Path) -> Parsed {
            let bytes = std::fs::read(path).unwrap();
            let marker = b"<AppendedData encoding=\"raw\">";
            let pos = bytes.windows(marker.len()).position(|w| w == marker).expect("AppendedData");
            let underscore = pos + bytes[pos..].iter().position(|&b| b == b'_').unwrap();
            let tail = b"\n  </AppendedData>\n</VTKFile>\n";
            assert!(bytes.ends_with(tail));
            Parsed {
                xml: String::from_utf8(bytes[..underscore].to_vec()).unwrap(),
                data: bytes[underscore + 1..bytes.len() - tail.len()].to_vec(),
            }
        }
        pub fn attr(&self, tag_start: &str, attr: &str) -> String {
            let i = self.xml.find(tag_start).unwrap_or_else(|| panic!("no {tag_start}"));
            let end = i + self.xml[i..].find('>').unwrap();
            let tag = &self.xml[i..end];
            let key = format!(" {attr}=\"");
            let j = tag.find(&key).unwrap_or_else(|| panic!("no {attr} in {tag}")) + key.len();
            tag[j..j + tag[j..].find('"').unwrap()].to_string()
        }
        fn array_bytes(&self, name: &str) -> &[u8] {
            let off: usize = self.attr(&format!("Name=\"{name}\""), "offset").parse().unwrap();
            let n = u64::from_le_bytes(self.data[off..off + 8].try_into().unwrap()) as usize;
            &self.data[off + 8..off + 8 + n]
        }
        pub fn f64s(&self, name: &str) -> Vec<f64> {
            self.array_bytes(name).chunks(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect()
        }
        pub fn i64s(&self, name: &str) -> Vec<i64> {
            self.array_bytes(name).chunks(8).map(|c| i64::from_le_bytes(c.try_into().unwrap())).collect()
        }
        pub fn u8s(&self, name: &str) -> Vec<u8> {
            self.array_bytes(name).to_vec()
        }
    }

    fn test_dir() -> std::path::PathBuf {
        let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("target").join("test-output").join("vtu");
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// One P2 tetrahedron (10 nodes) and one P2 triangle on its face z = 0.
    fn p2_mesh() -> (Vec<[f64; 3]>, Vec<u32>, Vec<u32>) {
        let mut pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for [a, b] in QUADRATIC_TETRA_EDGES {
            let (pa, pb) = (pts[a], pts[b]);
            pts.push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])]);
        }
        let tet: Vec<u32> = (0..10).collect();
        // face (0,1,2): edges (0,1)->4, (1,2)->5, (2,0)->6
        let tri = vec![0, 1, 2, 4, 5, 6];
        (pts, tet, tri)
    }

    #[test]
    fn vtu_mixed_p2_mesh_round_trip() {
        let (pts, tet, tri) = p2_mesh();
        let p: Vec<f64> = pts.iter().map(|q| q[0] + 2.0 * q[1] + 3.0 * q[2]).collect();
        let u: Vec<f64> = pts.iter().flat_map(|q| [q[0], -q[1], 1e-9 * q[2]]).collect();
        let id = [7.0, 8.0];
        let path = test_dir().join("p2 <mixed>.vtu");
        write_vtu(
            &path,
            &pts,
            &[(VTK_QUADRATIC_TETRA, &tet), (VTK_QUADRATIC_TRIANGLE, &tri)],
            &[Field { name: "pressure", components: 1, values: &p }, Field { name: "u & v", components: 3, values: &u }],
            &[Field { name: "region", components: 1, values: &id }],
        )
        .unwrap();
        let r = Parsed::read(&path);
        assert!(r.xml.starts_with("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\""));
        assert_eq!(r.attr("<Piece", "NumberOfPoints"), "10");
        assert_eq!(r.attr("<Piece", "NumberOfCells"), "2");
        assert_eq!(r.attr("<PointData", "Scalars"), "pressure");
        assert_eq!(r.attr("<PointData", "Vectors"), "u &amp; v");
        assert_eq!(r.f64s("pressure"), p);
        assert_eq!(r.f64s("u &amp; v"), u);
        assert_eq!(r.attr("Name=\"u &amp; v\"", "NumberOfComponents"), "3");
        assert_eq!(r.f64s("region"), id);
        assert_eq!(r.f64s("Points"), pts.iter().flatten().copied().collect::<Vec<_>>());
        let conn: Vec<i64> = tet.iter().chain(&tri).map(|&n| n as i64).collect();
        assert_eq!(r.i64s("connectivity"), conn);
        assert_eq!(r.i64s("offsets"), vec![10, 16]);
        assert_eq!(r.u8s("types"), vec![24, 22]);
        // the XML part is well formed enough: every opened element is closed
        for tag in ["VTKFile", "UnstructuredGrid", "Piece", "PointData", "CellData", "Points", "Cells"] {
            assert_eq!(r.xml.matches(&format!("<{tag}")).count(), 1, "{tag}");
        }
        for tag in ["UnstructuredGrid", "Piece", "PointData", "CellData", "Points", "Cells"] {
            assert!(r.xml.contains(&format!("</{tag}>")), "{tag}");
        }
    }

    #[test]
    fn vtu_single_type_linear() {
        let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 1.0]];
        let conn = [0, 1, 2, 4, 0, 2, 3, 4];
        let path = test_dir().join("tets.vtu");
        write_vtu_single_type(&path, &pts, VTK_TETRA, &conn, &[], &[]).unwrap();
        let r = Parsed::read(&path);
        assert_eq!(r.attr("<Piece", "NumberOfCells"), "2");
        assert_eq!(r.i64s("offsets"), vec![4, 8]);
        assert_eq!(r.u8s("types"), vec![10, 10]);
        let tris = [0, 1, 2, 0, 2, 3];
        write_vtu_single_type(&test_dir().join("tris.vtu"), &pts, VTK_TRIANGLE, &tris, &[], &[]).unwrap();
        assert_eq!(Parsed::read(&test_dir().join("tris.vtu")).u8s("types"), vec![5, 5]);
    }

    #[test]
    fn vtu_rejects_bad_input() {
        let pts = [[0.0; 3]; 4];
        let d = test_dir();
        assert!(write_vtu_single_type(&d.join("bad1.vtu"), &pts, VTK_TETRA, &[0, 1, 2], &[], &[]).is_err());
        assert!(write_vtu_single_type(&d.join("bad2.vtu"), &pts, VTK_TETRA, &[0, 1, 2, 4], &[], &[]).is_err());
        assert!(write_vtu_single_type(&d.join("bad3.vtu"), &pts, 12, &[0, 1, 2, 3, 0, 1, 2, 3], &[], &[]).is_err());
        assert!(write_vtu(&d.join("bad4.vtu"), &pts, &[(VTK_QUADRATIC_TETRA, &[0, 1, 2, 3])], &[], &[]).is_err());
        let short = [1.0; 3];
        let f = [Field { name: "p", components: 1, values: &short }];
        assert!(write_vtu_single_type(&d.join("bad5.vtu"), &pts, VTK_TETRA, &[0, 1, 2, 3], &f, &[]).is_err());
        for i in 1..=5 {
            assert!(!d.join(format!("bad{i}.vtu")).exists());
        }
    }
}
